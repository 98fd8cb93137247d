// Shared by several test binaries; each uses part of it.
#![allow(dead_code)]

//! Running the built `aviary` as a user does, in scratch directories.

use std::path::{Path, PathBuf};
use std::process::Command;

/// The drones of the paper's world (`examples/search_and_rescue.world.toml`), in its order.
pub const PAPER_DRONES: [&str; 7] = [
    "video_drone1",
    "video_drone2",
    "flir_drone1",
    "flir_drone2",
    "sensor_drone",
    "beacon_drone1",
    "beacon_drone2",
];

/// Runs `aviary ARGS` in `dir`: exit code, stdout, stderr.
pub fn aviary(args: &[&str], dir: &Path) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("run aviary");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Waits for `child` at most `limit`: its exit code; past it the child is killed and the
/// test fails, naming `what`.
pub fn wait_at_most(
    child: &mut std::process::Child,
    limit: std::time::Duration,
    what: &str,
) -> i32 {
    let start = std::time::Instant::now();
    loop {
        if let Some(status) = child.try_wait().expect("wait") {
            return status.code().unwrap_or(-1);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what} did not end within {limit:?}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// A fresh directory under the target dir, so tests never touch the source tree.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}
/// A Zenoh peer's JSON5 configuration that finds no one by scouting: it `listen`s or
/// `connect`s (`role`) at `endpoint` (`tcp/127.0.0.1:7447`) only, so no other test's
/// session on this machine can join it.
pub fn zenoh_peer(role: &str, endpoint: &str) -> String {
    format!(
        r#"{{ mode: "peer", {role}: {{ endpoints: ["{endpoint}"] }},
            scouting: {{ multicast: {{ enabled: false }}, gossip: {{ enabled: false }} }} }}"#
    )
}

