//! `Outcome::at`: where the unhandled exception that failed a mission was raised, the
//! statement a campaign's report names (docs/CAMPAIGNS.md).

use aviary_diagnostics::SourceMap;
use aviary_engine::Status;
use aviary_test_support::harness::{run, run_in, WORLD};

/// The line (1-based) of the span `at` in `text`.
fn line(text: &str, at: Option<aviary_ir::Origin>) -> usize {
    let at = at.expect("a failed mission says where");
    let mut sources = SourceMap::new();
    let id = sources.add("m.mission", text);
    sources.line_col(id, at.span.start).line
}

#[test]
fn a_throw_nobody_handles_is_placed_at_the_throw() {
    let text = "MISSION M:\n    a TakeOff WITH 10m\n    THROW EXCEPTION Late\n";
    let ran = run(text);
    assert_eq!(ran.outcome.status, Status::Failed);
    assert_eq!(line(text, ran.outcome.at), 3);
}

#[test]
fn a_fault_nobody_handles_is_placed_at_the_drones_call_in_progress() {
    let world =
        format!("{WORLD}\n[[faults]]\ndrone = \"a\"\nat = 30.0\nkind = \"motor_failure\"\n");
    let text = "CAPABILITY Go BY d:\n    PERFORM:\n        d.Arm()\n        d.TakeOff(10m)\n        d.FlyToPosition(Far)\n        d.Land()\n\nMISSION M:\n    a Go\n";
    let ran = run_in(text, &world);
    assert_eq!(ran.outcome.status, Status::Failed, "{:?}", ran.outcome.reason);
    assert_eq!(line(text, ran.outcome.at), 5, "the FlyToPosition in progress at 30 s");
}

#[test]
fn a_mission_that_ends_well_is_placed_nowhere() {
    let ran = run("MISSION M:\n    a TakeOff WITH 10m\n");
    assert_eq!(ran.outcome.status, Status::Ok);
    assert_eq!(ran.outcome.at, None);
}
