//! `aviary check --plan`: the estimate agrees with a simulated run of the same mission
//! within 15% for each drone's flight time and distance, and its forms (text, JSON,
//! refusals) are as docs/GUIDE.md describes.

mod common;

use aviary_api::trace::{Event, EventKind, Params, Shown, Status};
use aviary_api::Point;
use aviary_test_support::trace::Trace;
use common::{aviary, repo, scratch, PAPER_DRONES};

/// Per drone: (distance m, flight s), from the summary `aviary run` prints.
fn simulated(mission: &str, world: &[&str]) -> Vec<(String, f64, f64)> {
    let (code, out, err) = aviary(&[&["run", mission], world].concat(), &repo());
    assert_eq!(code, 0, "the run failed: {err}");
    common::summary_rows(&out)
}

fn planned(mission: &str, world: &[&str]) -> serde_json::Value {
    let (code, out, err) =
        aviary(&[&["check", "--plan", "--format", "json", mission], world].concat(), &repo());
    assert_eq!(code, 0, "check --plan failed: {err}");
    serde_json::from_str(&out).expect("one JSON document")
}

fn agrees_within_15_percent(mission: &str, world: &[&str]) {
    let sim = simulated(mission, world);
    let plan = planned(mission, world);
    let drones = plan["plan"]["drones"].as_array().expect("drones");
    assert_eq!(drones.len(), sim.len());
    let mut off = Vec::new();
    for (d, (name, distance, flight)) in drones.iter().zip(&sim) {
        assert_eq!(d["drone"].as_str(), Some(name.as_str()));
        for (what, est, real) in [
            ("distance", d["distance"].as_f64().expect("distance"), *distance),
            ("flight time", d["flight_time"].as_f64().expect("flight time"), *flight),
        ] {
            // The summary rounds to whole metres and seconds.
            if (est - real).abs() > 0.15 * real + 1.0 {
                off.push(format!("{name}: {what} planned {est:.0}, simulated {real:.0}"));
            }
        }
    }
    assert!(off.is_empty(), "the plan is off by more than 15%:\n{}", off.join("\n"));
}

#[test]
fn the_papers_plan_agrees_with_its_simulated_run() {
    agrees_within_15_percent("examples/search_and_rescue.mission", &[]);
}

#[test]
fn the_shared_papers_plan_agrees_with_its_simulated_run() {
    let shared = repo().join("../shared/examples/search_and_rescue.mission");
    if !shared.is_file() {
        eprintln!("skipped: ../shared/examples is not beside the repository");
        return;
    }
    agrees_within_15_percent("../shared/examples/search_and_rescue.mission", &[]);
}

#[test]
fn the_plan_agrees_with_a_simulated_run_of_drones_with_arducopters_figures() {
    // Slower climbs and descents, a slow touch-down, a higher return with a wait above
    // home: the plan follows each as the simulator flies it.
    let dir = scratch("plan_arducopter");
    let world = dir.join("arducopter.world.toml");
    std::fs::write(&world, common::example_world_with(|_| common::ARDUCOPTER.to_owned()))
        .expect("world");
    agrees_within_15_percent(
        "examples/search_and_rescue.mission",
        &["--world", &world.to_string_lossy()],
    );
}

#[test]
fn the_plan_agrees_with_a_simulated_run_of_drones_with_px4s_figures() {
    // A take-off at half the climb rate and a slower way home (MPC_TKO_SPEED,
    // MPC_XY_CRUISE), a high return: the plan follows each as the simulator flies it.
    let dir = scratch("plan_px4");
    let world = dir.join("px4.world.toml");
    std::fs::write(&world, common::example_world_with(|_| common::PX4.to_owned())).expect("world");
    agrees_within_15_percent(
        "examples/search_and_rescue.mission",
        &["--world", &world.to_string_lossy()],
    );
}

const FIXTURES: &str = "crates/aviary-verify/tests/fixtures";

#[test]
fn the_plan_agrees_with_simulated_runs_of_the_preflight_fixtures() {
    let world = format!("{FIXTURES}/world.toml");
    for fixture in [
        "n303_every_firing",
        "n303_after_signal",
        "ok_no_conflicts",
        "w203_two_handlers",
        "w203_parallel_branches",
    ] {
        agrees_within_15_percent(&format!("{FIXTURES}/{fixture}.mission"), &["--world", &world]);
    }
}

