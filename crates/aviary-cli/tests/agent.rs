//! `aviary agent` between a mission and its vehicles, on one machine: `aviary vehicles`
//! serves the vehicles, an agent holds their MAVLink link and carries it on Zenoh, and
//! `aviary run --zenoh` flies them through it (`mavlink = "agent:field1"` in the world).
//! Nothing is mocked: the three are the programs a user runs.
//!
//! The operation over three machines (network namespaces and a `zenohd` router) is
//! `three_machines.rs`.

mod common;

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use aviary_api::trace::{CallStatus, Event, Record, Shown};
use aviary_api::Function;
use aviary_test_support::trace::{actor, Trace};
use common::agent::Agent;
use common::background;
use common::vehicles::{Vehicles, SMALL_WORLD};
use common::{aviary, free_port, scratch, wait_at_most, zenoh_peer};
use zenoh::Wait;

/// The scout hovers long enough for its agent to be cut off mid-flight.
const MISSION: &str = "\
MISSION Hold:
    PARALLEL Both:
        SEQUENTIAL First:
            scout TakeOff WITH 10m
            scout FlyTo WITH Near
            scout Hover WITH HOVER
        SEQUENTIAL Second:
            buddy TakeOff WITH 10m
            buddy FlyTo WITH Far
            buddy ReturnHome
";

/// The world with both drones behind agent `field1`.
fn behind_the_agent() -> String {
    SMALL_WORLD.replace("home = [", "mavlink = \"agent:field1\"\nhome = [")
}

/// `aviary run --zenoh` of the mission (hovering `hover`) in `world` in `dir`, its trace
/// `t.jsonl`.
fn start_run(dir: &Path, config: &str, hover: &str, world: &str) -> Child {
    std::fs::write(dir.join("m.mission"), MISSION.replace("HOVER", hover)).expect("mission");
    std::fs::write(dir.join("m.world.toml"), world).expect("world");
    std::fs::write(dir.join("run.json5"), config).expect("config");
    Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", "m.mission", "--zenoh", "run.json5", "--quiet", "--trace", "t.jsonl"])
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn aviary run")
}

fn events(dir: &Path) -> Trace {
    background::events(&dir.join("t.jsonl"))
}

fn stderr_of(child: &mut Child) -> String {
    let mut text = String::new();
    if let Some(mut err) = child.stderr.take() {
        let _ = std::io::Read::read_to_string(&mut err, &mut text);
    }
    text
}

/// Both drones fly the whole mission through the agent, and a foreign peer's garbage on
/// the agent's command key reaches no vehicle: the agent refuses it and says so.
#[test]
fn a_mission_flies_its_vehicles_through_an_agent_and_garbage_reaches_none() {
    let dir = scratch("agent_flies");
    std::fs::write(dir.join("vehicles.world.toml"), SMALL_WORLD).expect("world");
    let vehicles = Vehicles::start(&dir.join("vehicles.world.toml"), "5");
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    // The agent listens; the run and the foreign peer connect to it (peers relay nothing
    // for one another: that takes a router, as in three_machines.rs).
    let agent = Agent::start(&dir, &zenoh_peer("listen", &endpoint), vehicles.port);
    let mut run = start_run(&dir, &zenoh_peer("connect", &endpoint), "5s", &behind_the_agent());
    // A peer of the test's own, as anyone on the network could be.
    let foreign =
        zenoh::open(zenoh::Config::from_json5(&zenoh_peer("connect", &endpoint)).expect("config"))
            .wait()
            .expect("the foreign peer joins");
    let start = Instant::now();
    while !agent.said().contains("refused a sample") {
        assert!(start.elapsed() < Duration::from_secs(30), "agent said: {}", agent.said());
        foreign.put("aviary-agent/field1/gcs", "not a MAVLink frame").wait().expect("put");
        std::thread::sleep(Duration::from_millis(200));
    }
    let code = wait_at_most(&mut run, Duration::from_secs(120), "aviary run");
    let trace = events(&dir);
    assert_eq!(code, 0, "{}\n{:?}", stderr_of(&mut run), trace.last());
    // Every call of the mission, and the scout's way home after it, flown and done.
    use Function::{Arm, FlyToPosition, Hover, ReturnToLaunch, TakeOff};
    for (drone, calls) in [
        ("scout", vec![Arm, TakeOff, FlyToPosition, Hover, ReturnToLaunch]),
        ("buddy", vec![Arm, TakeOff, FlyToPosition, ReturnToLaunch]),
    ] {
        let done: Vec<(Function, CallStatus)> = trace
            .iter()
            .filter_map(|e| match &e.event {
                Event::ApiDone { function, status, .. } if actor(&e.event) == Some(drone) => {
                    Some((*function, *status))
                }
                _ => None,
            })
            .collect();
        let ok: Vec<(Function, CallStatus)> =
            calls.into_iter().map(|f| (f, CallStatus::Ok)).collect();
        assert_eq!(done, ok, "{drone} flew through the agent");
    }
    let said = agent.said();
    assert!(said.contains("agent `field1` carries tcp:127.0.0.1:"), "{said}");
    assert!(
        said.contains(
            "refused a sample of 19 bytes on aviary-agent/field1/gcs: not one MAVLink frame"
        ),
        "{said}"
    );
}

