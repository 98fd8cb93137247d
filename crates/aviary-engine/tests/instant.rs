//! Instant activities (src/instant.rs) against the general path: every mission gives the
//! same trace, event for event, with `instant_activities` on and off. The missions are
//! the examples and one for each way an instant activity has to wait and becomes a
//! general one: its claims are busy, its root is paused, a call takes time, a call fails.

use aviary_engine::{RunOptions, Status};
use aviary_test_support::harness;

fn both_ways(mission: &str, world: &str) -> harness::Run {
    let instant = harness::run_with(mission, world, &RunOptions::default());
    let general = harness::run_with(
        mission,
        world,
        &RunOptions { instant_activities: false, ..RunOptions::default() },
    );
    assert_eq!(instant.outcome, general.outcome);
    let (a, b) = (instant.dump(), general.dump());
    if a != b {
        let at = a
            .lines()
            .zip(b.lines())
            .position(|(x, y)| x != y)
            .unwrap_or(a.lines().count().min(b.lines().count()));
        panic!(
            "the traces part at event {at}:\ninstant: {:?}\ngeneral: {:?}",
            a.lines().nth(at),
            b.lines().nth(at)
        );
    }
    instant
}

const PING: &str = "CAPABILITY Ping BY d:\n    PERFORM:\n        d.StartStreaming()\n        d.StopStreaming()\n\n";

#[test]
fn the_examples_run_the_same_both_ways() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let mut missions = vec![format!("{root}/search_and_rescue")];
    for kind in ["battery_critical", "crash", "gps_loss", "link_loss", "motor_failure"] {
        missions.push(format!("{root}/faults/{kind}"));
    }
    for m in missions {
        let mission = std::fs::read_to_string(format!("{m}.mission")).unwrap();
        let world = std::fs::read_to_string(format!("{m}.world.toml")).unwrap();
        let run = both_ways(&mission, &world);
        assert!(run.trace.len() > 30, "{m}: the mission ran");
    }
}

#[test]
fn instant_steps_end_in_the_instant_they_start_and_in_order() {
    let r = both_ways(
        &format!("{PING}MISSION M:\n    a Ping\n    b Ping\n    a Hover WITH 2s\n    a Ping\n"),
        harness::WORLD,
    );
    let pings: Vec<(&str, &str, f64)> = r
        .trace
        .iter()
        .filter(|e| e["capability"] == "Ping")
        .map(|e| {
            (e["event"].as_str().unwrap(), e["actor"].as_str().unwrap(), e["t"].as_f64().unwrap())
        })
        .collect();
    assert_eq!(pings.len(), 6);
    assert_eq!(
        pings[..4].iter().map(|p| (p.0, p.1)).collect::<Vec<_>>(),
        [
            ("capability_start", "a"),
            ("capability_end", "a"),
            ("capability_start", "b"),
            ("capability_end", "b")
        ]
    );
    assert!(pings[..4].iter().all(|p| p.2 == 0.0), "no time passes: {pings:?}");
    assert!(pings[4..].iter().all(|p| (p.2 - 2.0).abs() < 0.11), "after the hover: {pings:?}");
    let calls: Vec<&str> = r
        .trace
        .iter()
        .filter(|e| e["event"] == "api_done" && e["actor"] == "a")
        .map(|e| e["function"].as_str().unwrap())
        .collect();
    assert_eq!(calls[..2], ["StartStreaming", "StopStreaming"]);
}

#[test]
fn an_instant_activity_on_busy_claims_waits_its_turn() {
    // Film holds a's camera for 3 s; Ping needs it and starts when Film ends.
    let film = "CAPABILITY Film BY d:\n    PERFORM:\n        d.StartStreaming()\n        d.Hover(3s)\n        d.StopStreaming()\n\n";
    let r = both_ways(&format!("{PING}{film}MISSION M:\n    a TakeOff\n    PARALLEL:\n        a Film\n        a Ping\n"), harness::WORLD);
    let film_end = r.index("capability_end", "capability", "Film");
    let ping_start = r.index("capability_start", "capability", "Ping");
    assert!(film_end < ping_start, "{}", r.dump());
    assert!(
        (r.t("capability_start", "capability", "Ping")
            - r.t("capability_end", "capability", "Film"))
        .abs()
            < 1e-9
    );
}

#[test]
fn an_instant_activity_inside_a_paused_one_waits_for_its_resume() {
    let watch =
        "CAPABILITY Watch BY d:\n    PERFORM:\n        WAITFOR RECEIVED(Go)\n        d Ping\n\n";
    let r = both_ways(
        &format!("{PING}{watch}MISSION M:\n    PARALLEL:\n        a Watch-W1\n        SEQUENTIAL:\n            b TakeOff\n            Watch-W1 PAUSE\n            SIGNAL Go\n            b Hover WITH 5s\n            Watch-W1 RESUME\n"),
        harness::WORLD,
    );
    let resumed =
        r.trace.iter().find(|e| e["event"] == "leash" && e["action"] == "RESUME").unwrap()["t"]
            .as_f64()
            .unwrap();
    let calls: Vec<f64> = r
        .trace
        .iter()
        .filter(|e| e["event"] == "api_call" && e["function"] == "StartStreaming")
        .map(|e| e["t"].as_f64().unwrap())
        .collect();
    assert_eq!(calls.len(), 1);
    assert!(calls[0] >= resumed, "the call waits for RESUME ({resumed}): {calls:?}\n{}", r.dump());
    assert_eq!(r.outcome.status, Status::Ok);
}

#[test]
fn an_instant_call_that_fails_is_its_activitys_exception() {
    // c has no camera: StartStreaming fails as it is made, inside Ping.
    let r = both_ways(
        &format!(
            "{PING}MISSION M:\n    c Ping\n    ON EXCEPTION CommandFailed BY c:\n        a Ping\n"
        ),
        harness::WORLD,
    );
    let ping_c = r.ends("Ping", "c");
    assert_eq!(ping_c[0]["status"], "failed", "{}", r.dump());
    assert!(
        r.find("api_call", "function", "StopStreaming").iter().all(|e| e["actor"] != "c"),
        "the failed call ends the sequence"
    );
    assert_eq!(r.ends("Ping", "a")[0]["status"], "ok", "the handler ran");
    assert_eq!(r.first("exception", "name", "CommandFailed")["handled"], true);
}

#[test]
fn a_capability_whose_calls_take_time_goes_on_where_it_stood() {
    // TakeOff (standard library): Arm ends at once, TakeOff takes time.
    let r = both_ways(
        "MISSION M:\n    PARALLEL:\n        a TakeOff\n        b TakeOff WITH 20m\n",
        harness::WORLD,
    );
    let a: Vec<&str> = r
        .trace
        .iter()
        .filter(|e| e["actor"] == "a" && e["event"] != "telemetry")
        .map(|e| e["event"].as_str().unwrap())
        .collect();
    assert_eq!(
        a[..6],
        ["capability_start", "api_call", "api_done", "api_call", "api_done", "capability_end"],
        "{}",
        r.dump()
    );
    assert!(
        r.ends("TakeOff", "b")[0]["t"].as_f64().unwrap()
            > r.ends("TakeOff", "a")[0]["t"].as_f64().unwrap()
    );
}
