//! `aviary run` over MAVLink against a real peer: the `aviary vehicles` binary on
//! loopback (an ephemeral port, read from its first line). Nothing is mocked: both ends
//! are the programs a user runs, talking MAVLink 2 over TCP.
//!
//! The vehicles run at 20 times real time so that the paper's 490 s mission takes about
//! half a minute; the mission's own waits (none in the paper's mission) run on the wall
//! clock.

mod common;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use aviary_api::trace::{CallStatus, Event, EventKind, Record, Shown};
use aviary_api::{Function, Remainder};
use aviary_test_support::trace::actor;
use common::background::{self, events};
use common::vehicles::{Vehicles, SMALL_WORLD};
use common::{aviary, repo, scratch};
use serde_json::Value;

/// The world with `mavlink = "tcp:127.0.0.1:PORT"` given to the drones named.
fn bind(world: &str, port: u16, drones: &[&str]) -> String {
    let mut out = String::new();
    for line in world.lines() {
        out.push_str(line);
        out.push('\n');
        let name = line.strip_prefix("[drones.").and_then(|l| l.strip_suffix(']'));
        if name.is_some_and(|n| drones.is_empty() || drones.contains(&n)) {
            out.push_str(&format!("mavlink = \"tcp:127.0.0.1:{port}\"\n"));
        }
    }
    out
}

/// Runs `aviary run` in `dir`, killed if it takes longer than `limit`.
fn run_within(dir: &Path, args: &[&str], limit: Duration) -> i32 {
    let mut child = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn aviary run");
    common::wait_at_most(&mut child, limit, "aviary run")
}