/// `(start, end)` of each activity of `actor` running `capability` with `args` (by name,
/// in any order), in order.
fn activities(
    trace: &str,
    actor: &str,
    capability: &str,
    args: &[(&str, Shown)],
) -> Vec<(f64, f64)> {
    let events = Trace::parse(trace);
    let same = |given: &Params| {
        given.0.len() == args.len() && args.iter().all(|(k, v)| given.get(k) == Some(v))
    };
    let mine = |a: &str, c: &str, given: &Params| a == actor && c == capability && same(given);
    let starts = events.iter().filter_map(|e| match &e.event {
        Event::CapabilityStart { actor, capability, args, .. } if mine(actor, capability, args) => {
            Some(e.t)
        }
        _ => None,
    });
    let ends = events.iter().filter_map(|e| match &e.event {
        Event::CapabilityEnd { actor, capability, args, .. } if mine(actor, capability, args) => {
            Some(e.t)
        }
        _ => None,
    });
    starts.zip(ends).collect()
}

/// `FlyTo`'s values: to a place, at the drone's own speed.
fn fly_to(x: f64, y: f64) -> [(&'static str, Shown<'static>); 2] {
    [("target", Shown::Position(Point { x, y, z: None })), ("speed", Shown::Number(0.0))]
}

#[test]
fn what_n303_says_waits_does_wait_in_the_engine() {
    let dir = scratch("n303_engine");
    let trace = dir.join("trace.jsonl");
    let world = format!("{FIXTURES}/world.toml");
    let (code, _, err) = aviary(
        &[
            "run",
            &format!("{FIXTURES}/n303_after_signal.mission"),
            "--world",
            &world,
            "--trace",
            trace.to_str().expect("path"),
        ],
        &repo(),
    );
    assert_eq!(code, 0, "{err}");
    let trace = std::fs::read_to_string(&trace).expect("trace");
    let flow = activities(&trace, "scout1", "FlyTo", &fly_to(300.0, 0.0));
    let handler = activities(&trace, "scout1", "FlyTo", &fly_to(0.0, 300.0));
    assert_eq!((flow.len(), handler.len()), (1, 1), "{trace}");
    assert!(
        handler[0].0 >= flow[0].1,
        "the handler's flight starts at {} before the flow's ends at {}",
        handler[0].0,
        flow[0].1
    );
    // And the plan puts them in the same order.
    let plan = planned(&format!("{FIXTURES}/n303_after_signal.mission"), &["--world", &world]);
    let acts = plan["plan"]["drones"][0]["activities"].as_array().expect("activities").clone();
    let lines: Vec<&str> = acts.iter().map(|a| a["at"].as_str().expect("at")).collect();
    assert_eq!(
        lines.iter().map(|l| l.rsplit(':').nth(1).expect("line")).collect::<Vec<_>>(),
        ["5", "7", "9", "10"]
    );
}

#[test]
fn each_on_every_firing_waits_for_the_last_one_in_the_engine() {
    let dir = scratch("n303_every_engine");
    let trace = dir.join("trace.jsonl");
    let world = format!("{FIXTURES}/world.toml");
    let (code, _, err) = aviary(
        &[
            "run",
            &format!("{FIXTURES}/n303_every_firing.mission"),
            "--world",
            &world,
            "--trace",
            trace.to_str().expect("path"),
        ],
        &repo(),
    );
    assert_eq!(code, 0, "{err}");
    let trace = std::fs::read_to_string(&trace).expect("trace");
    let events = Trace::parse(&trace);
    let starts: Vec<f64> = events
        .find(|e| matches!(e, Event::CapabilityStart { capability, .. } if capability == "Deliver"))
        .iter()
        .map(|e| e.t)
        .collect();
    let ends: Vec<f64> = events
        .find(|e| matches!(e, Event::CapabilityEnd { capability, .. } if capability == "Deliver"))
        .iter()
        .map(|e| e.t)
        .collect();
    assert_eq!(starts.len(), 2, "one delivery per target: {starts:?}");
    assert!(
        starts[1] >= ends[0],
        "the second delivery starts at {} before the first ends at {}",
        starts[1],
        ends[0]
    );
}

