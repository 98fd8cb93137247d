//! `aviary run` as a user runs it: the paper's mission flies to its end, the trace is
//! valid against the trace's schema (docs/trace.schema.json) line by line, and the same
//! files give the same bytes.

mod common;

use aviary_api::trace::{AutopilotAction, Event, EventKind};
use aviary_api::FlightState;
use aviary_test_support::trace::Trace;
use common::{aviary, repo, scratch};

/// The schema of one trace line: the shared contract's copy when it is there, else ours.
fn schema() -> serde_json::Value {
    let shared = repo().join("../shared/trace.schema.json");
    let ours = repo().join("docs/trace.schema.json");
    let text = std::fs::read_to_string(&shared)
        .or_else(|_| std::fs::read_to_string(&ours))
        .expect("trace.schema.json");
    serde_json::from_str(&text).expect("the schema is JSON")
}

#[test]
fn the_paper_mission_runs_and_its_trace_fits_the_schema() {
    let dir = scratch("paper_run");
    let trace = dir.join("trace.jsonl");
    let trace_arg = trace.to_string_lossy().into_owned();
    let (code, out, err) = aviary(
        &[
            "run",
            "examples/search_and_rescue.mission",
            "--trace",
            &trace_arg,
            "--telemetry-hz",
            "1",
        ],
        &repo(),
    );
    assert_eq!(code, 0, "{out}\n{err}");
    assert!(out.contains("mission ok"), "{out}");
    assert!(out.contains("detections: 3"), "{out}");
    for drone in ["video_drone1", "flir_drone2", "beacon_drone2"] {
        let line = out
            .lines()
            .find(|l| l.starts_with(drone))
            .unwrap_or_else(|| panic!("{drone} in the summary: {out}"));
        assert!(line.ends_with("Landed"), "{line}");
    }
    let validator = jsonschema::validator_for(&schema()).expect("a valid schema");
    let text = std::fs::read_to_string(&trace).unwrap();
    let mut last_t = 0.0;
    let mut kinds = std::collections::BTreeSet::new();
    for (n, line) in text.lines().enumerate() {
        let event: serde_json::Value =
            serde_json::from_str(line).unwrap_or_else(|e| panic!("line {}: {e}", n + 1));
        let errors: Vec<String> = validator.iter_errors(&event).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "line {}: {line}\n{errors:#?}", n + 1);
        let t = event["t"].as_f64().unwrap();
        assert!(t >= last_t, "line {}: time goes forward", n + 1);
        last_t = t;
        kinds.insert(event["event"].as_str().unwrap().to_string());
    }
    for kind in [
        "mission_start",
        "block_start",
        "block_end",
        "capability_start",
        "capability_end",
        "api_call",
        "api_done",
        "signal",
        "handler_start",
        "handler_end",
        "detection",
        "telemetry",
        "mission_end",
    ] {
        assert!(kinds.contains(kind), "the paper's trace has {kind} events");
    }
}

