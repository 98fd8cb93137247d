//! Every example mission checks clean and runs: the paper's, and one drill per fault kind
//! (examples/faults/), where the fault's exception is raised once and handled.

mod common;

use aviary_api::trace::{Event, EventKind, Status};
use aviary_test_support::trace::Trace;
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
        let events = Trace::read(&trace);
        let raised = events.events(EventKind::Exception);
        assert_eq!(raised.len(), 1, "{kind}: one fault, one exception");
        let Event::Exception { name, actor, handled, .. } = &raised[0].event else {
            unreachable!()
        };
        assert_eq!(
            (&**name, actor.as_deref(), *handled),
            (exception, Some("scout"), true),
            "{kind}"
        );
        let carrier = events
            .iter()
            .find_map(|e| match &e.event {
                Event::CapabilityEnd { actor, status, .. } if actor == "carrier" => Some(*status),
                _ => None,
            })
            .unwrap();
        assert_eq!(carrier, Status::Ok, "{kind}: the other drones carry on");
    }
}