/// MAVLink 2 signing holds end to end through the agent, which carries the frames and
/// cannot sign them: vehicles that take only signed commands fly the mission whose world
/// gives their drones the key; with another key, the mission believes none of their
/// frames.
#[test]
fn signed_frames_go_through_the_agent_unchanged() {
    let dir = scratch("agent_signed");
    std::fs::write(dir.join("vehicles.world.toml"), SMALL_WORLD).expect("world");
    let vehicles =
        Vehicles::start_signed(&dir.join("vehicles.world.toml"), "5", "the field team's key");
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let _agent = Agent::start(&dir, &zenoh_peer("listen", &endpoint), vehicles.port);
    let signed = behind_the_agent().replace(
        "mavlink = \"agent:field1\"\n",
        "mavlink = \"agent:field1\"\nsigning_key = \"the field team's key\"\n",
    );
    let mut run = start_run(&dir, &zenoh_peer("connect", &endpoint), "2s", &signed);
    let code = wait_at_most(&mut run, Duration::from_secs(120), "aviary run");
    assert_eq!(code, 0, "{}\n{:?}", stderr_of(&mut run), events(&dir).last());
    // Another key: the vehicles' frames are not believed, so nothing is heard of them.
    let wrong = signed.replace("the field team's key", "a guess");
    let mut run = start_run(&dir, &zenoh_peer("connect", &endpoint), "2s", &wrong);
    let code = wait_at_most(&mut run, Duration::from_secs(60), "aviary run");
    let err = stderr_of(&mut run);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("for a HEARTBEAT from system 1 (drone `scout`) on agent:field1"), "{err}");
}

/// The agent gone mid-flight is a silent link: `ConnectionLost` within the heartbeat
/// timeout, as when a vehicle's own link goes. An agent started again restores the link,
/// and the run brings its vehicles down and ends. A world whose agent is not there at all
/// is a clear error before anything flies.
#[test]
fn a_lost_agent_is_connection_lost_and_a_missing_one_a_clear_error() {
    let dir = scratch("agent_lost");
    let port = free_port();
    let endpoint = format!("tcp/127.0.0.1:{port}");
    let mut alone = start_run(&dir, &zenoh_peer("listen", &endpoint), "60s", &behind_the_agent());
    let code = wait_at_most(&mut alone, Duration::from_secs(30), "aviary run");
    let err = stderr_of(&mut alone);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("no agent `field1` on Zenoh (looked 5 s for aviary-agent/field1): is `aviary agent --name field1` running"),
        "{err}"
    );

    std::fs::write(dir.join("vehicles.world.toml"), SMALL_WORLD).expect("world");
    let vehicles = Vehicles::start(&dir.join("vehicles.world.toml"), "5");
    let mut run = start_run(&dir, &zenoh_peer("listen", &endpoint), "60s", &behind_the_agent());
    let mut agent = Agent::start(&dir, &zenoh_peer("connect", &endpoint), vehicles.port);
    let trace = dir.join("t.jsonl");
    let hover = |e: &Record| background::is_call(e, Function::Hover);
    background::first_event(&trace, Duration::from_secs(60), "hover", hover);
    agent.child.kill().expect("kill the agent");
    // The heartbeat timeout is 3 s; allow 3 s more for a loaded machine.
    let lost = |e: &Record| background::is_exception(e, "ConnectionLost");
    let exception = background::first_event(&trace, Duration::from_secs(6), "ConnectionLost", lost);
    let Event::Exception { args, .. } = &exception.event else { unreachable!() };
    let reason = args.first().and_then(Shown::as_str).unwrap_or("");
    assert!(reason.contains("for 3.0 s"), "{exception:?}");
    // Back again: the run reaches the vehicles and lands them (out of reach, it would
    // wait 120 s for them and leave them to their failsafes).
    let _again = Agent::start(&dir, &zenoh_peer("connect", &endpoint), vehicles.port);
    let code = wait_at_most(&mut run, Duration::from_secs(60), "aviary run");
    assert_eq!(code, 1, "unhandled, ConnectionLost fails the mission");
    let trace = events(&dir);
    assert!(background::signalled(&trace, "ConnectionRestored"), "{:?}", trace.last());
    let home = |e: &Record| {
        matches!(&e.event, Event::ApiDone { function: Function::ReturnToLaunch, status, .. }
            if *status == CallStatus::Ok)
    };
    assert_eq!(trace.iter().filter(|e| home(e)).count(), 2, "both brought home: {trace:?}");
}

/// What cannot work is said at once, with what to do: an agent's name that is no key
/// chunk, an address that is none, a station asked for a folder and a run at once, and a
/// station whose run is not on Zenoh.
#[test]
fn bad_agent_and_station_arguments_are_clear_errors() {
    let dir = scratch("agent_arguments");
    let (code, _, err) =
        aviary(&["agent", "--name", "field/1", "--mavlink", "tcp:127.0.0.1:1"], &dir);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(
            "an agent's name holds only letters, digits, `-`, `_` and `.`, and `field/1` holds `/`"
        ),
        "{err}"
    );
    let (code, _, err) =
        aviary(&["agent", "--name", "field1", "--mavlink", "carrier-pigeon"], &dir);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("`carrier-pigeon` is not SCHEME:HOST:PORT"), "{err}");
    let (code, _, err) =
        aviary(&["gcs", "missions", "--zenoh", "--zenoh-prefix", "aviary/M"], &dir);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("a folder (DIR) or a run on Zenoh (--zenoh), not both"), "{err}");
    std::fs::write(
        dir.join("alone.json5"),
        zenoh_peer("listen", &format!("tcp/127.0.0.1:{}", free_port())),
    )
    .expect("config");
    let start = Instant::now();
    let (code, _, err) = aviary(
        &["gcs", "--zenoh", "alone.json5", "--zenoh-prefix", "aviary/M", "--listen", "0"],
        &dir,
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("is `aviary run --zenoh` flying under aviary/M"), "{err}");
    assert!(start.elapsed() < Duration::from_secs(30), "it gave up after {:?}", start.elapsed());
}
