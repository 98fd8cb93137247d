//! The benchmark missions (`aviary bench w`, `aviary bench swarm`) really do their work:
//! generated in the language, they check with no diagnostic at all and, flown small
//! here, do all of it, as the trace shows.

use aviary_api::trace::{CallStatus, Event, EventKind};
use aviary_api::Function;
use aviary_bench::generate::{swarm_mission, swarm_world, w_mission, w_world};
use aviary_engine::Status;
use aviary_test_support::harness;
use aviary_test_support::trace::{actor, is};

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
    let dones = r.find(is::signal("Done"));
    assert_eq!(dones.len() as u64, n);
    let sum: u64 = dones
        .iter()
        .map(|e| match &e.event {
            Event::Signal { args, .. } => args[0].as_number().unwrap() as u64,
            _ => unreachable!(),
        })
        .sum();
    assert_eq!(sum, n * (n - 1) / 2);
    let handled = r
        .trace
        .iter()
        .filter(|e| {
            matches!(&e.event, Event::HandlerStart { signal, handler, .. }
                if signal == "Done" && handler == "W/ON Done")
        })
        .count();
    assert_eq!(handled as u64, n, "the one handler takes every Done");
    let steps = r
        .trace
        .iter()
        .filter(|e| {
            matches!(&e.event, Event::CapabilityEnd { capability, status: Status::Ok, .. }
                if capability == "Step")
        })
        .count();
    assert_eq!(steps as u64, n * k);
    // Each actor's steps run one after another, each ending before the next starts,
    // and its Done comes after its last step.
    let a7: Vec<EventKind> =
        r.trace.iter().filter(|e| actor(&e.event) == Some("a7")).map(|e| e.event.kind()).collect();
    use EventKind::*;
    let expected: Vec<EventKind> =
        std::iter::repeat_n([CapabilityStart, ApiCall, ApiDone, CapabilityEnd], k as usize)
            .flatten()
            .chain([Signal, HandlerStart, HandlerEnd])
            .collect();
    assert_eq!(a7, expected);
}

#[test]
fn the_swarm_sweeps_every_cell_and_hears_every_find() {
    let r = harness::run_in(&swarm_mission(4), &swarm_world(4));
    assert_eq!(r.outcome.status, Status::Ok, "{:?}", r.outcome.reason);
    let detections = r.events(EventKind::Detection).len();
    assert_eq!(detections, 2, "cells 0 and 3 hide a target each");
    assert_eq!(r.find(is::handler_start("Found")).len(), detections);
    let sweeps = r
        .find(|e| {
            matches!(e, Event::ApiDone { function: Function::Sweep, status: CallStatus::Ok, .. })
        })
        .len();
    assert_eq!(sweeps, 4);
}