/// Per event kind and actor, what a trace says, in a form two runs can be compared in:
/// sorted, because the two runs' timing differs (which body is found first). Of a signal
/// its name and the numbers of its values; of a detection its kind and location; of a
/// call its function and the numbers of its values; of a call's end its function and
/// where it left the drone.
fn facts(trace: &[Record<'static>], kind: EventKind) -> Vec<(String, String, Vec<f64>)> {
    let mut out: Vec<(String, String, Vec<f64>)> = trace
        .iter()
        .filter(|e| e.event.kind() == kind)
        .map(|e| {
            let known = |p: &[f64]| p.iter().copied().filter(|c| c.is_finite()).collect();
            let (key, numbers) = match &e.event {
                Event::Signal { name, args, .. } => (name.to_string(), flatten(args)),
                Event::Detection { kind, location, .. } => (kind.to_string(), known(location)),
                Event::ApiCall { function, args, .. } => {
                    (function.name().to_string(), flatten(args))
                }
                Event::ApiDone { function, position, .. } => {
                    (function.name().to_string(), known(position))
                }
                other => panic!("no facts of {other:?}"),
            };
            (actor(&e.event).unwrap_or("").to_owned(), key, numbers)
        })
        .collect();
    out.sort_by(|a, b| {
        (&a.0, &a.1)
            .cmp(&(&b.0, &b.1))
            .then(a.2.partial_cmp(&b.2).unwrap_or(std::cmp::Ordering::Equal))
    });
    out
}

/// The numbers of values, in the order the trace writes them (a coordinate it does not
/// know, written null, is none).
fn flatten(values: &[Shown]) -> Vec<f64> {
    let point = |p: &aviary_api::Point| [Some(p.x), Some(p.y), p.z];
    let numbers: Vec<f64> = values
        .iter()
        .flat_map(|v| match v {
            Shown::Number(n) => vec![*n],
            Shown::Position(p) => point(p).into_iter().flatten().collect(),
            Shown::Area(corners) => corners.iter().flatten().copied().collect(),
            Shown::Remainder(left) => match &**left {
                Remainder::Nothing => Vec::new(),
                Remainder::Lanes { lanes, spacing } => {
                    lanes.iter().flatten().flatten().copied().chain([*spacing]).collect()
                }
                Remainder::Points(points) => points.iter().flat_map(point).flatten().collect(),
            },
            Shown::Text(_) | Shown::Bool(_) | Shown::Null => Vec::new(),
        })
        .collect();
    numbers.into_iter().filter(|n| n.is_finite()).collect()
}

/// The calls a drone made, in the order they ended.
fn done_by(trace: &[Record<'static>], actor: &str) -> Vec<Function> {
    trace
        .iter()
        .filter_map(|e| match &e.event {
            Event::ApiDone { actor: a, function, .. } if a == actor => Some(*function),
            _ => None,
        })
        .collect()
}

/// A flight out and home: the calls that end, in order.
const FLIGHT: [Function; 4] =
    [Function::Arm, Function::TakeOff, Function::FlyToPosition, Function::ReturnToLaunch];

/// Whether the event is of `actor`.
fn actor_is(e: &Record, actor: &str) -> bool {
    aviary_test_support::trace::actor(&e.event) == Some(actor)
}

fn agree(
    what: &str,
    direct: &[(String, String, Vec<f64>)],
    mavlink: &[(String, String, Vec<f64>)],
    tolerance: f64,
) {
    assert_eq!(direct.len(), mavlink.len(), "{what}: {direct:?}\nvs\n{mavlink:?}");
    for (a, b) in direct.iter().zip(mavlink) {
        assert_eq!((&a.0, &a.1), (&b.0, &b.1), "{what}");
        assert_eq!(a.2.len(), b.2.len(), "{what}: {a:?} vs {b:?}");
        for (x, y) in a.2.iter().zip(&b.2) {
            assert!((x - y).abs() <= tolerance, "{what}: {a:?} vs {b:?}");
        }
    }
}

#[test]
fn the_paper_mission_over_mavlink_agrees_with_a_simulated_run() {
    let dir = scratch("mavlink_paper");
    let examples = repo().join("examples");
    let world =
        std::fs::read_to_string(examples.join("search_and_rescue.world.toml")).expect("world");
    std::fs::copy(examples.join("search_and_rescue.mission"), dir.join("m.mission")).expect("copy");
    std::fs::write(dir.join("m.world.toml"), &world).expect("world");
    let (code, _, err) = aviary(&["run", "m.mission", "--quiet", "--trace", "direct.jsonl"], &dir);
    assert_eq!(code, 0, "{err}");

    let vehicles = Vehicles::start(&examples.join("search_and_rescue.world.toml"), "20");
    let live = dir.join("live");
    std::fs::create_dir_all(&live).expect("dir");
    std::fs::copy(examples.join("search_and_rescue.mission"), live.join("m.mission"))
        .expect("copy");
    std::fs::write(live.join("m.world.toml"), bind(&world, vehicles.port, &[])).expect("world");
    let code = run_within(
        &live,
        &["run", "m.mission", "--quiet", "--trace", "t.jsonl"],
        Duration::from_secs(240),
    );
    let direct = events(&dir.join("direct.jsonl"));
    let mavlink = events(&live.join("t.jsonl"));
    assert_eq!(code, 0, "the mission ends ok over MAVLink: {:?}", mavlink.last());
    assert!(
        matches!(
            mavlink.last().map(|e| &e.event),
            Some(Event::MissionEnd { status: aviary_api::trace::Status::Ok, .. })
        ),
        "{:?}",
        mavlink.last()
    );
    // The same signals, the same finds at the same places, the same calls with the
    // same positions (the beacons fly to where the bodies were found).
    use EventKind::{ApiCall, ApiDone, Detection, Signal};
    agree("signals", &facts(&direct, Signal), &facts(&mavlink, Signal), 0.0);
    agree("detections", &facts(&direct, Detection), &facts(&mavlink, Detection), 1.0);
    agree("calls", &facts(&direct, ApiCall), &facts(&mavlink, ApiCall), 1.0);
    // Where each call left its drone: within the arrival tolerances (1 m over the
    // ground, 0.5 m in height) and the rounding of the reported position.
    agree("positions", &facts(&direct, ApiDone), &facts(&mavlink, ApiDone), 1.5);
    assert!(mavlink.events(EventKind::Exception).is_empty(), "no exception over MAVLink");
}

const SMALL_MISSION: &str = "\
MISSION Hold:
    PARALLEL Both:
        SEQUENTIAL Real:
            scout TakeOff WITH 10m
            scout FlyTo WITH Near
            scout Hover WITH 60s
        SEQUENTIAL Simulated:
            buddy TakeOff WITH 10m
            buddy FlyTo WITH Far
            buddy ReturnHome
";

#[test]
fn a_killed_vehicle_raises_connection_lost_within_the_heartbeat_timeout() {
    let dir = scratch("mavlink_link_loss");
    std::fs::write(dir.join("vehicles.world.toml"), SMALL_WORLD).expect("world");
    let mut vehicles = Vehicles::start(&dir.join("vehicles.world.toml"), "5");
    std::fs::write(dir.join("m.mission"), SMALL_MISSION).expect("mission");
    std::fs::write(dir.join("m.world.toml"), bind(SMALL_WORLD, vehicles.port, &["scout", "buddy"]))
        .expect("world");
    let mut run = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", "m.mission", "--quiet", "--trace", "t.jsonl"])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn aviary run");
    let trace = dir.join("t.jsonl");
    let hover = |e: &Record| background::is_call(e, Function::Hover);
    background::first_event(&trace, Duration::from_secs(60), "hover of the scout", hover);
    vehicles.child.kill().expect("kill the vehicles");
    // The heartbeat timeout is 3 s from the last HEARTBEAT (sent each second); allow 3 s
    // more for a loaded machine.
    let lost = |e: &Record| background::is_exception(e, "ConnectionLost");
    let exception = background::first_event(
        &trace,
        Duration::from_secs(6),
        "ConnectionLost after the kill",
        lost,
    );
    let Event::Exception { args, .. } = &exception.event else { unreachable!() };
    let reason = args.first().and_then(Shown::as_str).unwrap_or("");
    assert!(reason.contains("no HEARTBEAT from system 1 for 3.0 s"), "{exception:?}");
    // The vehicles back on their port: the link is opened again, and the run brings them
    // down and ends (out of reach, it would wait 120 s for each and leave it to its
    // failsafe).
    let _back = Vehicles::start_on(&dir.join("vehicles.world.toml"), "5", vehicles.port);
    let code = common::wait_at_most(&mut run, Duration::from_secs(60), "aviary run");
    assert_eq!(code, 1, "unhandled, ConnectionLost fails the mission");
    let flown = events(&trace);
    assert!(background::signalled(&flown, "ConnectionRestored"), "{:?}", flown.last());
}

#[test]
fn a_mixed_fleet_flies_one_drone_over_mavlink_and_one_simulated() {
    let dir = scratch("mavlink_mixed");
    std::fs::write(dir.join("vehicles.world.toml"), SMALL_WORLD).expect("world");
    let vehicles = Vehicles::start(&dir.join("vehicles.world.toml"), "5");
    let mission = SMALL_MISSION.replace("scout Hover WITH 60s", "scout ReturnHome");
    std::fs::write(dir.join("m.mission"), mission).expect("mission");
    std::fs::write(dir.join("m.world.toml"), bind(SMALL_WORLD, vehicles.port, &["scout"]))
        .expect("world");
    let code = run_within(
        &dir,
        &["run", "m.mission", "--quiet", "--trace", "t.jsonl"],
        Duration::from_secs(120),
    );
    let trace = events(&dir.join("t.jsonl"));
    assert_eq!(code, 0, "{:?}", trace.last());
    for actor in ["scout", "buddy"] {
        assert_eq!(done_by(&trace, actor), FLIGHT, "{actor}: {trace:?}");
    }
}

#[test]
fn an_unreachable_vehicle_is_a_clear_error() {
    let dir = scratch("mavlink_unreachable");
    // Port 1 on loopback: nothing listens there.
    std::fs::write(dir.join("m.world.toml"), bind(SMALL_WORLD, 1, &["scout"])).expect("world");
    std::fs::write(dir.join("m.mission"), SMALL_MISSION).expect("mission");
    let (code, _, err) = aviary(&["run", "m.mission", "--quiet"], &dir);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("cannot reach the MAVLink address `tcp:127.0.0.1:1`"), "{err}");
}

