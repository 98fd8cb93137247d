//! The pipeline relay case of the radio's reach, end to end: `aviary check` warns where a
//! planned path leaves reach (W210) and the run loses the link there; with a relay half
//! way, neither.

mod common;

use aviary_test_support::trace::{actor, is, Trace};
use common::{aviary, scratch};

fn fixture(name: &str) -> std::path::PathBuf {
    common::repo().join("crates/aviary-verify/tests/fixtures").join(name)
}

/// Checks and runs the fixture `stem` in a scratch copy: the check's output, and the
/// run's exit code and trace.
fn check_and_run(stem: &str) -> (String, i32, Trace) {
    let dir = scratch(&format!("radio_{stem}"));
    for ext in ["mission", "world.toml"] {
        std::fs::copy(fixture(&format!("{stem}.{ext}")), dir.join(format!("m.{ext}")))
            .expect("fixture");
    }
    let (_, checked, err) = aviary(&["check", "m.mission"], &dir);
    let (code, _, _) = aviary(&["run", "m.mission", "--trace", "t.jsonl"], &dir);
    let trace = Trace::read(&dir.join("t.jsonl"));
    (checked + &err, code, trace)
}

#[test]
fn a_path_out_of_reach_is_warned_before_flight_and_loses_its_link_there() {
    let (checked, code, trace) = check_and_run("w210_pipeline_out_of_reach");
    assert!(
        checked.contains("warning[W210]: inspector's planned path leaves radio reach"),
        "{checked}"
    );
    assert!(checked.contains("m.mission:6:9"), "at the statement that flies it out: {checked}");
    assert_eq!(code, 1, "the lost link is not handled: the mission fails");
    let lost = trace
        .iter()
        .find(|e| is::exception("ConnectionLost")(&e.event))
        .unwrap_or_else(|| panic!("no ConnectionLost: {trace:?}"));
    assert_eq!(actor(&lost.event), Some("inspector"));
    // When the check said: about 100 s in.
    let t = lost.t;
    assert!((80.0..=120.0).contains(&t), "lost at {t} s (the check: about 100 s)");
}

#[test]
fn a_relay_half_way_keeps_the_link_and_the_check_quiet() {
    let (checked, code, trace) = check_and_run("ok_pipeline_relayed");
    assert!(!checked.contains("W210"), "{checked}");
    assert_eq!(code, 0, "{:?}", trace.last());
    assert!(trace.find(is::exception("ConnectionLost")).is_empty(), "the relay kept the link");
}
