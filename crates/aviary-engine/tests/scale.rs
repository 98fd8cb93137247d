//! The benchmark missions (`aviary bench w`, `aviary bench swarm`) really do their work:
//! generated in the language, they check with no diagnostic at all and, flown small
//! here, do all of it, as the trace shows.

use aviary_bench::generate::{swarm_mission, swarm_world, w_mission, w_world};
use aviary_engine::Status;
use aviary_test_support::harness;

/// Every diagnostic (errors, warnings and notes) of a mission in its world.
fn diagnostics(mission: &str, world: &str) -> Vec<String> {
    let (_, checked) = harness::check(mission, world);
    checked.diagnostics.iter().map(|d| format!("{} {}", d.code, d.message)).collect()
}

#[test]
fn the_benchmark_missions_check_clean() {
    assert_eq!(diagnostics(&w_mission(10), &w_world(100)), Vec::<String>::new());
    assert_eq!(diagnostics(&w_mission(1), &w_world(1)), Vec::<String>::new());
    assert_eq!(diagnostics(&swarm_mission(9), &swarm_world(9)), Vec::<String>::new());
}

#[test]
fn w_raises_n_dones_that_one_handler_takes_with_every_index() {
    let (n, k) = (40u64, 3u64);
    let r = harness::run_in(&w_mission(k as usize), &w_world(n as usize));
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let dones = r.find("signal", "name", "Done");
    assert_eq!(dones.len() as u64, n);
    let sum: u64 = dones.iter().map(|e| e["args"][0].as_f64().unwrap() as u64).sum();
    assert_eq!(sum, n * (n - 1) / 2);
    let handled = r
        .trace
        .iter()
        .filter(|e| {
            e["event"] == "handler_start" && e["signal"] == "Done" && e["handler"] == "W/ON Done"
        })
        .count();
    assert_eq!(handled as u64, n, "the one handler takes every Done");
    let steps = r
        .trace
        .iter()
        .filter(|e| {
            e["event"] == "capability_end" && e["capability"] == "Step" && e["status"] == "ok"
        })
        .count();
    assert_eq!(steps as u64, n * k);
    // Each actor's steps run one after another, each ending before the next starts,
    // and its Done comes after its last step.
    let a7: Vec<&str> =
        r.trace.iter().filter(|e| e["actor"] == "a7").filter_map(|e| e["event"].as_str()).collect();
    let expected: Vec<&str> = std::iter::repeat_n(
        ["capability_start", "api_call", "api_done", "capability_end"],
        k as usize,
    )
    .flatten()
    .chain(["signal", "handler_start", "handler_end"])
    .collect();
    assert_eq!(a7, expected);
}

#[test]
fn the_swarm_sweeps_every_cell_and_hears_every_find() {
    let r = harness::run_in(&swarm_mission(4), &swarm_world(4));
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let detections = r.trace.iter().filter(|e| e["event"] == "detection").count();
    assert_eq!(detections, 2, "cells 0 and 3 hide a target each");
    assert_eq!(
        r.trace.iter().filter(|e| e["event"] == "handler_start" && e["signal"] == "Found").count(),
        detections
    );
    let sweeps = r
        .trace
        .iter()
        .filter(|e| e["event"] == "api_done" && e["function"] == "Sweep" && e["status"] == "ok")
        .count();
    assert_eq!(sweeps, 4);
}
