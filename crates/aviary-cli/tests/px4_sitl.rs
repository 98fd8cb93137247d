//! Aviary against PX4, the paper's autopilot: PX4 SITL with its built-in SIH simulator,
//! each vehicle a process of its own, flown by `aviary run` over MAVLink on UDP. The
//! tests run where `AVIARY_PX4` names PX4's `bin/px4` (build.rs turns on
//! `cfg(px4_sitl)`); elsewhere each is ignored with the line that says how to run it.
//! `AVIARY_PX4_SPEED=5` runs PX4 five times faster than real time; the mission keeps
//! the vehicles' clock, so it flies the same (docs/REAL_DRONES.md).

mod common;

use std::path::Path;

use common::px4::{Px4, ORIGIN};
use common::{aviary, scratch};
use serde_json::Value;

fn events(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap_or_default()
        .lines()
        .map(|l| serde_json::from_str(l).expect("a whole JSON event"))
        .collect()
}

fn pos(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("a position");
    let n = |i: usize| a.get(i).and_then(Value::as_f64).unwrap_or(0.0);
    [n(0), n(1), n(2)]
}

/// A world of PX4 copters, each `(name, vehicle)` at its home.
fn world(copters: &[(&str, [f64; 2], &Px4)], extra: &str) -> String {
    let mut w = format!(
        "[site]\nname = \"PX4\"\norigin = {{ lat = {}, lon = {}, alt = {} }}\nmax_altitude = 60\n{extra}\n",
        ORIGIN.lat, ORIGIN.lon, ORIGIN.alt
    );
    for (name, home, px4) in copters {
        w += &format!(
            "[drones.{name}]\nhome = [{}, {}]\nmavlink = \"{}\"\nsystem_id = {}\n",
            home[0],
            home[1],
            px4.address(),
            px4.system
        );
    }
    w
}

/// The `api_done` of `function`, the first after `after` events.
fn done<'a>(events: &'a [Value], function: &str) -> (usize, &'a Value) {
    events
        .iter()
        .enumerate()
        .find(|(_, e)| e["event"] == "api_done" && e["function"] == function)
        .unwrap_or_else(|| panic!("no {function} done in {events:?}"))
}

/// The hop mission a PX4 user tried first: PX4 took off, then came down to land on the
/// first `FlyTo` (it read the height above home as one above sea level). Now: up, over,
/// around in PX4's ORBIT mode, and down, each where the trace says.
#[test]
#[cfg_attr(
    not(px4_sitl),
    ignore = "PX4 SITL not named: set AVIARY_PX4=/path/to/build/px4_sitl_default/bin/px4 to fly it (docs/REAL_DRONES.md)"
)]
fn the_hop_mission_takes_off_flies_orbits_and_lands() {
    let dir = scratch("px4_hop");
    let px4 = Px4::start(&dir, [0.0, 0.0]);
    std::fs::write(
        dir.join("m.world.toml"),
        world(&[("copter", [0.0, 0.0], &px4)], "[places]\nFar = [30, 30]\n"),
    )
    .expect("world");
    std::fs::write(
        dir.join("m.mission"),
        "MISSION Hop:\n    SEQUENTIAL Fly:\n        copter TakeOff WITH 12m\n        copter FlyTo WITH Far\n        copter FlyCircle WITH Far, 15m, 1\n        copter Land\n",
    )
    .expect("mission");
    let (code, out, err) =
        aviary(&["run", "m.mission", "--trace", "t.jsonl", "--telemetry-hz", "4"], &dir);
    assert_eq!(code, 0, "{out}{err}\nsee {}", dir.display());
    let flown = events(&dir.join("t.jsonl"));
    let (_, up) = done(&flown, "TakeOff");
    assert!((pos(&up["position"])[2] - 12.0).abs() < 1.0, "{up}");
    let (_, there) = done(&flown, "FlyToPosition");
    let p = pos(&there["position"]);
    assert!((p[0] - 30.0).hypot(p[1] - 30.0) < 2.0 && (p[2] - 12.0).abs() < 1.5, "{there}");
    // Around the circle: once on it, within 3 m of its radius, through every quarter.
    let (start, _) = done(&flown, "FlyToPosition");
    let (end, _) = done(&flown, "Orbit");
    let on: Vec<[f64; 3]> = flown[start..end]
        .iter()
        .filter(|e| e["event"] == "telemetry")
        .map(|e| pos(&e["position"]))
        .skip_while(|p| ((p[0] - 30.0).hypot(p[1] - 30.0) - 15.0).abs() > 3.0)
        .collect();
    assert!(on.len() > 20, "too few positions on the circle: {on:?}");
    for p in &on {
        let r = (p[0] - 30.0).hypot(p[1] - 30.0);
        assert!((r - 15.0).abs() < 3.0, "{r} m from the center at {p:?}");
    }
    let quarter = |p: &[f64; 3]| usize::from(p[0] > 30.0) + 2 * usize::from(p[1] > 30.0);
    let mut seen = [false; 4];
    on.iter().for_each(|p| seen[quarter(p)] = true);
    assert_eq!(seen, [true; 4], "the orbit went all the way round: {on:?}");
    let (_, down) = done(&flown, "Land");
    assert!(pos(&down["position"])[2] < 0.5, "{down}");
    assert!(out.contains("mission ok"), "{out}");
}

