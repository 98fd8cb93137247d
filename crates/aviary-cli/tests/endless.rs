//! Missions that would go on for ever at one instant, as a user runs them (issue 31): a
//! cycle of signals once wrote 71 GB of trace in 28 minutes, `aviary check` never ended
//! on it, and SIGTERM did not stop the run. Now `aviary check` warns of it (W209), the run
//! ends with the reason and the fleet home, a stop signal is heard at once, and a trace
//! never grows past its size limit.
//!
//! The missions are files, `tests/endless/*.mission` (flown in `tests/endless/world.toml`);
//! what `aviary check` and `aviary run` print for each is a snapshot. Every command here is
//! waited for a bounded time, then killed: a run that does not end fails the test.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use aviary_api::trace::{CallStatus, Event, EventKind, Record, Status};
use aviary_api::Function;
use aviary_test_support::trace::{is, Trace};
use common::{scratch, wait_at_most};

fn folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("endless")
}

/// `aviary ARGS` in `dir`, its standard output and error in files of `out`.
fn spawn(args: &[&str], dir: &Path, out: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdout(std::fs::File::create(out.join("stdout")).expect("stdout file"))
        .stderr(std::fs::File::create(out.join("stderr")).expect("stderr file"))
        .stdin(Stdio::null())
        .spawn()
        .expect("run aviary")
}

/// `aviary ARGS` in `dir`, waited for at most `limit`: exit code, stdout, stderr.
fn bounded(args: &[&str], dir: &Path, out: &Path, limit: Duration) -> (i32, String, String) {
    let mut child = spawn(args, dir, out);
    let code = wait_at_most(&mut child, limit, &format!("aviary {}", args.join(" ")));
    let read = |name: &str| std::fs::read_to_string(out.join(name)).unwrap_or_default();
    (code, read("stdout"), read("stderr"))
}

fn events(trace: &Path) -> Trace {
    let text = std::fs::read_to_string(trace).expect("the trace");
    assert!(text.is_empty() || text.ends_with('\n'), "the last line is whole");
    Trace::parse(&text)
}