/// A Zenoh client's JSON5 configuration: it reaches everyone through the router at
/// `endpoint`, which relays between its clients (peers it would leave to meet directly).
pub fn zenoh_client(endpoint: &str) -> String {
    format!(r#"{{ mode: "client", connect: {{ endpoints: ["{endpoint}"] }} }}"#)
}

/// Waits (at most `limit`) until something listens on `address`: a server the test
/// started, before its clients connect (a Zenoh client gives up at once on a router that
/// is not there yet).
pub fn wait_for_listener(address: &str, limit: std::time::Duration) {
    let address: std::net::SocketAddr = address.parse().expect("an address");
    let start = std::time::Instant::now();
    while std::net::TcpStream::connect_timeout(&address, std::time::Duration::from_millis(200))
        .is_err()
    {
        assert!(start.elapsed() < limit, "nothing listens on {address} after {limit:?}");
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
}

/// A free TCP port on loopback, for a server the test starts.
pub fn free_port() -> u16 {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").expect("bind loopback");
    listener.local_addr().expect("its address").port()
}

pub mod agent;
pub mod background;
pub mod logs;
pub mod px4;
pub mod sitl;
pub mod vehicles;

/// ArduCopter's own figures (its default parameters) as a drone's world keys:
/// WPNAV_SPEED_UP 250 cm/s, WPNAV_SPEED_DN 150 cm/s, WPNAV_ACCEL 250 cm/s², LAND_SPEED
/// 50 cm/s under LAND_ALT_LOW 1000 cm, RTL_ALT 1500 cm, RTL_LOIT_TIME 5000 ms.
pub const ARDUCOPTER: &str = "climb_rate = 2.5\ndescent_rate = 1.5\nacceleration = 2.5\nland_speed = 0.5\nland_speed_below = 10\nreturn_altitude = 15\nreturn_loiter = 5\n";

/// PX4's own figures (its default parameters, as PX4 SITL gave them) as a drone's world
/// keys: MPC_Z_V_AUTO_UP 3 m/s, MPC_TKO_SPEED 1.5 m/s, MPC_Z_V_AUTO_DN 1.5 m/s,
/// MPC_ACC_HOR 3 m/s² (of which its paths average half: 1.5), MPC_LAND_SPEED 0.7 m/s
/// under MPC_LAND_ALT1 10 m, RTL_RETURN_ALT 30 m, RTL_LAND_DELAY 0 s, MPC_XY_CRUISE 5 m/s.
pub const PX4: &str = "climb_rate = 3\ntakeoff_speed = 1.5\ndescent_rate = 1.5\nacceleration = 1.5\nland_speed = 0.7\nland_speed_below = 10\nreturn_altitude = 30\nreturn_loiter = 0\nreturn_speed = 5\n";

/// The paper's mission flown in the simulator and planned (`aviary check --plan`), in
/// its world with `keys(name)` added to each drone (the figures of the vehicles that fly
/// it for real): the run's output, its events, and the plan.
pub fn simulated_and_planned(
    dir: &Path,
    keys: impl Fn(&str) -> String,
) -> (String, aviary_test_support::trace::Trace, serde_json::Value) {
    let world = dir.join("sim.world.toml");
    std::fs::write(&world, example_world_with(keys)).expect("world");
    let world = world.to_string_lossy().into_owned();
    let trace = dir.join("sim.jsonl");
    let (code, out, err) = aviary(
        &[
            "run",
            "examples/search_and_rescue.mission",
            "--world",
            &world,
            "--trace",
            &trace.to_string_lossy(),
        ],
        &repo(),
    );
    assert_eq!(code, 0, "the simulated run: {err}");
    let (code, plan, err) = aviary(
        &[
            "check",
            "--plan",
            "--format",
            "json",
            "examples/search_and_rescue.mission",
            "--world",
            &world,
        ],
        &repo(),
    );
    assert_eq!(code, 0, "the plan: {err}");
    let plan = serde_json::from_str(&plan).expect("the plan's JSON");
    (out, background::events(&trace), plan)
}

/// Each of the `real` drones' flight time (from `aviary run`'s summary, `out`) against
/// the simulator's (`sim_out`) and the plan's: those more than `share` apart, in words.
pub fn flight_times_apart(
    out: &str,
    sim_out: &str,
    plan: &serde_json::Value,
    real: &[&str],
    share: f64,
) -> Vec<String> {
    let (flown, sim) = (summary_rows(out), summary_rows(sim_out));
    let flight = |rows: &[(String, f64, f64)], name: &str| {
        rows.iter().find(|r| r.0 == name).map(|r| r.2).expect("a summary row")
    };
    let planned = |name: &str| {
        plan["plan"]["drones"]
            .as_array()
            .expect("drones")
            .iter()
            .find(|d| d["drone"] == name)
            .and_then(|d| d["flight_time"].as_f64())
            .expect("a planned flight time")
    };
    let mut apart = Vec::new();
    for name in real {
        let real_time = flight(&flown, name);
        for (what, t) in [("the simulator", flight(&sim, name)), ("the plan", planned(name))] {
            if (t - real_time).abs() > share * real_time {
                apart.push(format!("{name}: {real_time:.0} s flown, {t:.0} s in {what}"));
            }
        }
    }
    apart
}

/// The paper's example world with `keys(name)` added to each drone's table.
pub fn example_world_with(keys: impl Fn(&str) -> String) -> String {
    let text = std::fs::read_to_string(repo().join("examples/search_and_rescue.world.toml"))
        .expect("example world");
    let mut out = String::new();
    for line in text.lines() {
        out.push_str(line);
        out.push('\n');
        if let Some(name) = line.strip_prefix("[drones.").and_then(|l| l.strip_suffix(']')) {
            out.push_str(&keys(name));
        }
    }
    out
}

/// The summary table `aviary run` prints: per drone, (name, distance m, flight s).
pub fn summary_rows(out: &str) -> Vec<(String, f64, f64)> {
    out.lines()
        .skip_while(|l| !l.starts_with("drone "))
        .skip(1)
        .take_while(|l| !l.starts_with("signals:"))
        .map(|l| {
            let f: Vec<&str> = l.split_whitespace().collect();
            (f[0].to_string(), f[1].parse().expect("distance"), f[2].parse().expect("flight time"))
        })
        .collect()
}

/// Where each drone of the paper's world stands (its `home`), for the vehicles that
/// stand in for it.
pub fn paper_home(name: &str) -> [f64; 2] {
    match name {
        "video_drone1" => [0.0, 0.0],
        "video_drone2" => [5.0, 0.0],
        "flir_drone1" => [0.0, 5.0],
        "flir_drone2" => [5.0, 5.0],
        "sensor_drone" => [10.0, 0.0],
        "beacon_drone1" => [-10.0, -10.0],
        "beacon_drone2" => [10.0, -10.0],
        other => panic!("no drone {other} in the example"),
    }
}

/// The signals (with their counts) and finds of a trace, which must not depend on
/// whether the drones are real or simulated.
pub fn paper_outcome(
    events: &[aviary_api::trace::Record<'static>],
) -> (Vec<String>, Vec<(String, i64, i64)>) {
    use aviary_api::trace::Event;
    let mut signals: Vec<String> = events
        .iter()
        .filter_map(|e| match &e.event {
            Event::Signal { name, .. } => Some(name.to_string()),
            _ => None,
        })
        .collect();
    signals.sort();
    let mut finds: Vec<(String, i64, i64)> = events
        .iter()
        .filter_map(|e| match &e.event {
            Event::Detection { kind, location, .. } => {
                let at = |i: usize| background::pos(*location)[i].round() as i64;
                Some((kind.to_string(), at(0), at(1)))
            }
            _ => None,
        })
        .collect();
    finds.sort();
    (signals, finds)
}