#[test]
fn the_papers_mission_checks_clean_apart_from_notes() {
    let (code, out, _) = aviary(&["check", "examples/search_and_rescue.mission"], &repo());
    assert_eq!(code, 0);
    assert!(!out.contains("warning["), "{out}");
    assert!(
        out.contains("note[N303]"),
        "the queueing of video_drone2 and the beacons is noted:\n{out}"
    );
}

#[test]
fn the_text_plan_lists_every_drone_with_its_timeline() {
    let (code, out, _) =
        aviary(&["check", "--plan", "examples/search_and_rescue.mission"], &repo());
    assert_eq!(code, 0);
    assert!(out.contains("plan: the mission takes about"), "{out}");
    for drone in PAPER_DRONES {
        assert!(
            out.lines().any(|l| l.starts_with(&format!("{drone}: ")) && l.contains("battery left")),
            "no line for {drone}:\n{out}"
        );
    }
    // beacon_drone2 flies one beacon per body the world holds.
    assert_eq!(
        out.matches("DeployBeacon  (examples/search_and_rescue.mission:43:13)").count(),
        2,
        "{out}"
    );
}

#[test]
fn a_plan_needs_a_world_and_a_mission_without_errors() {
    let dir = scratch("plan_refusals");
    std::fs::write(dir.join("alone.mission"), "MISSION M:\n    scout TakeOff\n").expect("write");
    let (code, _, err) = aviary(&["check", "--plan", "alone.mission"], &dir);
    assert_eq!(code, 1);
    assert!(err.contains("no plan for alone.mission: a plan needs the world file"), "{err}");
    std::fs::write(dir.join("broken.mission"), "MISSION M:\n    scout TakeOf\n").expect("write");
    std::fs::write(dir.join("broken.world.toml"), "[drones.scout]\nhome = [0, 0]\n")
        .expect("write");
    let (code, out, err) = aviary(&["check", "--plan", "broken.mission"], &dir);
    assert_eq!(code, 1);
    assert!(out.contains("error[E101]") || out.contains("error["), "{out}");
    assert!(err.contains("fix its errors first"), "{err}");
}

#[test]
fn a_low_reserve_is_a_warning_in_check_and_flagged_in_the_plan() {
    let dir = scratch("plan_reserve");
    std::fs::write(
        dir.join("long.mission"),
        "MISSION Long:\n    spare TakeOff\n    spare Hover WITH 25min\n    spare ReturnHome\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("long.world.toml"),
        "[drones.spare]\nhome = [0, 0]\nendurance = 1800\n",
    )
    .expect("write");
    let (code, out, _) = aviary(&["check", "--plan", "--format", "json", "long.mission"], &dir);
    assert_eq!(code, 0, "a warning does not fail the check");
    let doc: serde_json::Value = serde_json::from_str(&out).expect("JSON");
    assert_eq!(doc["diagnostics"][0]["code"], "W204");
    let left = doc["plan"]["drones"][0]["battery_left"].as_f64().expect("battery");
    assert!(left < 0.2 && left > 0.1, "{left}");
}

#[test]
fn a_long_chain_of_capabilities_checks_plans_and_runs_without_overflowing() {
    let dir = scratch("deep_chain");
    let n = 5000;
    let mut text =
        String::from("MISSION M:\n    scout TakeOff\n    scout C0\n    scout ReturnHome\n");
    for i in 0..n {
        let body =
            if i + 1 < n { format!("drone C{}", i + 1) } else { "drone.Hover(1s)".to_string() };
        text.push_str(&format!("\nCAPABILITY C{i} BY drone:\n    PERFORM:\n        {body}\n"));
    }
    std::fs::write(dir.join("deep.mission"), text).expect("write");
    std::fs::write(dir.join("deep.world.toml"), "[drones.scout]\nhome = [0, 0]\n").expect("write");
    let (code, out, err) = aviary(&["check", "--plan", "deep.mission"], &dir);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("C0  (deep.mission:3:5)"), "{out}");
    let (code, out, err) = aviary(&["run", "deep.mission"], &dir);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("mission ok"), "{out}");
}

