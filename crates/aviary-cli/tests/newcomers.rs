//! Two of the newcomers' scenarios (examples/), flown as a user flies them, each proven
//! from its trace: the wildfire perimeter, whose tired drone hands its side to the
//! reserve, and the bridge inspection, which the operator holds for traffic through the
//! operator API.

mod common;

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use aviary_api::trace::{CallStatus, Event, EventKind, Record, Shown};
use aviary_api::Function;
use aviary_test_support::trace::{actor, is, Trace};
use common::{aviary, repo, scratch};
use serde_json::Value;

fn read_trace(path: &std::path::Path) -> Trace {
    Trace::read(path)
}

fn t(e: &Record) -> f64 {
    e.t
}

/// Telemetry of one drone: (t, position).
fn track(trace: &Trace, drone: &str) -> Vec<(f64, [f64; 3])> {
    trace.positions(drone)
}

/// How far a point is, over the ground, from the segment `a`–`b`.
fn off_segment(p: [f64; 3], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let along = ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy);
    let s = along.clamp(0.0, 1.0);
    (p[0] - a[0] - s * dx).hypot(p[1] - a[1] - s * dy)
}

/// The east side of the fire perimeter (examples/wildfire_perimeter.world.toml).
const NE: [f64; 2] = [350.0, 250.0];
const SE: [f64; 2] = [350.0, -250.0];
/// A side is watched while a drone flies over it: at most this far from it over the
/// ground (the thermal camera's range, 30 m), at least 20 m up.
const WATCHING: f64 = 30.0;
/// The watch lasts twenty minutes (`Watch_Side WITH from, to, 20min`).
const WATCH_ENDS: f64 = 1200.0;

#[test]
fn the_reserve_takes_over_the_tired_drones_side_and_it_is_never_unwatched() {
    let dir = scratch("newcomers_wildfire");
    let mission = "examples/wildfire_perimeter.mission";
    // One warning, on purpose: the plan sees that east_watch cannot last the watch.
    let (code, out, err) = aviary(&["check", mission, "--format", "json"], &repo());
    assert_eq!(code, 0, "{out}{err}");
    let codes: Vec<String> = out
        .lines()
        .map(|l| serde_json::from_str::<Value>(l).expect("a diagnostic is JSON"))
        .map(|d| d["code"].as_str().unwrap_or_default().to_string())
        .collect();
    assert_eq!(codes, ["W204"], "{out}");

    let trace_path = dir.join("wildfire.jsonl");
    let trace_arg = trace_path.to_string_lossy().to_string();
    let (code, out, err) =
        aviary(&["run", mission, "--quiet", "--telemetry-hz", "1", "--trace", &trace_arg], &repo());
    assert_eq!(code, 0, "{out}{err}");
    let trace = read_trace(&trace_path);

    // BatteryLow of east_watch, heard inside its patrol (the capability's own handler).
    let low = trace.first(is::signal("BatteryLow"));
    assert_eq!(
        actor(&low.event),
        Some("east_watch"),
        "only east_watch started the day half charged"
    );
    let heard = trace.first(is::handler_start("BatteryLow"));
    let Event::HandlerStart { handler, .. } = &heard.event else { unreachable!() };
    assert_eq!((&**handler, t(heard)), ("Watch_Side/ON BatteryLow", t(low)));

    // The reserve takes over the east side after that, and flies it end to end.
    let takes_over = trace.first(|e| {
        matches!(e, Event::CapabilityStart { actor, capability, .. }
            if actor == "reserve" && capability == "Watch_Side")
    });
    assert!(t(takes_over) > t(low));
    let Event::CapabilityStart { args, .. } = &takes_over.event else { unreachable!() };
    let xy = |name: &str| match args.get(name) {
        Some(Shown::Position(p)) => [p.x, p.y],
        other => panic!("{name}: not a position: {other:?}"),
    };
    assert_eq!((xy("from"), xy("to")), (NE, SE), "the tired drone's side");
    let reserve = track(&trace, "reserve");
    let passes = |corner: [f64; 2]| {
        reserve
            .iter()
            .any(|(s, p)| *s > t(takes_over) && (p[0] - corner[0]).hypot(p[1] - corner[1]) < 5.0)
    };
    assert!(passes(NE) && passes(SE), "the reserve flies the side from end to end");

    // The tired drone goes home once the reserve is there, and lands.
    let on_station = trace.first(is::signal("Relief_On_Station"));
    let home_start = trace.first(|e| {
        matches!(e, Event::CapabilityStart { actor, capability, .. }
            if actor == "east_watch" && capability == "ReturnHome")
    });
    assert_eq!(t(home_start), t(on_station), "relieved on the spot");
    let east = track(&trace, "east_watch");
    let (_, last) = east.last().expect("east_watch's telemetry");
    assert!((last[0] + 10.0).hypot(last[1] + 450.0) < 0.01 && last[2] < 0.01, "{last:?}");

    // Never unwatched: from the moment east_watch first reaches its side until the watch
    // ends, every second (each telemetry sample) east_watch or the reserve is over it.
    let over = |p: &[f64; 3]| off_segment(*p, NE, SE) <= WATCHING && p[2] >= 20.0;
    let arrived = east.iter().find(|(_, p)| over(p)).expect("east_watch reaches its side").0;
    let samples: Vec<f64> =
        east.iter().map(|(s, _)| *s).filter(|s| *s >= arrived && *s <= WATCH_ENDS).collect();
    assert!(samples.len() > 1000, "twenty minutes, a sample a second");
    let at = |list: &[(f64, [f64; 3])], s: f64| list.iter().find(|(u, _)| *u == s).map(|(_, p)| *p);
    let unwatched: Vec<f64> = samples
        .iter()
        .copied()
        .filter(|s| ![at(&east, *s), at(&reserve, *s)].iter().flatten().any(over))
        .collect();
    assert!(unwatched.is_empty(), "the east side was unwatched at {unwatched:?} s");
}

