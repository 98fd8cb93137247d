//! Nothing is lost when a run is cut short: killed at random points, every line written
//! is a whole JSON event and the lines are exactly the start of the full trace (a
//! simulated run is deterministic, so the full trace is known); Ctrl-C ends gracefully,
//! and a second Ctrl-C stops at once, with `mission_end` written either way.

mod common;

use std::process::{Child, Command, Stdio};
use std::time::Duration;

use aviary_api::trace::{CallStatus, Event, EventKind, Record, Status};
use aviary_api::Function;
use aviary_test_support::trace::{is, Trace};
use common::{aviary, repo, scratch};

fn spawn(trace: &std::path::Path, speed: &str) -> Child {
    Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args([
            "run",
            "examples/search_and_rescue.mission",
            "--quiet",
            "--speed",
            speed,
            "--trace",
            &trace.to_string_lossy(),
        ])
        .current_dir(repo())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn aviary")
}

fn lines(path: &std::path::Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    assert!(text.is_empty() || text.ends_with('\n'), "the last line is whole");
    text.lines().map(str::to_string).collect()
}

/// The records of the trace at `path`: its lines, each whole.
fn records(path: &std::path::Path) -> Trace {
    Trace::parse(&lines(path).join("\n"))
}

fn interrupt(child: &Child) {
    send(child, "INT");
}

fn send(child: &Child, signal: &str) {
    let status = Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(status.success());
}

/// A small deterministic generator, so the "random" cut points are the same every run.
fn cut_points(seed: u64, n: usize) -> Vec<u64> {
    let mut x = seed;
    (0..n)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            100 + x % 3_800
        })
        .collect()
}

#[test]
fn a_killed_run_keeps_every_event_before_the_cut() {
    let dir = scratch("killed");
    let full = dir.join("full.jsonl");
    let (code, _, err) = aviary(
        &[
            "run",
            "examples/search_and_rescue.mission",
            "--quiet",
            "--trace",
            &full.to_string_lossy(),
        ],
        &repo(),
    );
    assert_eq!(code, 0, "{err}");
    let reference = lines(&full);
    for (i, ms) in cut_points(0x5eed, 4).into_iter().enumerate() {
        let cut = dir.join(format!("cut{i}.jsonl"));
        // 100 times real time: the 490 s mission takes about 4.9 s, and the cut lands inside it.
        let mut child = spawn(&cut, "100");
        std::thread::sleep(Duration::from_millis(ms));
        child.kill().expect("kill");
        child.wait().expect("wait");
        let written = lines(&cut);
        for (n, line) in written.iter().enumerate() {
            serde_json::from_str::<Record>(line)
                .unwrap_or_else(|e| panic!("cut at {ms} ms, line {}: {e}", n + 1));
        }
        assert!(written.len() < reference.len(), "cut at {ms} ms: the run was cut before its end");
        assert_eq!(
            written[..],
            reference[..written.len()],
            "cut at {ms} ms: no event before the cut is lost or changed"
        );
    }
}

/// One signal, as a first Ctrl-C: the mission is aborted with `reason`, every drone in
/// the air is brought home, and the trace ends with `mission_end` after those returns.
fn ends_gracefully_on(signal: &str, reason: &str) {
    let dir = scratch(&format!("graceful_{signal}"));
    let trace = dir.join("t.jsonl");
    let mut child = spawn(&trace, "20");
    std::thread::sleep(Duration::from_millis(1500));
    send(&child, signal);
    let status = child.wait().expect("wait");
    assert_eq!(status.code(), Some(1), "an aborted mission exits 1");
    let events = records(&trace);
    let end = events.last().unwrap();
    let Event::MissionEnd { status, reason: why } = &end.event else { panic!("{end:?}") };
    assert_eq!((*status, why.as_deref()), (Status::Aborted, Some(reason)));
    assert_eq!(events.events(EventKind::MissionEnd).len(), 1);
    let home: Vec<&str> = events
        .iter()
        .filter_map(|e| match &e.event {
            Event::ApiDone {
                function: Function::ReturnToLaunch,
                status: CallStatus::Ok,
                actor,
                ..
            } => Some(&**actor),
            _ => None,
        })
        .collect();
    assert!(home.contains(&"video_drone1"), "the drones in the air were brought home: {home:?}");
    // Ordering: the running activities are aborted first, then the drones are sent home,
    // and the trace ends only once every return has ended.
    let aborted = events
        .iter()
        .position(|e| matches!(e.event, Event::ApiDone { status: CallStatus::Aborted, .. }))
        .expect("activities were aborted");
    let first_home = events.index(is::call(Function::ReturnToLaunch));
    let last_home = events
        .iter()
        .rposition(|e| is::done(Function::ReturnToLaunch)(&e.event))
        .expect("a return ended");
    assert!(
        aborted < first_home && last_home < events.len() - 1,
        "abort, then returns, then mission_end"
    );
}