#[test]
fn a_capability_that_calls_itself_behind_a_condition_is_planned_once_with_a_note() {
    let dir = scratch("recursive_plan");
    std::fs::write(dir.join("rec.mission"), "MISSION M:\n    scout Loop\n\nCAPABILITY Loop BY drone:\n    PERFORM:\n        drone.Hover(1s)\n        IF drone.battery > 50%:\n            drone Loop\n").expect("write");
    std::fs::write(dir.join("rec.world.toml"), "[drones.scout]\nhome = [0, 0]\n").expect("write");
    let (code, out, err) = aviary(&["check", "--plan", "rec.mission"], &dir);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.contains("rec.mission:8:13: `Loop` calls itself; the estimate counts one round of it"),
        "{out}"
    );
}

#[test]
fn a_capability_that_calls_itself_unconditionally_is_an_error_with_no_plan() {
    let dir = scratch("recursive_error");
    std::fs::write(dir.join("rec.mission"), "MISSION M:\n    scout A\n\nCAPABILITY A BY d:\n    PERFORM:\n        d B\n\nCAPABILITY B BY d:\n    PERFORM:\n        d.Hover(1s)\n        d A\n").expect("write");
    std::fs::write(dir.join("rec.world.toml"), "[drones.scout]\nhome = [0, 0]\n").expect("write");
    let (code, out, err) = aviary(&["check", "--plan", "rec.mission"], &dir);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.starts_with("rec.mission:6:11: error[E126]: `A` calls itself through `B` with nothing to stop it: A → B → A"), "{out}");
    assert!(err.contains("no plan for rec.mission: fix its errors first"), "{err}");
    let (code, _, err) = aviary(&["run", "rec.mission"], &dir);
    assert_eq!(code, 2, "a mission with errors is not flown: {err}");
    assert!(
        err.contains("error[E126]") && err.contains("rec.mission has errors, so it was not run"),
        "{err}"
    );
    let (code, out, _) = aviary(&["explain", "E126"], &dir);
    assert_eq!(code, 0);
    assert!(out.starts_with("E126 (error): a capability that calls itself"), "{out}");
}

#[test]
fn a_recursion_that_never_ends_in_flight_fails_the_mission_with_command_failed_not_a_crash() {
    let dir = scratch("recursive_run");
    // Allowed (behind a condition), and the condition never turns false: no time passes.
    std::fs::write(dir.join("rec.mission"), "MISSION M:\n    scout Loop\n\nCAPABILITY Loop BY drone:\n    PERFORM:\n        IF drone.battery > 50%:\n            drone Loop\n").expect("write");
    std::fs::write(dir.join("rec.world.toml"), "[drones.scout]\nhome = [0, 0]\n").expect("write");
    let (code, out, err) = aviary(&["run", "rec.mission", "--trace", "rec.jsonl"], &dir);
    assert_eq!(code, 1, "{out}{err}");
    assert!(
        out.contains(
            "calling `Loop` would nest capability calls 10001 deep, past the limit of 10000"
        ),
        "{out}{err}"
    );
    let trace = std::fs::read_to_string(dir.join("rec.jsonl")).expect("trace");
    let events = Trace::parse(&trace);
    assert_eq!(events.events(EventKind::CapabilityStart).len(), 10_000);
    let last = events.last().expect("events");
    assert!(matches!(last.event, Event::MissionEnd { status: Status::Failed, .. }), "{last:?}");
}

#[test]
fn capabilities_that_fan_out_are_checked_and_planned_in_bounded_time() {
    let dir = scratch("fan_out");
    // Each capability calls the next ten times, twelve deep: 10^12 flights if every
    // call were followed. A few hundred bytes; it must not keep `aviary check` busy.
    let depth = 12;
    let mut text = String::from("MISSION M:\n    scout TakeOff WITH 20m\n    scout D0\n");
    for i in 0..depth {
        text.push_str(&format!("\nCAPABILITY D{i} BY drone:\n    PERFORM:\n"));
        for _ in 0..10 {
            text.push_str(&if i + 1 < depth {
                format!("        drone D{}\n", i + 1)
            } else {
                "        drone.FlyToPosition((10, 10))\n".into()
            });
        }
    }
    std::fs::write(dir.join("fan.mission"), text).expect("write");
    std::fs::write(dir.join("fan.world.toml"), "[site]\ngeofence = [[-100, -100], [100, -100], [100, 100], [-100, 100]]\n[drones.scout]\nhome = [0, 0]\n").expect("write");
    let (code, out, err) = aviary(&["check", "--plan", "fan.mission"], &dir);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("the capability calls fan out past what the estimate follows"), "{out}");
}