#[test]
fn the_same_files_and_seed_give_the_same_trace_byte_for_byte() {
    let dir = scratch("determinism");
    let (a, b) = (dir.join("a.jsonl"), dir.join("b.jsonl"));
    for t in [&a, &b] {
        let (code, _, err) = aviary(
            &[
                "run",
                "examples/search_and_rescue.mission",
                "--seed",
                "7",
                "--quiet",
                "--trace",
                &t.to_string_lossy(),
            ],
            &repo(),
        );
        assert_eq!(code, 0, "{err}");
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

/// The trace of `mission` in `dir`, run with these extra arguments.
fn trace_of(dir: &std::path::Path, mission: &str, extra: &[&str], name: &str) -> Vec<u8> {
    let trace = dir.join(name);
    let mut args = vec!["run", mission, "--quiet", "--trace"];
    let trace_arg = trace.to_string_lossy().into_owned();
    args.push(&trace_arg);
    args.extend_from_slice(extra);
    let (code, _, err) = aviary(&args, dir);
    assert_eq!(code, 0, "{err}");
    std::fs::read(&trace).unwrap()
}

#[test]
fn a_world_without_chances_gives_one_trace_whatever_the_seed() {
    let dir = scratch("seed_free");
    let paper = repo().join("examples/search_and_rescue.mission");
    let paper = paper.to_string_lossy();
    let without = trace_of(&dir, &paper, &[], "none.jsonl");
    for seed in ["0", "1", "18446744073709551615"] {
        assert!(
            without == trace_of(&dir, &paper, &["--seed", seed], "seeded.jsonl"),
            "--seed {seed}"
        );
    }
}

/// A swarm whose thermal cameras find a body with a chance of one half: the seed decides
/// what is found, the same seed the same, and no `--seed` is seed 0.
#[test]
fn the_seed_draws_the_chances_a_world_asks_for() {
    let dir = scratch("seeded");
    let (code, mission, _) = aviary(&["bench", "swarm", "--drones", "36", "--emit"], &dir);
    assert_eq!(code, 0);
    let (code, world, _) = aviary(&["bench", "swarm", "--drones", "36", "--emit-world"], &dir);
    assert_eq!(code, 0);
    assert!(world.contains("range = 15.0\n"), "{world}");
    std::fs::write(dir.join("swarm.mission"), mission).unwrap();
    std::fs::write(
        dir.join("swarm.world.toml"),
        world.replace("range = 15.0\n", "range = 15.0\nprobability = 0.5\n"),
    )
    .unwrap();
    let found = |trace: &[u8]| {
        String::from_utf8_lossy(trace)
            .lines()
            .filter(|l| l.contains("\"event\":\"detection\""))
            .count()
    };
    let one = trace_of(&dir, "swarm.mission", &["--seed", "1"], "one.jsonl");
    assert!(one == trace_of(&dir, "swarm.mission", &["--seed", "1"], "again.jsonl"));
    let two = trace_of(&dir, "swarm.mission", &["--seed", "2"], "two.jsonl");
    assert!(one != two, "seeds 1 and 2 give the same trace");
    // 12 bodies, each found with a chance of one half.
    for trace in [&one, &two] {
        assert!((1..12).contains(&found(trace)), "{} found", found(trace));
    }
    let zero = trace_of(&dir, "swarm.mission", &["--seed", "0"], "zero.jsonl");
    assert!(zero == trace_of(&dir, "swarm.mission", &[], "default.jsonl"), "no --seed is seed 0");
}

#[test]
fn exit_codes_follow_runtime_md() {
    let dir = scratch("run_exits");
    std::fs::write(dir.join("m.world.toml"), "[drones.d1]\nhome = [0, 0]\n").unwrap();
    std::fs::write(
        dir.join("m.mission"),
        "MISSION M:\n    d1 TakeOff WITH 20m\n    THROW EXCEPTION Broken\n",
    )
    .unwrap();
    let (code, out, _) = aviary(&["run", "m.mission"], &dir);
    assert_eq!(code, 1, "an unhandled exception fails the mission: {out}");
    assert!(out.contains("mission failed: unhandled exception Broken on the mission"), "{out}");
    std::fs::write(dir.join("m.mission"), "MISSION M:\n    d1 TakeOff WITH 20s\n").unwrap();
    let (code, _, err) = aviary(&["run", "m.mission"], &dir);
    assert_eq!(code, 2, "a mission with errors is not run");
    assert!(err.contains("error[E107]") && err.contains("was not run"), "{err}");
    std::fs::write(
        dir.join("lib.mission"),
        "CAPABILITY Up BY d:\n    PERFORM:\n        d.TakeOff(5m)\n",
    )
    .unwrap();
    let (code, _, err) = aviary(&["run", "lib.mission", "--world", "m.world.toml"], &dir);
    assert_eq!(code, 2);
    assert!(err.contains("no MISSION to run"), "{err}");
    std::fs::write(dir.join("alone.mission"), "MISSION M:\n    SIGNAL Hi\n").unwrap();
    let (code, _, err) = aviary(&["run", "alone.mission"], &dir);
    assert_eq!(code, 2);
    assert!(err.contains("has no world file"), "{err}");
    let (code, _, err) = aviary(&["run", "m.mission", "--speed", "fast"], &dir);
    assert_eq!(code, 2);
    assert!(err.contains("not a speed"), "{err}");
}

#[test]
fn a_speed_paces_the_run_against_the_wall_clock() {
    let dir = scratch("speed");
    std::fs::write(dir.join("m.world.toml"), "[drones.d1]\nhome = [0, 0]\n").unwrap();
    std::fs::write(dir.join("m.mission"), "MISSION M:\n    d1 Hover WITH 1s\n").unwrap();
    let started = std::time::Instant::now();
    let (code, _, err) = aviary(&["run", "m.mission", "--speed", "2", "--quiet"], &dir);
    assert_eq!(code, 0, "{err}");
    // 1 s of mission time at twice real time: at least half a second of wall time.
    assert!(started.elapsed() >= std::time::Duration::from_millis(450), "{:?}", started.elapsed());
}

#[test]
fn an_unhandled_crash_exits_1_with_the_others_home() {
    let dir = scratch("unhandled_crash");
    std::fs::write(dir.join("m.world.toml"), "[places]\nFar = [0, 300]\n[drones.a]\nhome = [0, 0]\n[drones.b]\nhome = [10, 0]\n[[faults]]\ndrone = \"a\"\nat = 10.0\nkind = \"crash\"\n").unwrap();
    std::fs::write(
        dir.join("m.mission"),
        "MISSION M:\n    PARALLEL:\n        a FlyTo WITH Far\n        b FlyTo WITH Far\n",
    )
    .unwrap();
    let (code, out, _) = aviary(&["run", "m.mission", "--trace", "t.jsonl"], &dir);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("mission failed: unhandled exception DroneLost on a"), "{out}");
    let trace = std::fs::read_to_string(dir.join("t.jsonl")).unwrap();
    assert!(
        trace.lines().any(|l| l.contains("\"function\":\"ReturnToLaunch\"")
            && l.contains("\"actor\":\"b\"")
            && l.contains("\"status\":\"ok\"")),
        "b is brought home"
    );
    let b = out.lines().find(|l| l.starts_with("b ")).unwrap();
    assert!(b.ends_with("Landed"), "{b}");
    let a = out.lines().find(|l| l.starts_with("a ")).unwrap();
    assert!(a.ends_with("Lost"), "{a}");
}

#[test]
fn in_the_trace_no_two_airborne_drones_come_closer_than_min_separation() {
    let dir = scratch("separation");
    let trace = dir.join("t.jsonl");
    let (code, _, err) = aviary(
        &[
            "run",
            "examples/search_and_rescue.mission",
            "--quiet",
            "--telemetry-hz",
            "20",
            "--trace",
            &trace.to_string_lossy(),
        ],
        &repo(),
    );
    assert_eq!(code, 0, "{err}");
    let mut by_time: std::collections::BTreeMap<u64, Vec<[f64; 3]>> = Default::default();
    for e in Trace::read(&trace).iter() {
        let Event::Telemetry { state, position: p, .. } = e.event else { continue };
        let airborne =
            matches!(state, FlightState::TakingOff | FlightState::Flying | FlightState::Landing);
        if airborne {
            assert!(p.iter().all(|c| c.is_finite()), "{e:?}");
        }
        if airborne && p[2] > 0.0 {
            by_time.entry(e.t.to_bits()).or_default().push(p);
        }
    }
    assert!(by_time.len() > 5000, "telemetry at 20 Hz over the whole mission");
    let mut closest = f64::INFINITY;
    for drones in by_time.values() {
        for (i, a) in drones.iter().enumerate() {
            for b in &drones[i + 1..] {
                closest = closest.min(
                    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt(),
                );
            }
        }
    }
    assert!(closest >= 5.0 - 1e-6, "two drones in the air came within {closest} m");
}

#[test]
fn a_trace_that_cannot_be_written_is_said_at_once_and_exits_3_after_a_whole_flight() {
    // /dev/full takes the open and refuses every write, as a full disk does.
    let (code, out, err) =
        aviary(&["run", "examples/search_and_rescue.mission", "--trace", "/dev/full"], &repo());
    assert_eq!(code, 3, "{out}\n{err}");
    assert!(
        err.contains("cannot write the trace /dev/full") && err.contains("No space left"),
        "{err}"
    );
    // Said once, not once per event.
    assert_eq!(err.matches("cannot write the trace").count(), 1, "{err}");
    // The fleet flew the mission to its end all the same.
    assert!(out.contains("mission ok"), "{out}");
    assert!(out.lines().filter(|l| l.ends_with("Landed")).count() == 7, "every drone down:\n{out}");
}

/// A handler whose work fails at once takes its own exception again at the same instant:
/// the run passes it over after 100 re-entries instead of looping for ever (which once
/// filled a disk with its trace, and took no SIGTERM), fails, and brings the fleet home.
#[test]
fn a_handler_that_fails_at_once_ends_the_run_instead_of_looping() {
    let dir = scratch("reentered");
    std::fs::write(
        dir.join("m.world.toml"),
        "[places]\nFar = [0, 300]\n[drones.a]\nhome = [0, 0]\n[drones.c]\nhome = [10, 0]\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("m.mission"),
        "MISSION M:\n    a TakeOff WITH 20m\n    SEQUENTIAL Stream:\n        c StartStreaming\n        ON EXCEPTION CommandFailed BY c:\n            c StartStreaming\n    a FlyTo WITH Far\n",
    )
    .unwrap();
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", "m.mission", "--trace", "t.jsonl"])
        .current_dir(&dir)
        .env("NO_COLOR", "1")
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("run aviary");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for aviary") {
            break status;
        }
        if std::time::Instant::now() > deadline {
            child.kill().expect("kill aviary");
            panic!("the run did not end within 60 s");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let mut out = String::new();
    std::io::Read::read_to_string(&mut child.stdout.take().unwrap(), &mut out).unwrap();
    assert_eq!(status.code(), Some(1), "{out}");
    assert!(
        out.contains("mission failed: unhandled exception CommandFailed on c: c has no camera; its handler Stream/ON EXCEPTION CommandFailed, line 5, re-entered 100 times at t = 7.7 s without time passing, so it did not take it again"),
        "{out}"
    );
    assert!(
        out.contains(
            "exceptions: CommandFailed on c (handled) ×101, CommandFailed on c (unhandled)"
        ),
        "{out}"
    );
    let trace = std::fs::read_to_string(dir.join("t.jsonl")).unwrap();
    assert!(trace.lines().count() < 1000, "{} lines", trace.lines().count());
    assert!(!trace.contains("\"FlyToPosition\""), "nothing new starts");
    assert!(
        trace.lines().any(|l| l.contains("\"function\":\"ReturnToLaunch\"")
            && l.contains("\"actor\":\"a\"")
            && l.contains("\"status\":\"ok\"")),
        "a is brought home"
    );
    assert!(trace.lines().last().unwrap().contains("\"event\":\"mission_end\""));
}

/// What a drone's autopilot does on its own is in the trace, after the fault behind it, and
/// in the summary, with the drone of every exception.
#[test]
fn a_drone_acting_on_its_own_is_in_the_trace_and_the_summary() {
    let dir = scratch("autopilot_run");
    let drill = repo().join("examples/faults");
    std::fs::copy(drill.join("link_loss.mission"), dir.join("drill.mission")).unwrap();
    // The link-loss drill with an outage longer than `link_loss_rtl_after` (10 s): the
    // scout holds where it is, then flies home on its own.
    let world = std::fs::read_to_string(drill.join("link_loss.world.toml")).unwrap();
    assert!(world.contains("duration = 5.0"));
    std::fs::write(
        dir.join("drill.world.toml"),
        world.replace("duration = 5.0", "duration = 30.0"),
    )
    .unwrap();
    let (code, out, err) = aviary(&["run", "drill.mission", "--trace", "t.jsonl"], &dir);
    assert_eq!(code, 0, "{out}{err}");
    let trace = Trace::read(&dir.join("t.jsonl"));
    let autopilot: Vec<(f64, &str, AutopilotAction)> = trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::Autopilot { actor, action, .. } => Some((e.t, &**actor, *action)),
            _ => None,
        })
        .collect();
    assert_eq!(autopilot.len(), 2, "{autopilot:?}");
    assert_eq!(
        (autopilot[0].0, autopilot[0].1, autopilot[0].2),
        (20.0, "scout", AutopilotAction::Hold)
    );
    assert_eq!((autopilot[1].1, autopilot[1].2), ("scout", AutopilotAction::ReturnHome));
    assert!(
        (autopilot[1].0 - 30.0).abs() <= 0.05 + 1e-9,
        "10 s after the link went: {autopilot:?}"
    );
    // The fault's exception comes first, then what the autopilot does about it.
    let lost = trace.index(|e| e.kind() == EventKind::Exception);
    let held = trace.index(|e| e.kind() == EventKind::Autopilot);
    assert!(
        matches!(&trace[lost].event, Event::Exception { name, .. } if name == "ConnectionLost")
    );
    assert!(lost < held);
    assert!(out.contains("exceptions: ConnectionLost on scout (handled)\n"), "{out}");
    assert!(out.contains("operator actions: none\n"), "{out}");
    assert!(
        out.contains(
            "autopilot, on its own: scout: link lost: holds where it is (at 20.0 s); \
             scout: no link for 10 s: returns to launch on its own (at 30."
        ),
        "{out}"
    );
}