#[test]
fn bad_vehicles_and_speed_arguments_are_usage_errors() {
    let dir = scratch("mavlink_usage");
    std::fs::write(dir.join("w.world.toml"), SMALL_WORLD).expect("world");
    let (code, _, err) =
        aviary(&["vehicles", "--world", "w.world.toml", "--listen", "carrier-pigeon"], &dir);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("`carrier-pigeon` is not an address to listen on"), "{err}");
    let (code, _, err) = aviary(
        &["vehicles", "--world", "w.world.toml", "--listen", "tcp:127.0.0.1:0", "--speed", "0"],
        &dir,
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--speed must be a positive number"), "{err}");
    std::fs::write(
        dir.join("bad.world.toml"),
        "[drones.a]\nhome = [0, 0]\nmavlink = \"udp:127.0.0.1:99999\"\n",
    )
    .expect("world");
    let (code, _, err) =
        aviary(&["vehicles", "--world", "bad.world.toml", "--listen", "tcp:127.0.0.1:0"], &dir);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("bad.world.toml:3:11: error[E119]") && err.contains("99999"), "{err}");
    // MAVLink drones fly in real time: --speed is refused, before any connection.
    std::fs::write(dir.join("m.world.toml"), bind(SMALL_WORLD, 1, &["scout"])).expect("world");
    std::fs::write(dir.join("m.mission"), SMALL_MISSION).expect("mission");
    let (code, _, err) = aviary(&["run", "m.mission", "--speed", "10"], &dir);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("MAVLink drones, which fly in real time: leave out --speed"), "{err}");
}

