//! Every example mission checks clean and runs: the paper's, and one drill per fault kind
//! (examples/faults/), where the fault's exception is raised once and handled.

mod common;

use common::{aviary, repo, scratch};

#[test]
fn every_fault_drill_raises_its_exception_once_and_handles_it() {
    let dir = scratch("drills");
    let drills = [
        ("battery_critical", "BatteryCritical"),
        ("crash", "DroneLost"),
        ("motor_failure", "MotorFailure"),
        ("gps_loss", "PositionLost"),
        ("link_loss", "ConnectionLost"),
    ];
    for (kind, exception) in drills {
        let mission = format!("examples/faults/{kind}.mission");
        let (code, out, _) = aviary(&["check", &mission], &repo());
        assert_eq!(code, 0, "{out}");
        let trace = dir.join(format!("{kind}.jsonl"));
        let (code, out, err) =
            aviary(&["run", &mission, "--trace", &trace.to_string_lossy()], &repo());
        assert_eq!(code, 0, "{kind}: {out}{err}");
        let events: Vec<serde_json::Value> = std::fs::read_to_string(&trace)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        let raised: Vec<&serde_json::Value> =
            events.iter().filter(|e| e["event"] == "exception").collect();
        assert_eq!(raised.len(), 1, "{kind}: one fault, one exception");
        assert_eq!(
            (
                raised[0]["name"].as_str(),
                raised[0]["actor"].as_str(),
                raised[0]["handled"].as_bool()
            ),
            (Some(exception), Some("scout"), Some(true)),
            "{kind}"
        );
        let carrier = events
            .iter()
            .find(|e| e["event"] == "capability_end" && e["actor"] == "carrier")
            .unwrap();
        assert_eq!(carrier["status"], "ok", "{kind}: the other drones carry on");
    }
}
