//! `aviary ctl state` for people: the operator API's state document (docs/OPERATOR_API.md,
//! `GET /api/state`) as a few lines and tables. `--json` prints the document itself.

use aviary_api::operator::{MissionStatus, OperatorState, Withdrawn};

/// The state document as text; a field the document leaves out is shown as `-`.
pub fn state_table(state: &OperatorState) -> String {
    let mut out = String::new();
    let text = |v: &Option<String>| v.clone().unwrap_or_else(|| "-".to_owned());
    let mut head = format!(
        "mission {}   {}   t = {:.1} s",
        text(&state.mission),
        match state.status {
            MissionStatus::NotStarted => "not started",
            status => status.as_str(),
        },
        state.t
    );
    if state.paused {
        head.push_str("   PAUSED by the operator");
    }
    if let Some(reason) = &state.reason {
        head.push_str(&format!("   ({reason})"));
    }
    out.push_str(&head);
    out.push('\n');

    out.push_str(&format!(
        "blocks running: {}\n",
        if state.blocks.is_empty() { "none".to_owned() } else { state.blocks.join(", ") }
    ));

    if state.activities.is_empty() {
        out.push_str("activities running: none\n");
    } else {
        out.push_str("activities running:\n");
        let rows: Vec<Vec<String>> = state
            .activities
            .iter()
            .map(|a| {
                let leash = match &a.tag {
                    Some(tag) => format!("{}-{tag}", a.capability),
                    None => a.capability.clone(),
                };
                vec![
                    leash,
                    a.actor.clone(),
                    format!("{:.1} s", a.since),
                    if a.paused { "paused" } else { "" }.to_owned(),
                ]
            })
            .collect();
        out.push_str(&table(&["activity", "drones", "since", ""], &rows));
    }

    if !state.drones.is_empty() {
        out.push_str("drones:\n");
        let rows: Vec<Vec<String>> = state
            .drones
            .iter()
            .map(|d| {
                let (flight, battery, position) = match &d.telemetry {
                    Some(t) => {
                        let c: Vec<String> = t.position.iter().map(|x| format!("{x:.0}")).collect();
                        let battery = if t.battery.is_finite() {
                            format!("{:.0}%", t.battery * 100.0)
                        } else {
                            "-".to_owned()
                        };
                        (t.state.as_str().to_owned(), battery, format!("({})", c.join(", ")))
                    }
                    None => ("-".to_owned(), "-".to_owned(), "-".to_owned()),
                };
                let steered = match (d.withdrawn, d.held) {
                    (Some(Withdrawn::Home), _) => "sent home by the operator",
                    (Some(Withdrawn::Land), _) => "landed by the operator",
                    (None, true) => "held by the operator",
                    (None, false) => "",
                };
                vec![d.name.clone(), flight, battery, position, steered.to_owned()]
            })
            .collect();
        out.push_str(&table(&["drone", "state", "battery", "position (m)", ""], &rows));
    }
    out
}

/// Columns padded to their widest cell, two spaces apart, indented by two; trailing
/// blanks trimmed.
fn table(header: &[&str], rows: &[Vec<String>]) -> String {
    let mut widths: Vec<usize> = header.iter().map(|h| h.chars().count()).collect();
    for row in rows {
        for (w, cell) in widths.iter_mut().zip(row) {
            *w = (*w).max(cell.chars().count());
        }
    }
    let line = |cells: Vec<&str>| {
        let padded: Vec<String> =
            cells.iter().zip(&widths).map(|(c, w)| format!("{c:<w$}")).collect();
        format!("  {}", padded.join("  ")).trim_end().to_owned() + "\n"
    };
    let mut out = line(header.to_vec());
    for row in rows {
        out.push_str(&line(row.iter().map(String::as_str).collect()));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::state_table;
    use serde_json::json;

    fn read(value: serde_json::Value) -> aviary_api::operator::OperatorState {
        serde_json::from_value(value).expect("a state document")
    }

    #[test]
    fn a_running_mission_reads_as_lines_and_tables() {
        let state = json!({
            "mission": "Watch", "t": 42.0, "status": "running", "reason": null, "paused": false,
            "blocks": ["Watch", "Watch/Circle"],
            "activities": [
                {"capability": "FlyCircle", "tag": "C1", "actor": "scout1", "args": {}, "since": 12.0, "paused": true},
                {"capability": "TakeOff", "tag": null, "actor": "scout2", "args": {}, "since": 40.5, "paused": false}
            ],
            "drones": [
                {"name": "scout1", "position": [10.0, -20.4, 30.0], "battery": 0.875, "state": "Flying", "t": 42.0, "held": false, "withdrawn": null},
                {"name": "scout2", "position": [0.0, 0.0, 1.0], "battery": 1.0, "state": "TakingOff", "t": 42.0, "held": true, "withdrawn": null},
                {"name": "spare", "held": false, "withdrawn": "home"}
            ]
        });
        let expected = [
            "mission Watch   running   t = 42.0 s",
            "blocks running: Watch, Watch/Circle",
            "activities running:",
            "  activity      drones  since",
            "  FlyCircle-C1  scout1  12.0 s  paused",
            "  TakeOff       scout2  40.5 s",
            "drones:",
            "  drone   state      battery  position (m)",
            "  scout1  Flying     88%      (10, -20, 30)",
            "  scout2  TakingOff  100%     (0, 0, 1)      held by the operator",
            "  spare   -          -        -              sent home by the operator",
        ];
        assert_eq!(state_table(&read(state)), expected.join("\n") + "\n");
    }

    #[test]
    fn before_the_start_and_after_the_end() {
        let empty = json!({"mission": null, "t": 0.0, "status": "", "reason": null, "paused": false,
            "blocks": [], "activities": [], "drones": []});
        assert_eq!(
            state_table(&read(empty)),
            "mission -   not started   t = 0.0 s\nblocks running: none\nactivities running: none\n"
        );
        let ended = json!({"mission": "M", "t": 9.0, "status": "failed", "reason": "unhandled exception", "paused": true,
            "blocks": [], "activities": [], "drones": []});
        assert!(state_table(&read(ended)).starts_with(
            "mission M   failed   t = 9.0 s   PAUSED by the operator   (unhandled exception)\n"
        ));
    }
}