/// `aviary check` asks MAVLink vehicles for their figures only with `--plan`, and not
/// with `--offline`: a listener that never answers counts who connects. With `--plan`
/// the silent vehicle costs a bounded wait and the plan is made with the world's figures.
#[test]
fn check_asks_the_vehicles_only_for_a_plan_and_waits_for_them_a_bounded_time() {
    let dir = scratch("mavlink_check_asks");
    let listener = std::net::TcpListener::bind("127.0.0.1:0").expect("listen");
    listener.set_nonblocking(true).expect("nonblocking");
    let port = listener.local_addr().expect("address").port();
    std::fs::write(dir.join("m.world.toml"), bind(SMALL_WORLD, port, &["scout"])).expect("world");
    std::fs::write(dir.join("m.mission"), SMALL_MISSION).expect("mission");
    let connected = || match listener.accept() {
        Ok(_) => true,
        Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => false,
        Err(e) => panic!("accept: {e}"),
    };
    for args in [&["check", "m.mission"][..], &["check", "--plan", "--offline", "m.mission"]] {
        let (code, out, err) = aviary(args, &dir);
        assert_eq!(code, 0, "{args:?}: {out}{err}");
        assert!(!out.contains("figures of the MAVLink drones"), "{args:?}: {out}");
        assert!(!connected(), "{args:?} connected to the vehicle");
    }
    let start = Instant::now();
    let (code, out, err) = aviary(&["check", "--plan", "m.mission"], &dir);
    let took = start.elapsed();
    assert_eq!(code, 0, "{out}{err}");
    assert!(connected(), "check --plan asked the vehicle");
    let said = format!("scout: no answer from tcp:127.0.0.1:{port} (system 1): no HEARTBEAT; planned with the world's figures");
    assert!(out.contains(&said), "{out}");
    assert!(out.contains("plan: the mission takes about"), "{out}");
    assert!(took < Duration::from_secs(8), "check --plan took {took:?} on a silent vehicle");
}

/// Against `aviary vehicles`, which serves the world's drones: check --plan hears each
/// vehicle, takes its charge from SYS_STATUS, and names where each drone's figures come
/// from, within the bounded wait. (Whether it serves parameters or not: a vehicle that
/// answers none keeps the world's figures, and the line says so.)
#[test]
fn check_plan_hears_aviary_vehicles_and_says_where_the_figures_come_from() {
    let dir = scratch("mavlink_check_vehicles");
    std::fs::write(dir.join("vehicles.world.toml"), SMALL_WORLD).expect("world");
    let vehicles = Vehicles::start(&dir.join("vehicles.world.toml"), "1");
    std::fs::write(dir.join("m.world.toml"), bind(SMALL_WORLD, vehicles.port, &["scout", "buddy"]))
        .expect("world");
    std::fs::write(dir.join("m.mission"), SMALL_MISSION).expect("mission");
    let start = Instant::now();
    let (code, out, err) = aviary(&["check", "--plan", "--format", "json", "m.mission"], &dir);
    let took = start.elapsed();
    assert_eq!(code, 0, "{out}{err}");
    let doc: Value = serde_json::from_str(&out).expect("one JSON document");
    let sources = doc["vehicles"].as_array().unwrap_or_else(|| panic!("no vehicles in {doc}"));
    assert_eq!(sources.len(), 2, "{doc}");
    for (s, (name, system)) in sources.iter().zip([("scout", 1), ("buddy", 2)]) {
        let line = s["source"].as_str().expect("source");
        assert_eq!(s["drone"].as_str(), Some(name));
        assert!(
            line.starts_with(&format!("{name}: "))
                && line.contains(&format!("tcp:127.0.0.1:{} (system {system})", vehicles.port)),
            "{line}"
        );
        assert!(!line.contains("no answer from"), "the vehicle was heard: {line}");
        assert!(line.contains("charge 100%"), "the charge from SYS_STATUS: {line}");
    }
    assert!(doc["plan"]["drones"].as_array().is_some_and(|d| d.len() == 2), "{doc}");
    assert!(took < Duration::from_secs(8), "check --plan took {took:?}");
}

/// Against `aviary vehicles --autopilot px4`, whose drones climb, descend, land and return
/// otherwise than the mission's world says: check --plan hears PX4 vehicles, reads their
/// figures under PX4's names (aviary_mavlink's PX4 table, integers bytewise), names each
/// parameter that differs, and plans with them.
#[test]
fn check_plan_reads_the_figures_of_px4_vehicles_under_px4s_names() {
    let dir = scratch("mavlink_check_px4");
    let figures = "climb_rate = 2.5\ndescent_rate = 1.5\nacceleration = 2.0\nland_speed = 0.6\nland_speed_below = 8.0\nreturn_altitude = 25.0\nreturn_loiter = 4.0\n";
    let theirs = SMALL_WORLD.replace("home = [0, 0]\n", &format!("home = [0, 0]\n{figures}"));
    std::fs::write(dir.join("vehicles.world.toml"), &theirs).expect("world");
    let vehicles = Vehicles::start_as(&dir.join("vehicles.world.toml"), "1", "px4");
    std::fs::write(dir.join("m.world.toml"), bind(SMALL_WORLD, vehicles.port, &["scout"]))
        .expect("world");
    std::fs::write(dir.join("m.mission"), SMALL_MISSION).expect("mission");
    let (code, out, err) = aviary(&["check", "--plan", "--format", "json", "m.mission"], &dir);
    assert_eq!(code, 0, "{out}{err}");
    let doc: Value = serde_json::from_str(&out).expect("one JSON document");
    let scout = &doc["vehicles"][0];
    let source = scout["source"].as_str().expect("source");
    assert!(
        source.starts_with("scout: figures from the vehicle on"),
        "every parameter answered: {source}"
    );
    let differences: Vec<&str> = scout["differences"]
        .as_array()
        .expect("differences")
        .iter()
        .filter_map(Value::as_str)
        .collect();
    for (name, figure) in [
        ("MPC_Z_V_AUTO_UP", "climb 2.5 m/s"),
        ("MPC_Z_V_AUTO_DN", "descent 1.5 m/s"),
        ("MPC_ACC_HOR", "acceleration 2 m/s²"),
        ("MPC_LAND_SPEED", "landing speed 0.6 m/s"),
        ("RTL_RETURN_ALT", "return altitude 25 m"),
        ("RTL_LAND_DELAY", "wait above home 4 s"),
    ] {
        assert!(
            differences
                .iter()
                .any(|d| d.contains(figure) && d.contains(&format!("the vehicle's {name}"))),
            "no {name} ({figure}) in {differences:?}"
        );
    }
    // BAT1_CAPACITY is -1 (the world gives none): no usable capacity, the world's kept.
    assert!(differences.iter().any(|d| d.contains("BAT1_CAPACITY")), "{differences:?}");
}