/// The paper's world with every part of `[air]`.
fn paper_in_the_air(dir: &std::path::Path) {
    let world = std::fs::read_to_string(repo().join("examples/search_and_rescue.world.toml"))
        .expect("the paper's world");
    let air = "\n[air.wind]\nspeed = 4\nfrom = 250\nturbulence = \"light\"\n\n[air.gps]\nerror = 2\n\n[air.detection]\nfalloff = \"linear\"\n\n[air.battery]\ncapacity_spread = 0.05\n\n[air.faults]\ngps_loss = 1\n";
    std::fs::write(dir.join("paper.world.toml"), world + air).unwrap();
    let mission = std::fs::read_to_string(repo().join("examples/search_and_rescue.mission"))
        .expect("the paper's mission");
    std::fs::write(dir.join("paper.mission"), mission).unwrap();
}

#[test]
fn with_air_the_same_seed_gives_the_same_trace_and_another_seed_another() {
    let dir = scratch("air_determinism");
    paper_in_the_air(&dir);
    let one = |name| {
        let trace = dir.join(name);
        let args = ["run", "paper.mission", "--quiet", "--seed", "3", "--trace"];
        let mut args: Vec<&str> = args.to_vec();
        let t = trace.to_string_lossy().into_owned();
        args.push(&t);
        let (code, out, err) = aviary(&args, &dir);
        assert!(code == 0 || code == 1, "{out}\n{err}");
        std::fs::read(&trace).unwrap()
    };
    let (a, b) = (one("a.jsonl"), one("b.jsonl"));
    assert!(a == b, "seed 3 gave two traces");
    let other = dir.join("c.jsonl");
    let t = other.to_string_lossy().into_owned();
    let (code, _, err) =
        aviary(&["run", "paper.mission", "--quiet", "--seed", "4", "--trace", &t], &dir);
    assert!(code == 0 || code == 1, "{err}");
    assert!(a != std::fs::read(&other).unwrap(), "seeds 3 and 4 gave one trace");
}