/// How long the operator's hold lasts: the section's `drone.Hover(30s)`.
const HOLD: f64 = 30.0;
/// The telemetry step of the served run below (`--telemetry-hz 10`).
const STEP: f64 = 0.1;

#[test]
fn the_operator_holds_the_bridge_inspection_30_s_then_it_finishes() {
    let dir = scratch("newcomers_bridge");
    let mission = repo().join("examples/bridge_inspection.mission");
    let (code, out, err) = aviary(&["check", &mission.to_string_lossy()], &dir);
    assert_eq!((code, out.contains("ok"), err.as_str()), (0, true, ""), "{out}");

    // A served run, 40 times real time, as an operator would start it.
    let mut run = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", &mission.to_string_lossy(), "--serve", "0", "--speed", "40"])
        .args(["--telemetry-hz", "10", "--quiet", "--trace", "t.jsonl"])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn aviary run");
    let mut line = String::new();
    BufReader::new(run.stderr.take().expect("stderr")).read_line(&mut line).expect("announced");
    // aviary: operator API on http://127.0.0.1:PORT  token TOKEN
    let url = line.split_whitespace().find(|w| w.starts_with("http://")).expect("url").to_string();
    let token = line.split_whitespace().last().expect("token").to_string();

    // Watching the live events, the operator steps in once the drone is on its slow pass
    // along the bridge (its first FlyToPosition at 2 m/s).
    let mut events = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["ctl", "--url", &url, "events"])
        .current_dir(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn aviary ctl events");
    let (seen, on_pass) = mpsc::channel();
    let stream = events.stdout.take().expect("stdout");
    std::thread::spawn(move || {
        for line in BufReader::new(stream).lines().map_while(Result::ok) {
            let e: Option<Record> = serde_json::from_str(&line).ok();
            let slow_pass = e.is_some_and(|e| {
                matches!(&e.event, Event::ApiCall { function: Function::FlyToPosition, args, .. }
                    if args.len() == 2)
            });
            if slow_pass {
                let _ = seen.send(());
            }
        }
    });
    on_pass.recv_timeout(Duration::from_secs(60)).expect("the inspection pass begins");
    let (code, out, err) = aviary(
        &[
            "ctl",
            "--url",
            &url,
            "--token",
            &token,
            "leash",
            "Inspect_Bridge-Span",
            "Hold_For_Traffic",
        ],
        &dir,
    );
    assert_eq!(code, 0, "{out}{err}");
    assert_eq!(run.wait().expect("the run ends").code(), Some(0), "the mission ends ok");
    let _ = events.wait();

    let trace = read_trace(&dir.join("t.jsonl"));
    let leash =
        trace.first(|e| matches!(e, Event::Leash { action, .. } if action == "Hold_For_Traffic"));
    let t0 = t(leash);
    let hover = trace.find(|e| is::call(Function::Hover)(e) || is::done(Function::Hover)(e));
    assert_eq!(hover.len(), 2, "the section's hover, made and done");
    assert_eq!(t(hover[0]), t0, "the section starts at once");
    assert!((t(hover[1]) - (t0 + HOLD)).abs() < 1e-6, "and holds 30 s");

    // Held where it was on the pass, 30 s to within the telemetry step, then on again:
    // the samples from the first after the leash on (one at the leash's instant may come
    // before it), while the position stays the same.
    let inspector = track(&trace, "inspector");
    let from = inspector.iter().position(|(s, _)| *s > t0).expect("a sample after the leash");
    let (first, held) = inspector[from];
    assert!(first - t0 <= STEP + 1e-9, "the hold starts at once");
    assert!(
        held[0] > -150.0 && held[0] < 150.0 && held[1] == 20.0,
        "on the upstream pass: {held:?}"
    );
    let still = inspector[from..].iter().take_while(|(_, p)| *p == held).count();
    let last = inspector[from + still - 1].0;
    assert!((last - first - HOLD).abs() <= STEP + 1e-9, "held from {first} s to {last} s");
    assert!(inspector.get(from + still).is_some(), "the inspection goes on after the hold");

    // And the inspection finished: every leg flown, none failed, the whole pass and back.
    assert!(trace.events(EventKind::Exception).is_empty(), "nothing failed");
    let legs: Vec<(f64, CallStatus, [f64; 3])> = trace
        .iter()
        .filter_map(|e| match e.event {
            Event::ApiDone { function: Function::FlyToPosition, status, position, .. } => {
                Some((e.t, status, position))
            }
            _ => None,
        })
        .collect();
    assert_eq!(legs.len(), 4);
    assert!(legs.iter().all(|e| e.1 == CallStatus::Ok));
    assert_eq!(legs[1].2, [150.0, 20.0, 12.0], "the held pass reached its end");
    assert_eq!(legs[3].2, [-150.0, -20.0, 12.0], "and the pass back");
    assert!(legs[1].0 > t0 + HOLD);
    let inspected = trace.first(is::end_of("Inspect_Bridge"));
    assert!(matches!(
        inspected.event,
        Event::CapabilityEnd { status: aviary_api::trace::Status::Ok, .. }
    ));
}