const FIELD_WORLD: &str = "\
[site]
name = \"Loopback farm\"
origin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }
geofence = [[-100, -100], [100, -100], [100, 100], [-100, 100]]

[places]
Mid = [0, 50]

[areas]
Field = [[-60, 20], [60, 20], [60, 80], [-60, 80]]

[drones.scout]
home = [0, 0]

[drones.buddy]
home = [10, 0]
";

/// The scout's sweep is aborted on its second lane (`Mid`); the buddy sweeps what it
/// left. Three lanes of 120 m, 20 m apart: along y = 30 (east), 50 (west), 70 (east).
const HANDOVER: &str = "\
CAPABILITY Spray BY drone WITH field:
    PERFORM:
        drone.Sweep(field, 20m)

MISSION Handover:
    SEQUENTIAL Fields:
        PARALLEL Work:
            SEQUENTIAL First:
                scout TakeOff WITH 10m
                scout Spray-S1 WITH Field
                scout ReturnHome
            SEQUENTIAL Control:
                WAITFOR distance(scout, Mid) < 10m
                Spray-S1 ABORT
        buddy TakeOff WITH 15m
        buddy Spray WITH scout.remaining
        buddy ReturnHome
";

/// Over MAVLink the backend knows which point of the sweep a vehicle was flying to when
/// its sweep was aborted, and where the vehicle said it was: the remainder starts there,
/// and the other vehicle flies just that. Nothing is missed; what is flown twice is at
/// most the metres the first vehicle took to stop after the abort.
#[test]
fn the_remainder_of_a_sweep_aborted_over_mavlink_is_flown_by_another_vehicle() {
    remainder_handover("ardupilot");
}

/// The same on PX4, whose sweeps are uploaded and flown as missions: the point flown to
/// comes from MISSION_CURRENT.
#[test]
fn the_remainder_of_a_sweep_flown_as_a_px4_mission_is_flown_by_another_vehicle() {
    remainder_handover("px4");
}