#[test]
fn ctrl_c_ends_the_mission_with_the_fleet_home() {
    ends_gracefully_on("INT", "interrupted by Ctrl-C");
}

#[test]
fn sigterm_ends_the_mission_like_a_first_ctrl_c() {
    ends_gracefully_on("TERM", "interrupted by SIGTERM");
}

#[test]
fn sighup_ends_the_mission_like_a_first_ctrl_c() {
    ends_gracefully_on("HUP", "interrupted by SIGHUP");
}

#[test]
fn a_second_ctrl_c_stops_at_once_and_still_closes_the_trace() {
    let dir = scratch("ctrl_c_twice");
    let trace = dir.join("t.jsonl");
    let mut child = spawn(&trace, "2");
    std::thread::sleep(Duration::from_millis(1500));
    interrupt(&child);
    std::thread::sleep(Duration::from_millis(300));
    interrupt(&child);
    let status = child.wait().expect("wait");
    assert_eq!(status.code(), Some(130));
    let written = lines(&trace);
    let end: Record = serde_json::from_str(written.last().unwrap()).unwrap();
    let Event::MissionEnd { reason, .. } = &end.event else { panic!("{end:?}") };
    assert_eq!(reason.as_deref(), Some("stopped at once by a second Ctrl-C"));
    assert_eq!(written.iter().filter(|l| l.contains("\"mission_end\"")).count(), 1);
}

/// A run whose one drone is a MAVLink vehicle that never answers (a UDP address nobody
/// sends to): it waits up to 15 s for it before the mission starts.
fn connecting(dir: &std::path::Path) -> Child {
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .expect("a free port")
        .local_addr()
        .expect("addr")
        .port();
    std::fs::write(dir.join("m.mission"), "MISSION Waiting:\n    d TakeOff WITH 10m\n")
        .expect("mission");
    std::fs::write(dir.join("m.world.toml"), format!("[site]\norigin = {{ lat = 46.6, lon = 14.2, alt = 440 }}\n[drones.d]\nhome = [0, 0]\nmavlink = \"udp:127.0.0.1:{port}\"\n")).expect("world");
    Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", "m.mission", "--trace", "t.jsonl"])
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn aviary")
}

fn wait_at_most(child: &mut Child, limit: Duration) -> std::process::ExitStatus {
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            return status;
        }
        assert!(start.elapsed() < limit, "still running after {limit:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn ctrl_c_while_the_vehicles_connect_stops_at_once_with_a_whole_trace() {
    let dir = scratch("interrupt_connecting");
    let mut child = connecting(&dir);
    std::thread::sleep(Duration::from_millis(800));
    interrupt(&child);
    // Not the 15 s the connection would wait.
    let status = wait_at_most(&mut child, Duration::from_secs(3));
    assert_eq!(status.code(), Some(1));
    let out = child.wait_with_output().expect("output");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains(
            "mission aborted: stopped by Ctrl-C while the vehicles connected; nothing flew"
        ),
        "{stdout}"
    );
    let events = records(&dir.join("t.jsonl"));
    assert_eq!(
        events.iter().map(|e| e.event.kind()).collect::<Vec<_>>(),
        [EventKind::MissionStart, EventKind::MissionEnd]
    );
    let (Event::MissionStart { mission, .. }, Event::MissionEnd { status, .. }) =
        (&events[0].event, &events[1].event)
    else {
        unreachable!()
    };
    assert_eq!((&**mission, *status), ("Waiting", Status::Aborted));
}

#[test]
fn two_quick_stops_while_the_vehicles_connect_leave_a_whole_trace() {
    let dir = scratch("interrupt_connecting_twice");
    let mut child = connecting(&dir);
    std::thread::sleep(Duration::from_millis(800));
    send(&child, "TERM");
    std::thread::sleep(Duration::from_millis(5));
    let _ = Command::new("kill").args(["-TERM", &child.id().to_string()]).status();
    wait_at_most(&mut child, Duration::from_secs(3));
    let events = records(&dir.join("t.jsonl"));
    let kinds: Vec<EventKind> = events.iter().map(|e| e.event.kind()).collect();
    assert_eq!(
        kinds,
        [EventKind::MissionStart, EventKind::MissionEnd],
        "whole, whichever stop came first"
    );
}
