//! `aviary ctl state` for people: the operator API's state document (docs/OPERATOR_API.md,
//! `GET /api/state`) as a few lines and tables. `--json` prints the document itself.

use serde_json::Value;

/// The state document as text; a field the document lacks is shown as `-`.
pub fn state_table(state: &Value) -> String {
    let mut out = String::new();
    let text = |v: &Value| v.as_str().map(str::to_owned).unwrap_or_else(|| "-".to_owned());
    let mut head = format!(
        "mission {}   {}   t = {:.1} s",
        text(&state["mission"]),
        if state["status"].as_str().is_some_and(|s| !s.is_empty()) {
            text(&state["status"])
        } else {
            "not started".to_owned()
        },
        state["t"].as_f64().unwrap_or(0.0)
    );
    if state["paused"].as_bool() == Some(true) {
        head.push_str("   PAUSED by the operator");
    }
    if let Some(reason) = state["reason"].as_str() {
        head.push_str(&format!("   ({reason})"));
    }
    out.push_str(&head);
    out.push('\n');

    let blocks: Vec<String> = list(&state["blocks"]).iter().map(text).collect();
    out.push_str(&format!(
        "blocks running: {}\n",
        if blocks.is_empty() { "none".to_owned() } else { blocks.join(", ") }
    ));

    let activities = list(&state["activities"]);
    if activities.is_empty() {
        out.push_str("activities running: none\n");
    } else {
        out.push_str("activities running:\n");
        let rows: Vec<Vec<String>> = activities
            .iter()
            .map(|a| {
                let leash = match a["tag"].as_str() {
                    Some(tag) => format!("{}-{tag}", text(&a["capability"])),
                    None => text(&a["capability"]),
                };
                vec![
                    leash,
                    text(&a["actor"]),
                    format!("{:.1} s", a["since"].as_f64().unwrap_or(0.0)),
                    if a["paused"].as_bool() == Some(true) { "paused" } else { "" }.to_owned(),
                ]
            })
            .collect();
        out.push_str(&table(&["activity", "drones", "since", ""], &rows));
    }

    let drones = list(&state["drones"]);
    if !drones.is_empty() {
        out.push_str("drones:\n");
        let rows: Vec<Vec<String>> = drones
            .iter()
            .map(|d| {
                let position = match d["position"].as_array() {
                    Some(p) => {
                        let c: Vec<String> = p
                            .iter()
                            .map(|x| format!("{:.0}", x.as_f64().unwrap_or(f64::NAN)))
                            .collect();
                        format!("({})", c.join(", "))
                    }
                    None => "-".to_owned(),
                };
                let battery = match d["battery"].as_f64() {
                    Some(b) => format!("{:.0}%", b * 100.0),
                    None => "-".to_owned(),
                };
                let steered = match (d["withdrawn"].as_str(), d["held"].as_bool()) {
                    (Some("home"), _) => "sent home by the operator",
                    (Some("land"), _) => "landed by the operator",
                    (_, Some(true)) => "held by the operator",
                    _ => "",
                };
                vec![text(&d["name"]), text(&d["state"]), battery, position, steered.to_owned()]
            })
            .collect();
        out.push_str(&table(&["drone", "state", "battery", "position (m)", ""], &rows));
    }
    out
}

fn list(v: &Value) -> &[Value] {
    v.as_array().map_or(&[], Vec::as_slice)
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
        assert_eq!(state_table(&state), expected.join("\n") + "\n");
    }

    #[test]
    fn before_the_start_and_after_the_end() {
        let empty = json!({"mission": null, "t": 0.0, "status": "", "reason": null, "paused": false,
            "blocks": [], "activities": [], "drones": []});
        assert_eq!(
            state_table(&empty),
            "mission -   not started   t = 0.0 s\nblocks running: none\nactivities running: none\n"
        );
        let ended = json!({"mission": "M", "t": 9.0, "status": "failed", "reason": "unhandled exception", "paused": true,
            "blocks": [], "activities": [], "drones": []});
        assert!(state_table(&ended).starts_with(
            "mission M   failed   t = 9.0 s   PAUSED by the operator   (unhandled exception)\n"
        ));
    }
}