fn remainder_handover(autopilot: &str) {
    let dir = scratch(&format!("mavlink_remainder_{autopilot}"));
    std::fs::write(dir.join("vehicles.world.toml"), FIELD_WORLD).expect("world");
    let vehicles = Vehicles::start_as(&dir.join("vehicles.world.toml"), "5", autopilot);
    std::fs::write(dir.join("m.mission"), HANDOVER).expect("mission");
    std::fs::write(dir.join("m.world.toml"), bind(FIELD_WORLD, vehicles.port, &[])).expect("world");
    let code = run_within(
        &dir,
        &["run", "m.mission", "--quiet", "--telemetry-hz", "10", "--trace", "t.jsonl"],
        Duration::from_secs(180),
    );
    let trace = events(&dir.join("t.jsonl"));
    assert_eq!(code, 0, "{:?}", trace.last());
    let sweep = |actor: &str, kind: EventKind| -> &Record {
        trace
            .iter()
            .find(|e| {
                e.event.kind() == kind
                    && actor_is(e, actor)
                    && matches!(
                        e.event,
                        Event::ApiCall { function: Function::Sweep, .. }
                            | Event::ApiDone { function: Function::Sweep, .. }
                    )
            })
            .unwrap_or_else(|| panic!("no {kind:?} of {actor}'s Sweep: {trace:?}"))
    };
    let cut = sweep("scout", EventKind::ApiDone);
    let Event::ApiDone { status, left, position, .. } = cut.event else { unreachable!() };
    assert_eq!(status, CallStatus::Aborted);
    assert!(left.unwrap() > 0.0, "{cut:?}");
    let stop = [position[0], position[1]];
    assert!((stop[1] - 50.0).abs() < 2.0 && stop[0].abs() < 12.0, "stopped near Mid: {stop:?}");

    // What is left: the rest of the second lane from where the scout stopped, and the third.
    let Event::ApiCall { args, .. } = &sweep("buddy", EventKind::ApiCall).event else {
        unreachable!()
    };
    let left = &args[0];
    let Shown::Remainder(rest) = left else { panic!("lanes: {left:?}") };
    let Remainder::Lanes { lanes, .. } = &**rest else { panic!("lanes: {left:?}") };
    assert_eq!(lanes.len(), 2, "{left:?}");
    let from = lanes[0][0];
    assert_eq!(from[1], 50.0, "on the lane");
    assert!((from[0] - stop[0]).abs() < 1.5, "where the scout stopped: {from:?} {stop:?}");
    assert_eq!(lanes[0][1], [-60.0, 50.0]);
    assert_eq!(lanes[1], [[-60.0, 70.0], [60.0, 70.0]]);
    let done = sweep("buddy", EventKind::ApiDone);
    assert!(matches!(done.event, Event::ApiDone { status: CallStatus::Ok, .. }));

    // From the telemetry: the middle of every lane (away from the corners a vehicle cuts)
    // is flown; the second lane by the scout east of where it stopped and by the buddy
    // west of it.
    let tracks = aviary_test_support::lanes::tracks(&trace, &["scout", "buddy"]);
    let field = [[-60.0, 20.0], [60.0, 20.0], [60.0, 80.0], [-60.0, 80.0]];
    let all = aviary_api::sweep::lanes(&field, 20.0);
    let passes = aviary_test_support::lanes::passes(&all, &tracks);
    let step = aviary_test_support::lanes::STEP;
    let margin = aviary_test_support::lanes::MARGIN;
    // The handover is a corner too: the buddy reaches the point where the scout stopped
    // within the arrival tolerance (1 m) and turns onto the lane there, so the metres
    // around it is flown by both within a metre of the lane, but not along it, which
    // is what `passes` counts. That both come to it is asserted on its own.
    let arrive = aviary_mavlink::Tuning::default().arrive_xy;
    let came = |track: &[[f64; 3]]| {
        track.iter().any(|p| (p[0] - from[0]).hypot(p[1] - from[1]) <= arrive + 0.5)
    };
    assert!(came(&tracks[0].1) && came(&tracks[1].1), "both at the handover {from:?}");
    for (k, lane) in passes.iter().enumerate() {
        for (i, who) in lane.iter().enumerate() {
            let along = margin + i as f64 * step;
            if !(25.0..=95.0).contains(&along) {
                continue;
            }
            let x = all[k][0][0] + (all[k][1][0] - all[k][0][0]) * along / 120.0;
            // The turn there settles over a few metres: positions that keep the vehicles'
            // clock (10 Hz of its own time) are close enough together that the
            // centimetres it still drifts sideways turn a piece by more than `ALONG`.
            if k == 1 && (x - from[0]).abs() <= 3.0 * arrive {
                continue;
            }
            assert!(!who.is_empty(), "lane {k}, {along} m in: not flown");
            if who.len() > 1 {
                // Only just past where the scout stopped: its braking.
                assert!(
                    k == 1 && x <= stop[0] && x > stop[0] - 15.0,
                    "lane {k} at x = {x}: {who:?}"
                );
            }
        }
    }
}

/// A fire front between the drone's home and where it flies. The vehicles (like a real
/// autopilot) know nothing of it: the detour is the MAVLink backend's.
const FIRE_WORLD: &str = "\
[site]
name = \"Loopback field\"
origin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }
geofence = [[-400, -400], [400, -400], [400, 400], [-400, 400]]

[no_fly.Fire_Front]
polygon = [[60, -40], [140, -40], [140, 40], [60, 40]]

[drones.scout]
home = [0, 0]
";

const ACROSS_THE_FIRE: &str = "\
MISSION Across:
    scout TakeOff WITH 15m
    scout FlyTo WITH (200, 0)
    scout ReturnHome
";