#[test]
fn a_drone_with_a_wind_sensor_reads_the_wind() {
    let dir = scratch("wind_reading");
    std::fs::write(
        dir.join("m.mission"),
        "MISSION M:\n    d TakeOff WITH 20m\n    IF d.wind > 3m/s:\n        THROW EXCEPTION Windy\n",
    )
    .unwrap();
    let air = "[air.wind]\nspeed = 5\nfrom = 90\n";
    for (sensors, code, says) in
        [("sensors = [\"wind\"]", 1, "unhandled exception Windy"), ("", 0, "mission ok")]
    {
        let world = format!("[drones.d]\nhome = [0, 0]\n{sensors}\n{air}");
        std::fs::write(dir.join("m.world.toml"), world).unwrap();
        let (got, out, err) = aviary(&["run", "m.mission"], &dir);
        assert_eq!(got, code, "{sensors}: {out}\n{err}");
        assert!(out.contains(says), "{out}");
    }
    // A wind faster than the drone: refused, nothing flown.
    std::fs::write(
        dir.join("m.world.toml"),
        "[drones.d]\nhome = [0, 0]\n[air.wind]\nspeed = 12\nfrom = 90\n",
    )
    .unwrap();
    let (got, out, err) = aviary(&["run", "m.mission"], &dir);
    assert_eq!(got, 2, "{out}\n{err}");
    assert!(err.contains("m.world.toml:4:9") && err.contains("a wind of 12 m/s"), "{err}");
}