/// The paper's mission on seven PX4 copters (the beacon carriers with PX4's payload
/// deliverer as their gripper): it ends ok with the signals and finds of the simulated
/// run of the same files, and every beacon is dropped within 5 m of its find.
#[test]
#[cfg_attr(
    not(px4_sitl),
    ignore = "PX4 SITL not named: set AVIARY_PX4=/path/to/build/px4_sitl_default/bin/px4 to fly it (docs/REAL_DRONES.md)"
)]
fn the_paper_mission_on_seven_px4_copters() {
    let dir = scratch("px4_paper");
    let copters: Vec<(&str, Px4)> = common::PAPER_DRONES
        .iter()
        .map(|name| {
            let px4 = Px4::start(&dir, common::paper_home(name));
            (*name, if name.starts_with("beacon") { px4.with_gripper() } else { px4 })
        })
        .collect();
    std::fs::copy(common::repo().join("examples/search_and_rescue.mission"), dir.join("m.mission"))
        .expect("mission");
    let world = common::example_world_with(|name| {
        let (_, px4) = copters.iter().find(|(n, _)| *n == name).expect("a PX4 copter");
        format!("mavlink = \"{}\"\nsystem_id = {}\n", px4.address(), px4.system)
    });
    std::fs::write(dir.join("m.world.toml"), world).expect("world");
    let (code, out, err) =
        aviary(&["run", "m.mission", "--trace", "t.jsonl", "--telemetry-hz", "1"], &dir);
    assert_eq!(code, 0, "{out}{err}\nsee {}", dir.display());
    let flown = events(&dir.join("t.jsonl"));

    let (code, _, err) = aviary(
        &[
            "run",
            "examples/search_and_rescue.mission",
            "--trace",
            &dir.join("sim.jsonl").to_string_lossy(),
        ],
        &common::repo(),
    );
    assert_eq!(code, 0, "the simulated run: {err}");
    let simulated = events(&dir.join("sim.jsonl"));
    assert_eq!(
        common::paper_outcome(&flown),
        common::paper_outcome(&simulated),
        "the same signals and finds"
    );
    let finds: Vec<[f64; 3]> =
        flown.iter().filter(|e| e["event"] == "detection").map(|e| pos(&e["location"])).collect();
    let drops: Vec<&Value> = flown
        .iter()
        .filter(|e| e["event"] == "api_done" && e["function"] == "ReleasePayload")
        .collect();
    assert_eq!(drops.len(), finds.len(), "a beacon for every find");
    for drop in drops {
        let at = pos(&drop["position"]);
        let near =
            finds.iter().map(|f| (f[0] - at[0]).hypot(f[1] - at[1])).fold(f64::INFINITY, f64::min);
        assert!(
            near <= 5.0,
            "{} dropped its beacon {near:.1} m from the nearest find",
            drop["actor"]
        );
    }
    println!("{out}");
}