#[test]
fn a_flight_across_a_no_fly_zone_is_sent_as_waypoints_around_it() {
    let dir = scratch("mavlink_no_fly");
    std::fs::write(dir.join("vehicles.world.toml"), FIRE_WORLD).expect("world");
    let vehicles = Vehicles::start(&dir.join("vehicles.world.toml"), "4");
    std::fs::write(dir.join("m.mission"), ACROSS_THE_FIRE).expect("mission");
    std::fs::write(dir.join("m.world.toml"), bind(FIRE_WORLD, vehicles.port, &["scout"]))
        .expect("world");
    let code = run_within(
        &dir,
        &["run", "m.mission", "--quiet", "--trace", "t.jsonl", "--telemetry-hz", "20"],
        Duration::from_secs(180),
    );
    let trace = events(&dir.join("t.jsonl"));
    assert_eq!(code, 0, "{:?}", trace.last());
    let zone = [[60.0, -40.0], [140.0, -40.0], [140.0, 40.0], [60.0, 40.0]];
    let samples: Vec<[f64; 3]> = trace.positions("scout").into_iter().map(|(_, p)| p).collect();
    assert!(samples.len() > 100, "{} samples", samples.len());
    // Never in the zone, and never into its margin by more than the arrival tolerance and
    // the vehicle's overshoot: a corner passed within the pass radius (up to 25 m) instead
    // of reached would cut deep into it.
    for p in &samples {
        let xy = [p[0], p[1]];
        let near = aviary_api::geometry::dist_to_boundary(&zone, xy);
        assert!(!aviary_api::geometry::contains(&zone, xy), "{p:?} is inside the zone");
        assert!(
            p[2] < 0.5 || near >= aviary_route::MARGIN - 3.0,
            "{p:?} is {near} m from the zone"
        );
    }
    // It went around (off the straight line by the zone's half-width and the margin),
    // got there, and came home.
    let widest = samples.iter().map(|p| p[1].abs()).fold(0.0, f64::max);
    assert!(widest >= 40.0 + aviary_route::MARGIN - 2.0, "{widest}");
    assert!(samples.iter().any(|p| (p[0] - 200.0).abs() < 2.0 && p[1].abs() < 2.0));
    assert_eq!(done_by(&trace, "scout"), FLIGHT, "{trace:?}");
}

/// The hop mission that first failed on PX4 SITL (PX4 read FlyTo's height above home as
/// one above sea level and came down to land), flown by `aviary run` on `aviary vehicles
/// --autopilot px4`, which reads DO_REPOSITION's and DO_ORBIT's altitude as PX4 does: the
/// drone stays up, reaches the place, circles it in ORBIT and lands.
#[test]
fn the_hop_mission_flies_on_px4_vehicles_with_heights_above_sea_level() {
    let dir = scratch("mavlink_px4_hop");
    let world = "[site]\nname = \"Hop\"\norigin = { lat = 46.6167, lon = 14.2650, alt = 440 }\nmax_altitude = 60\n\n[places]\nFar = [30, 30]\n\n[drones.copter]\nhome = [0, 0]\n";
    std::fs::write(dir.join("vehicles.world.toml"), world).expect("world");
    let vehicles = Vehicles::start_as(&dir.join("vehicles.world.toml"), "5", "px4");
    std::fs::write(dir.join("m.world.toml"), bind(world, vehicles.port, &[])).expect("world");
    std::fs::write(
        dir.join("m.mission"),
        "MISSION Hop:\n    SEQUENTIAL Fly:\n        copter TakeOff WITH 12m\n        copter FlyTo WITH Far\n        copter FlyCircle WITH Far, 15m, 1\n        copter Land\n",
    )
    .expect("mission");
    let code = run_within(
        &dir,
        &["run", "m.mission", "--quiet", "--trace", "t.jsonl"],
        Duration::from_secs(120),
    );
    let trace = events(&dir.join("t.jsonl"));
    assert_eq!(code, 0, "{:?}", trace.last());
    let done = |function: Function| {
        trace
            .iter()
            .find_map(|e| match e.event {
                Event::ApiDone { function: f, position, .. } if f == function => Some(position),
                _ => None,
            })
            .unwrap_or_else(|| panic!("no {function:?} done: {trace:?}"))
    };
    let there = done(Function::FlyToPosition);
    assert!((there[0] - 30.0).hypot(there[1] - 30.0) < 1.5 && (there[2] - 12.0).abs() < 1.0);
    let around = done(Function::Orbit);
    assert!(((around[0] - 30.0).hypot(around[1] - 30.0) - 15.0).abs() < 3.0, "{around:?}");
    assert!(done(Function::Land)[2] < 0.3);
}

/// What PX4 SITL taught, held without it: PX4 acknowledges a DO_REPOSITION outside its
/// geofence, then its navigator refuses it in words alone ("Reposition is outside
/// geofence") and the drone stays. `aviary vehicles --autopilot px4` refuses as PX4 does
/// (its world has a fence that the mission's world lacks, as a vehicle's own fence is
/// unknown to the world); the call fails at once with PX4's words, not when its time
/// runs out.
#[test]
fn a_target_px4_refuses_in_words_fails_the_call_with_them_at_once() {
    let dir = scratch("mavlink_px4_refused");
    let site = "[site]\nname = \"Fence\"\norigin = { lat = 46.6167, lon = 14.2650, alt = 440 }\nmax_altitude = 60\n";
    let rest = "\n[places]\nFar = [0, 80]\n\n[drones.copter]\nhome = [0, 0]\n";
    let fenced = format!("{site}geofence = [[-50, -50], [50, -50], [50, 50], [-50, 50]]\n{rest}");
    std::fs::write(dir.join("vehicles.world.toml"), fenced).expect("world");
    let vehicles = Vehicles::start_as(&dir.join("vehicles.world.toml"), "5", "px4");
    std::fs::write(dir.join("m.world.toml"), bind(&format!("{site}{rest}"), vehicles.port, &[]))
        .expect("world");
    std::fs::write(
        dir.join("m.mission"),
        "MISSION Out:\n    SEQUENTIAL Fly:\n        copter TakeOff WITH 10m\n        copter FlyTo WITH Far\n    ON EXCEPTION CommandFailed BY copter:\n        SIGNAL Refused\n",
    )
    .expect("mission");
    let code = run_within(
        &dir,
        &["run", "m.mission", "--quiet", "--trace", "t.jsonl"],
        Duration::from_secs(120),
    );
    let trace = events(&dir.join("t.jsonl"));
    assert_eq!(code, 0, "{:?}", trace.last());
    let refused = trace
        .iter()
        .find(|e| matches!(&e.event, Event::Exception { name, .. } if name == "CommandFailed"))
        .unwrap_or_else(|| panic!("no CommandFailed: {trace:?}"));
    let said = common::background::said(refused);
    assert!(said.contains("Reposition is outside geofence"), "PX4's words in {said}");
    let sent = trace
        .iter()
        .find(|e| matches!(e.event, Event::ApiCall { function: Function::FlyToPosition, .. }))
        .expect("the flight out");
    let took = refused.t - sent.t;
    assert!(took < 5.0, "refused {took:.1} s after it was sent");
    assert!(common::background::signalled(&trace, "Refused"));
}