fn brought_home(events: &[Record<'static>], drone: &str) -> bool {
    events.iter().any(|e| {
        matches!(&e.event, Event::ApiDone {
            function: Function::ReturnToLaunch, status: CallStatus::Ok, actor, ..
        } if actor == drone)
    })
}

/// How the mission ended, and why: the trace's last event, its `mission_end`.
fn ended<'a>(events: &'a [Record<'static>]) -> (Status, Option<&'a str>) {
    match &events.last().expect("an event").event {
        Event::MissionEnd { status, reason } => (*status, reason.as_deref()),
        other => panic!("the trace ends with {other:?}"),
    }
}

#[test]
fn every_endless_mission_is_warned_of_and_its_run_ends_with_the_reason() {
    let mut missions: Vec<String> = std::fs::read_dir(folder())
        .expect("tests/endless")
        .map(|e| e.expect("an entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".mission"))
        .collect();
    missions.sort();
    assert!(missions.len() >= 3);
    for name in missions {
        let out = scratch(&format!("endless_{name}"));
        let trace = out.join("t.jsonl");
        let (code, stdout, stderr) = bounded(
            &["check", &name, "--world", "world.toml"],
            &folder(),
            &out,
            Duration::from_secs(60),
        );
        assert_eq!(code, 0, "{name}: a warning, not an error:\n{stdout}{stderr}");
        let checked = format!("{stdout}{stderr}");
        assert!(checked.contains("warning[W209]"), "{name}:\n{checked}");
        let (code, ran, err) = bounded(
            &["run", &name, "--world", "world.toml", "--trace", &trace.to_string_lossy()],
            &folder(),
            &out,
            Duration::from_secs(60),
        );
        assert_eq!(code, 1, "{name}: the mission fails:\n{ran}{err}");
        assert!(ran.contains("mission failed: a cycle of signals at one instant: P/ON X"), "{ran}");
        let events = events(&trace);
        assert!(events.len() < 2_000, "{name}: {} events", events.len());
        let (status, reason) = ended(&events);
        assert_eq!(status, Status::Failed);
        assert!(
            reason.is_some_and(|r| r.starts_with("a cycle of signals at one instant")),
            "{reason:?}"
        );
        let airborne = !events.find(is::done(Function::TakeOff)).is_empty();
        assert!(
            !airborne || brought_home(&events, "d"),
            "{name}: the drone in the air is brought home"
        );
        insta::assert_snapshot!(
            name.trim_end_matches(".mission").to_string(),
            format!("$ aviary check {name}\n{checked}\n$ aviary run {name} (exit {code})\n{ran}")
        );
    }
}

/// A run whose engine is busy at one instant for a long time: 50,000 cycles of signals
/// at once, each cut off after 100 rounds, some 15 million events without the engine
/// waiting once (a minute and more of a debug build).
fn busy(dir: &Path) {
    std::fs::copy(folder().join("world.toml"), dir.join("busy.world.toml")).expect("the world");
    let signals: String = (0..50_000).map(|_| "        SIGNAL X\n").collect();
    std::fs::write(
        dir.join("busy.mission"),
        format!("MISSION Busy:\n    d TakeOff WITH 20m\n    PARALLEL P:\n{signals}        ON EVERY X:\n            SIGNAL X\n    d ReturnHome\n"),
    )
    .expect("the mission");
}

/// Waits until the trace shows the cycles going round.
fn wait_for_the_cycles(trace: &Path, child: &mut Child) {
    let start = Instant::now();
    loop {
        let text = std::fs::read_to_string(trace).unwrap_or_default();
        if text.matches("handler_start").count() > 1_000 {
            return;
        }
        if let Some(status) = child.try_wait().expect("wait") {
            panic!("the run ended before the cycles began: {status}");
        }
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("the cycles did not begin within 60 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn stop_signal_ends_a_busy_run(signal: &str, by: &str) {
    let dir = scratch(&format!("endless_busy_{signal}"));
    busy(&dir);
    let trace = dir.join("t.jsonl");
    let mut child = spawn(&["run", "busy.mission", "--trace", "t.jsonl", "--quiet"], &dir, &dir);
    wait_for_the_cycles(&trace, &mut child);
    let sent = Instant::now();
    let status = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
    let code = wait_at_most(&mut child, Duration::from_secs(15), "the interrupted run");
    assert_eq!(code, 1, "an aborted mission exits 1");
    assert!(sent.elapsed() < Duration::from_secs(15));
    let events = events(&trace);
    let reason = format!("interrupted by {by}");
    assert_eq!(
        ended(&events),
        (Status::Aborted, Some(reason.as_str())),
        "stopped by the signal, not at the end of the cycles"
    );
    assert_eq!(events.events(EventKind::MissionEnd).len(), 1);
    assert!(brought_home(&events, "d"), "the drone in the air is brought home");
}

#[test]
fn sigterm_stops_a_run_whose_engine_never_waits_and_the_fleet_comes_home() {
    stop_signal_ends_a_busy_run("TERM", "SIGTERM");
}

#[test]
fn sighup_and_ctrl_c_stop_it_alike() {
    stop_signal_ends_a_busy_run("HUP", "SIGHUP");
    stop_signal_ends_a_busy_run("INT", "Ctrl-C");
}

#[test]
fn a_trace_at_its_size_limit_ends_the_run_with_the_fleet_home_and_exit_3() {
    let dir = scratch("endless_trace_limit");
    busy(&dir);
    let (code, out, err) = bounded(
        &["run", "busy.mission", "--trace", "t.jsonl", "--max-trace-size", "64KiB"],
        &dir,
        &dir,
        Duration::from_secs(120),
    );
    assert_eq!(code, 3, "the trace is not whole:\n{out}\n{err}");
    let size = std::fs::metadata(dir.join("t.jsonl")).expect("the trace").len();
    assert!(size <= 64 * 1024, "{size} bytes");
    assert!(
        err.contains("aviary: the trace t.jsonl reached its size limit of 64 KiB (--max-trace-size); the mission stops, the fleet returns home, and aviary will exit 3"),
        "said at once:\n{err}"
    );
    assert!(
        err.contains("aviary: the trace t.jsonl is not whole: it reached its size limit of 64 KiB"),
        "{err}"
    );
    assert!(
        out.contains("mission aborted: the trace t.jsonl reached its size limit of 64 KiB (--max-trace-size)"),
        "the summary says why:\n{out}"
    );
    assert!(out.lines().any(|l| l.starts_with("d ") && l.ends_with("Landed")), "home:\n{out}");
    let events = events(&dir.join("t.jsonl"));
    assert_eq!(
        ended(&events),
        (Status::Aborted, Some("the trace reached its size limit of 64 KiB: the run was stopped here, its fleet sent home, and nothing after is recorded"))
    );
}

#[test]
fn a_size_limit_is_a_size() {
    let dir = scratch("endless_size_words");
    for (bad, why) in [
        ("lots", "is not a size for --max-trace-size"),
        ("1XB", "is not a size for --max-trace-size"),
        ("100", "is too small for --max-trace-size: a trace needs at least 4 KiB"),
        ("99999999999999TiB", "is not a size for --max-trace-size"),
    ] {
        let (code, _, err) = common::aviary(&["run", "m.mission", "--max-trace-size", bad], &dir);
        assert_eq!(code, 2, "{bad}: {err}");
        assert!(err.contains(why), "{bad}: {err}");
    }
}
