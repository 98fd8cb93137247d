//! Zenoh's access control in front of an operation, as docs/SECURITY.md sets it up: a
//! `zenohd` router with `docs/zenoh/router-acl.json5` (user names and passwords, and who
//! may write where), a mission flown through an agent, each machine signed in as its role.
//!
//! - The mission flies through the agent and ends ok: the rules keep no legitimate flow.
//! - A station may read the mission's events, but its frames to the vehicle never reach
//!   the agent (without the router's rules the agent receives and refuses them:
//!   `agent.rs`).
//! - A machine without the right password does not join.
//!
//! It runs where `AVIARY_ZENOHD` names the router (build.rs), on loopback.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use common::agent::Agent;
use common::vehicles::Vehicles;
use common::{free_port, repo, scratch, wait_at_most};
use zenoh::Wait;

const WORLD: &str = "\
[site]
origin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }

[places]
Near = [10, 10]

[drones.scout]
home = [0, 0]
";

const MISSION: &str = "\
MISSION Reach:
    scout TakeOff WITH 10m
    scout FlyTo WITH Near
    scout Hover WITH 20s
";

const USERS: &str = "mission:mission-secret\nagent:agent-secret\nstation:station-secret\n";

/// A client of the router at `port`, signed in as `user`.
fn client(port: u16, user: &str, password: &str) -> String {
    format!(
        r#"{{ mode: "client", connect: {{ endpoints: ["tcp/127.0.0.1:{port}"] }},
            transport: {{ auth: {{ usrpwd: {{ user: "{user}", password: "{password}" }} }} }} }}"#
    )
}

fn zenohd() -> PathBuf {
    let binary = PathBuf::from(std::env::var_os("AVIARY_ZENOHD").unwrap_or_default());
    assert!(binary.is_file(), "AVIARY_ZENOHD must name zenohd, not `{}`", binary.display());
    binary
}

/// A process killed when dropped (also when the test fails).
struct Killed(Child);

impl Drop for Killed {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The router with docs/zenoh/router-acl.json5, listening on loopback `port`.
fn router(dir: &Path, port: u16) -> Killed {
    let config = std::fs::read_to_string(repo().join("docs/zenoh/router-acl.json5"))
        .expect("docs/zenoh/router-acl.json5");
    let here = config.replace("tcp/0.0.0.0:7447", &format!("tcp/127.0.0.1:{port}"));
    assert_ne!(here, config, "the documented router listens on tcp/0.0.0.0:7447");
    std::fs::write(dir.join("router.json5"), here).expect("config");
    std::fs::write(dir.join("users.txt"), USERS).expect("users");
    Killed(
        Command::new(zenohd())
            .args(["-c", "router.json5"])
            .current_dir(dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn zenohd"),
    )
}

#[test]
#[cfg_attr(
    not(zenohd),
    ignore = "zenohd not named: set AVIARY_ZENOHD=/path/to/zenohd to run it (docs/SECURITY.md)"
)]
fn a_router_s_access_control_keeps_a_station_from_commanding_a_vehicle() {
    let dir = scratch("access_control");
    let port = free_port();
    let _zenohd = router(&dir, port);
    common::wait_for_listener(&format!("127.0.0.1:{port}"), Duration::from_secs(30));
    std::fs::write(dir.join("vehicles.world.toml"), WORLD).expect("world");
    let vehicles = Vehicles::start(&dir.join("vehicles.world.toml"), "5");
    let agent = Agent::start(&dir, &client(port, "agent", "agent-secret"), vehicles.port);

    // A station, signed in: it reads the mission's events, and tries to command the
    // vehicle.
    let station = zenoh::open(
        zenoh::Config::from_json5(&client(port, "station", "station-secret")).expect("config"),
    )
    .wait()
    .expect("the station signs in");
    let heard = Arc::new(Mutex::new(Vec::<String>::new()));
    let into = Arc::clone(&heard);
    let _events = station
        .declare_subscriber("aviary/Reach/events")
        .callback(move |s| {
            into.lock().expect("lock").push(String::from_utf8_lossy(&s.payload().to_bytes()).into())
        })
        .wait()
        .expect("subscribe");

    std::fs::write(dir.join("m.mission"), MISSION).expect("mission");
    std::fs::write(
        dir.join("m.world.toml"),
        WORLD.replace("home = [", "mavlink = \"agent:field1\"\nhome = ["),
    )
    .expect("world");
    std::fs::write(dir.join("run.json5"), client(port, "mission", "mission-secret"))
        .expect("config");
    let mut run = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", "m.mission", "--zenoh", "run.json5", "--quiet", "--trace", "t.jsonl"])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn aviary run");
    let start = Instant::now();
    while heard.lock().expect("lock").is_empty() {
        assert!(start.elapsed() < Duration::from_secs(30), "the station hears no event");
        std::thread::sleep(Duration::from_millis(50));
    }
    // What a station would send the vehicle, had it the right: garbage here, which the
    // agent would refuse and say (agent.rs), were it to reach it.
    for _ in 0..20 {
        station.put("aviary-agent/field1/gcs", "not a MAVLink frame").wait().expect("put");
        std::thread::sleep(Duration::from_millis(100));
    }
    let code = wait_at_most(&mut run, Duration::from_secs(120), "aviary run");
    let mut err = String::new();
    if let Some(mut e) = run.stderr.take() {
        let _ = std::io::Read::read_to_string(&mut e, &mut err);
    }
    assert_eq!(code, 0, "the mission flies through the agent behind the router's rules: {err}");
    let heard = heard.lock().expect("lock").clone();
    assert!(heard.last().is_some_and(|l| l.contains("mission_end")), "{heard:?}");
    let said = agent.said();
    assert!(said.contains("carries tcp:127.0.0.1:"), "{said}");
    assert!(!said.contains("refused a sample"), "a station's frames reached the agent: {said}");

    // A wrong password: no session.
    let stranger =
        zenoh::open(zenoh::Config::from_json5(&client(port, "station", "guess")).expect("config"))
            .wait();
    assert!(stranger.is_err(), "a wrong password joined");
}