/// A PX4 path paused half way and resumed: the vehicle holds where it was (PX4's HOLD),
/// then flies the mission on from the point it was flying to, to its end.
#[test]
fn a_px4_path_paused_holds_and_resumed_flies_on_to_its_end() {
    let dir = scratch("mavlink_px4_pause");
    let world = "[site]\nname = \"Pause\"\norigin = { lat = 46.6167, lon = 14.2650, alt = 440 }\nmax_altitude = 60\n\n[places]\nMid = [30, 60]\n\n[drones.copter]\nhome = [0, 0]\n";
    std::fs::write(dir.join("vehicles.world.toml"), world).expect("world");
    let vehicles = Vehicles::start_as(&dir.join("vehicles.world.toml"), "5", "px4");
    std::fs::write(dir.join("m.world.toml"), bind(world, vehicles.port, &[])).expect("world");
    std::fs::write(
        dir.join("m.mission"),
        "CAPABILITY Trace BY drone:\n    PERFORM:\n        drone.FollowPath((0, 60), (60, 60), (60, 0))\n\nMISSION Held:\n    PARALLEL Work:\n        SEQUENTIAL Fly:\n            copter TakeOff WITH 10m\n            copter Trace-T\n            copter Land\n        SEQUENTIAL Control:\n            WAITFOR distance(copter, Mid) < 5m\n            Trace-T PAUSE\n            WAITFOR ELAPSED > 60s\n            Trace-T RESUME\n",
    )
    .expect("mission");
    let code = run_within(
        &dir,
        &["run", "m.mission", "--quiet", "--trace", "t.jsonl", "--telemetry-hz", "4"],
        Duration::from_secs(180),
    );
    let trace = events(&dir.join("t.jsonl"));
    assert_eq!(code, 0, "{:?}", trace.last());
    let leash = |action: &str| {
        trace
            .iter()
            .find(|e| matches!(&e.event, Event::Leash { action: a, .. } if a == action))
            .map(|e| e.t)
            .unwrap_or_else(|| panic!("no {action}: {trace:?}"))
    };
    let (paused, resumed) = (leash("PAUSE"), leash("RESUME"));
    let track: Vec<(f64, [f64; 3])> = trace.positions("copter");
    // Held: from 5 s after the PAUSE (braking) to the RESUME, within 2 m of one place.
    let held: Vec<[f64; 3]> =
        track.iter().filter(|(t, _)| *t > paused + 5.0 && *t < resumed).map(|(_, p)| *p).collect();
    assert!(held.len() > 40, "{held:?}");
    let spread =
        held.iter().map(|p| (p[0] - held[0][0]).hypot(p[1] - held[0][1])).fold(0.0, f64::max);
    assert!(spread < 2.0, "moved {spread:.1} m while held");
    assert!((held[0][1] - 60.0).abs() < 3.0, "held on the path's second leg: {:?}", held[0]);
    // Then on, through (60, 60) to (60, 0), where the path ends.
    let after: Vec<[f64; 3]> =
        track.iter().filter(|(t, _)| *t > resumed).map(|(_, p)| *p).collect();
    for point in [[60.0, 60.0], [60.0, 0.0]] {
        let near = after
            .iter()
            .map(|p| (p[0] - point[0]).hypot(p[1] - point[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(near < 1.5, "{point:?}: {near:.1} m away");
    }
    let done = trace
        .iter()
        .find(|e| matches!(e.event, Event::ApiDone { function: Function::FollowPath, .. }))
        .expect("the path's end");
    assert!(matches!(done.event, Event::ApiDone { status: CallStatus::Ok, .. }), "{done:?}");
    assert!(done.t > resumed);
}
