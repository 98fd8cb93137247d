//! Aviary against PX4, the paper's autopilot: PX4 SITL with its built-in SIH simulator,
//! each vehicle a process of its own, flown by `aviary run` over MAVLink on UDP. The
//! tests run where `AVIARY_PX4` names PX4's `bin/px4` (build.rs turns on
//! `cfg(px4_sitl)`); elsewhere each is ignored with the line that says how to run it.
//! `AVIARY_PX4_SPEED=5` runs PX4 five times faster than real time; the mission keeps
//! the vehicles' clock, so it flies the same (docs/REAL_DRONES.md).

mod common;

use aviary_api::trace::{Event, EventKind, Record};
use aviary_api::Function;
use common::background::{events, pos};
use common::px4::{Px4, ORIGIN};
use common::sitl::{Sitl, BIG_BATTERY};
use common::{aviary, scratch};

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

/// The first `api_done` of `function`: its index, and it.
fn done<'a>(events: &'a [Record<'static>], function: Function) -> (usize, &'a Record<'static>) {
    events
        .iter()
        .enumerate()
        .find(|(_, e)| matches!(&e.event, Event::ApiDone { function: f, .. } if *f == function))
        .unwrap_or_else(|| panic!("no {function:?} done in {events:?}"))
}

/// Where a call left its drone (an `api_done`), or a find was made (a `detection`), or a
/// drone was (`telemetry`).
fn at(e: &Record) -> [f64; 3] {
    match e.event {
        Event::ApiDone { position, .. } | Event::Telemetry { position, .. } => pos(position),
        Event::Detection { location, .. } => pos(location),
        ref other => panic!("no position in {other:?}"),
    }
}

/// Whether an event is a drone's telemetry.
fn telemetry(e: &&Record) -> bool {
    e.event.kind() == EventKind::Telemetry
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
    let (_, up) = done(&flown, Function::TakeOff);
    assert!((at(up)[2] - 12.0).abs() < 1.0, "{up:?}");
    let (_, there) = done(&flown, Function::FlyToPosition);
    let p = at(there);
    assert!((p[0] - 30.0).hypot(p[1] - 30.0) < 2.0 && (p[2] - 12.0).abs() < 1.5, "{there:?}");
    // Around the circle: once on it, within 3 m of its radius, through every quarter.
    let (start, _) = done(&flown, Function::FlyToPosition);
    let (end, _) = done(&flown, Function::Orbit);
    let on: Vec<[f64; 3]> = flown[start..end]
        .iter()
        .filter(telemetry)
        .map(at)
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
    let (_, down) = done(&flown, Function::Land);
    assert!(at(down)[2] < 0.5, "{down:?}");
    assert!(out.contains("mission ok"), "{out}");
    // PX4's own flight log (ULog, from arming to disarming): every position of the trace
    // lies within 2.5 m of one PX4 logged.
    let log = px4.logs().pop().expect("PX4 wrote a flight log");
    let logged = common::logs::logged_positions(&log, ORIGIN);
    let flown: Vec<[f64; 3]> = flown.iter().filter(telemetry).map(at).collect();
    let (off, at) = common::logs::farthest_from_log(&flown, &logged);
    assert!(off < 2.5, "the trace's {at:?} is {off:.1} m from anything in {}", log.display());
}

/// A path and a sweep, which PX4 flies as missions: through the path's bends at speed
/// (its HOLD, given the points one by one, stopped at each), every lane of the sweep to
/// its end, and the trace where PX4's own log says the copter was.
#[test]
#[cfg_attr(
    not(px4_sitl),
    ignore = "PX4 SITL not named: set AVIARY_PX4=/path/to/build/px4_sitl_default/bin/px4 to fly it (docs/REAL_DRONES.md)"
)]
fn a_path_and_a_sweep_are_flown_through_as_px4_missions() {
    let dir = scratch("px4_paths");
    let px4 = Px4::start(&dir, [0.0, 0.0]);
    std::fs::write(
        dir.join("m.world.toml"),
        world(
            &[("copter", [0.0, 0.0], &px4)],
            "[areas]\nPlot = [[0, 100], [60, 100], [60, 140], [0, 140]]\n",
        ),
    )
    .expect("world");
    std::fs::write(
        dir.join("m.mission"),
        "CAPABILITY Trace BY drone:\n    PERFORM:\n        drone.FollowPath((60, 0), (100, 40), (100, 100))\n\nCAPABILITY Cover BY drone WITH plot:\n    PERFORM:\n        drone.Sweep(plot, 20m)\n\nMISSION Paths:\n    SEQUENTIAL Fly:\n        copter TakeOff WITH 10m\n        copter Trace\n        copter Cover WITH Plot\n        copter Land\n",
    )
    .expect("mission");
    let (code, out, err) =
        aviary(&["run", "m.mission", "--trace", "t.jsonl", "--telemetry-hz", "4"], &dir);
    assert_eq!(code, 0, "{out}{err}\nsee {}", dir.display());
    let flown = events(&dir.join("t.jsonl"));
    let samples = |from: usize, to: usize| -> Vec<(f64, [f64; 3])> {
        flown[from..to].iter().filter(telemetry).map(|e| (e.t, at(e))).collect()
    };
    let (path_end, _) = done(&flown, Function::FollowPath);
    let (sweep_end, _) = done(&flown, Function::Sweep);
    let path = samples(done(&flown, Function::TakeOff).0, path_end);
    // Through the bends at (60, 0) and (100, 40), close to each (point by point, the
    // drone turned up to its pass radius, 25 m, before them), and never stopped: from
    // 20 m out of the start to 20 m before the end, at least 0.5 m/s over any second
    // (PX4 slows to about 1 m/s where the path turns by 45°).
    let far = |p: &[f64; 3], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]);
    for bend in [[60.0, 0.0], [100.0, 40.0]] {
        let near = path.iter().map(|(_, p)| far(p, bend)).fold(f64::INFINITY, f64::min);
        assert!(near < 3.0, "passed {bend:?} {near:.1} m away");
    }
    let middle: Vec<&(f64, [f64; 3])> = path
        .iter()
        .skip_while(|(_, p)| far(p, [0.0, 0.0]) < 20.0)
        .take_while(|(_, p)| far(p, [100.0, 100.0]) > 20.0)
        .collect();
    assert!(middle.len() > 20, "{middle:?}");
    let slowest = middle
        .windows(5)
        .map(|w| far(&w[4].1, [w[0].1[0], w[0].1[1]]) / (w[4].0 - w[0].0))
        .fold(f64::INFINITY, f64::min);
    assert!(slowest > 0.5, "slowed to {slowest:.2} m/s on the path");
    // Every lane of the sweep flown to both its ends.
    let sweep = samples(path_end, sweep_end);
    for lane in
        aviary_api::sweep::lanes(&[[0.0, 100.0], [60.0, 100.0], [60.0, 140.0], [0.0, 140.0]], 20.0)
    {
        for end in lane {
            let near = sweep.iter().map(|(_, p)| far(p, end)).fold(f64::INFINITY, f64::min);
            assert!(near < 2.5, "the lane's end {end:?}: {near:.1} m away");
        }
    }
    let log = px4.logs().pop().expect("PX4 wrote a flight log");
    let logged = common::logs::logged_positions(&log, ORIGIN);
    let all: Vec<[f64; 3]> = samples(0, flown.len()).into_iter().map(|(_, p)| p).collect();
    let (off, at) = common::logs::farthest_from_log(&all, &logged);
    assert!(off < 2.5, "the trace's {at:?} is {off:.1} m from anything in {}", log.display());
}

/// The paper's mission on seven PX4 copters (the beacon carriers with PX4's payload
/// deliverer as their gripper).
#[test]
#[cfg_attr(
    not(px4_sitl),
    ignore = "PX4 SITL not named: set AVIARY_PX4=/path/to/build/px4_sitl_default/bin/px4 to fly it (docs/REAL_DRONES.md)"
)]
fn the_paper_mission_on_seven_px4_copters() {
    paper_mission("px4_paper", &common::PAPER_DRONES, &[]);
}

/// The paper's mission on a mixed fleet: two PX4 copters, two ArduCopter copters and
/// three simulated drones, in one run.
#[test]
#[cfg_attr(
    not(all(px4_sitl, arducopter_sitl)),
    ignore = "PX4 SITL and ArduCopter SITL not both named: set AVIARY_PX4 and AVIARY_SITL to fly it (docs/REAL_DRONES.md)"
)]
fn the_paper_mission_on_px4_arducopter_and_simulated_drones() {
    paper_mission(
        "px4_mixed",
        &["video_drone1", "beacon_drone1"],
        &["flir_drone1", "beacon_drone2"],
    );
}

/// The paper's mission with the drones `px4` names on PX4 SITL, those `arducopter` names
/// on ArduCopter SITL and the rest simulated: it ends ok with the signals and finds of
/// the simulated run, every beacon is dropped within 5 m of its find, and each real
/// drone's flight time is within 15% of what the simulator and the plan give for a drone
/// with its autopilot's figures.
fn paper_mission(tag: &str, px4: &[&str], arducopter: &[&str]) {
    let dir = scratch(tag);
    let px4s: Vec<(&str, Px4)> = px4
        .iter()
        .map(|name| {
            let v = Px4::start(&dir, common::paper_home(name));
            (*name, if name.starts_with("beacon") { v.with_gripper() } else { v })
        })
        .collect();
    // ArduCopter's system ids stay clear of PX4's (its instance number + 1, 1 to 10).
    let sitls: Vec<(&str, Sitl)> = arducopter
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let system = 20 + i as u8;
            (*name, Sitl::start(&dir, 40, system, common::paper_home(name), BIG_BATTERY))
        })
        .collect();
    std::fs::copy(common::repo().join("examples/search_and_rescue.mission"), dir.join("m.mission"))
        .expect("mission");
    let world = common::example_world_with(|name| {
        let link = |address: String, system: u8| {
            format!("mavlink = \"{address}\"\nsystem_id = {system}\n")
        };
        if let Some((_, v)) = px4s.iter().find(|(n, _)| *n == name) {
            link(v.address(), v.system)
        } else if let Some((_, v)) = sitls.iter().find(|(n, _)| *n == name) {
            link(v.address(), v.system)
        } else {
            String::new()
        }
    });
    std::fs::write(dir.join("m.world.toml"), world).expect("world");
    // The same drones in the simulator, each real one with its autopilot's figures.
    let (sim_out, simulated, plan) = common::simulated_and_planned(&dir, |name| {
        if px4.contains(&name) {
            common::PX4.to_owned()
        } else if arducopter.contains(&name) {
            common::ARDUCOPTER.to_owned()
        } else {
            String::new()
        }
    });

    let (code, out, err) =
        aviary(&["run", "m.mission", "--trace", "t.jsonl", "--telemetry-hz", "1"], &dir);
    assert_eq!(code, 0, "{out}{err}\nsee {}", dir.display());
    let flown = events(&dir.join("t.jsonl"));
    assert_eq!(
        common::paper_outcome(&flown),
        common::paper_outcome(&simulated),
        "the same signals and finds"
    );
    let finds: Vec<[f64; 3]> =
        flown.iter().filter(|e| e.event.kind() == EventKind::Detection).map(at).collect();
    let drops: Vec<&Record> = flown
        .iter()
        .filter(|e| matches!(e.event, Event::ApiDone { function: Function::ReleasePayload, .. }))
        .collect();
    assert_eq!(drops.len(), finds.len(), "a beacon for every find");
    for drop in drops {
        let at = at(drop);
        let near =
            finds.iter().map(|f| (f[0] - at[0]).hypot(f[1] - at[1])).fold(f64::INFINITY, f64::min);
        assert!(
            near <= 5.0,
            "{:?} dropped its beacon {near:.1} m from the nearest find",
            aviary_test_support::trace::actor(&drop.event)
        );
    }
    let real: Vec<&str> = px4.iter().chain(arducopter).copied().collect();
    println!("{out}\nthe simulator, with the autopilots' figures:\n{sim_out}");
    let off = common::flight_times_apart(&out, &sim_out, &plan, &real, 0.15);
    assert!(off.is_empty(), "flight times more than 15% apart:\n{}", off.join("\n"));
}

/// One PX4 copter: each of PX4's failsafes reaching the mission as the language's
/// exception, a target PX4 refuses in words, and a vehicle that stops and comes back.
mod single {
    use std::path::PathBuf;
    use std::time::{Duration, Instant};

    use super::*;
    use aviary_mavlink::mavlink::dialects::ardupilotmega as mav;
    use common::background::{
        airborne, exception, finish, said, signal_names, signalled, start_run, Run,
    };
    use common::sitl::{wait_until, Gcs};

    /// A copter `d` at home (0, 0), set up by the test's ground station (`before`), and
    /// `aviary run` flying `mission` on it.
    fn one(
        tag: &str,
        world_extra: &str,
        mission: &str,
        before: impl FnOnce(&Gcs),
    ) -> (PathBuf, Px4, Gcs, Run) {
        let dir = scratch(tag);
        let px4 = Px4::start(&dir, [0.0, 0.0]);
        let gcs = px4.gcs();
        before(&gcs);
        std::fs::write(dir.join("m.world.toml"), world(&[("d", [0.0, 0.0], &px4)], world_extra))
            .expect("world");
        std::fs::write(dir.join("m.mission"), mission).expect("mission");
        let run = start_run(&dir, "m.mission");
        (dir, px4, gcs, run)
    }

    /// The exception `name`, raised on `d` and handled, with PX4's own action before it.
    fn caught<'a>(flown: &'a [Record<'static>], name: &str, out: &str) -> &'a Record<'static> {
        let e = exception(flown, name).unwrap_or_else(|| panic!("no {name}:\n{out}"));
        assert!(
            matches!(&e.event, Event::Exception { actor: Some(a), handled: true, .. } if a == "d"),
            "{e:?}"
        );
        assert!(signalled(flown, "Caught"), "the handler ran:\n{out}");
        e
    }

    /// Up, and a hover for as long as a failsafe needs, with a handler of `exception`.
    fn hover(exception: &str) -> String {
        format!("MISSION Drill:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d Hover WITH 120s\n    ON EXCEPTION {exception} BY d:\n        SIGNAL Caught\n")
    }

    #[test]
    #[cfg_attr(
        not(px4_sitl),
        ignore = "PX4 SITL not named: set AVIARY_PX4=/path/to/build/px4_sitl_default/bin/px4 to fly it (docs/REAL_DRONES.md)"
    )]
    fn an_emptied_battery_raises_battery_critical() {
        // PX4's failure injection empties its simulated battery. Its charge, as PX4
        // reports it, falls below what the way home needs: the backend's battery rule
        // raises BatteryCritical (PX4's own failsafe, COM_LOW_BAT_ACT 3, acts on the same
        // battery a moment later, unless the mission has already sent the drone home).
        let (dir, _px4, gcs, mut run) = one("px4_battery", "", &hover("BatteryCritical"), |gcs| {
            gcs.set_param_px4_int("SYS_FAILURE_EN", 1);
            gcs.set_param_px4_int("COM_LOW_BAT_ACT", 3);
        });
        airborne(&dir, Duration::from_secs(150));
        let answer = gcs.command(
            mav::MavCmd::MAV_CMD_INJECT_FAILURE,
            [100.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0], // the battery, off
        );
        assert_eq!(answer, mav::MavResult::MAV_RESULT_ACCEPTED);
        let (code, out) = finish(&mut run, &dir, Duration::from_secs(300));
        let flown = events(&dir.join("t.jsonl"));
        let e = caught(&flown, "BatteryCritical", &out);
        assert!(said(e).contains("% left"), "from the charge PX4 reports: {e:?}");
        assert_eq!(code, 0, "{out}");
    }

    #[test]
    #[cfg_attr(
        not(px4_sitl),
        ignore = "PX4 SITL not named: set AVIARY_PX4=/path/to/build/px4_sitl_default/bin/px4 to fly it (docs/REAL_DRONES.md)"
    )]
    fn the_vehicles_own_fence_raises_geofence_violation() {
        // PX4 refuses a reposition outside its fence, so the breach is made as on a real
        // site: the drone is 80 m out when the ground station sets PX4's fence, 50 m
        // from home with Return, which the world knows nothing of.
        let mission = "MISSION Drill:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d FlyTo WITH Far\n        d Hover WITH 120s\n    ON EXCEPTION GeofenceViolation BY d:\n        SIGNAL Caught\n";
        let (dir, _px4, gcs, mut run) =
            one("px4_fence", "[places]\nFar = [0, 80]\n", mission, |_| {});
        wait_until(Duration::from_secs(200), "the flight out", || {
            events(&dir.join("t.jsonl")).iter().any(|e| {
                matches!(e.event, Event::ApiDone { function: Function::FlyToPosition, .. })
            })
        });
        gcs.set_param_px4_int("GF_ACTION", 3);
        gcs.set_param("GF_MAX_HOR_DIST", 50.0);
        let (_, out) = finish(&mut run, &dir, Duration::from_secs(300));
        let flown = events(&dir.join("t.jsonl"));
        caught(&flown, "GeofenceViolation", &out);
    }

    #[test]
    #[cfg_attr(
        not(px4_sitl),
        ignore = "PX4 SITL not named: set AVIARY_PX4=/path/to/build/px4_sitl_default/bin/px4 to fly it (docs/REAL_DRONES.md)"
    )]
    fn a_target_outside_px4s_fence_fails_with_px4s_words() {
        // PX4 acknowledges the reposition, then its navigator refuses it in words alone
        // (with a fence that has an action: one that only warns lets it fly).
        let mission = "MISSION Drill:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d FlyTo WITH Far\n    ON EXCEPTION CommandFailed BY d:\n        SIGNAL Caught\n";
        let (dir, _px4, _gcs, mut run) =
            one("px4_refused", "[places]\nFar = [0, 80]\n", mission, |gcs| {
                gcs.set_param_px4_int("GF_ACTION", 3);
                gcs.set_param("GF_MAX_HOR_DIST", 50.0);
            });
        let started = Instant::now();
        let (code, out) = finish(&mut run, &dir, Duration::from_secs(300));
        let flown = events(&dir.join("t.jsonl"));
        let e = caught(&flown, "CommandFailed", &out);
        let said = said(e);
        assert!(said.contains("Reposition is outside geofence"), "PX4's own words in {said}");
        assert_eq!(code, 0, "{out}");
        // Refused at once, not after the flight's time ran out.
        let (_, up) = done(&flown, Function::TakeOff);
        let refused = e.t - up.t;
        assert!(
            refused < 10.0,
            "refused {refused:.1} s after the take-off ({:?} in all)",
            started.elapsed()
        );
    }

    #[test]
    #[cfg_attr(
        not(px4_sitl),
        ignore = "PX4 SITL not named: set AVIARY_PX4=/path/to/build/px4_sitl_default/bin/px4 to fly it (docs/REAL_DRONES.md)"
    )]
    fn gps_loss_raises_position_lost() {
        // PX4's SIH takes no GPS failure injection (only its Gazebo bridge does): its
        // simulated GPS loses its fix when it sees fewer than 4 satellites.
        let (dir, _px4, gcs, mut run) = one("px4_gps", "", &hover("PositionLost"), |_| {});
        airborne(&dir, Duration::from_secs(150));
        gcs.set_param_px4_int("SIM_GPS_USED", 0);
        let (_, out) = finish(&mut run, &dir, Duration::from_secs(300));
        let flown = events(&dir.join("t.jsonl"));
        let e =
            exception(&flown, "PositionLost").unwrap_or_else(|| panic!("no PositionLost:\n{out}"));
        assert!(matches!(&e.event, Event::Exception { actor: Some(a), .. } if a == "d"));
    }

    #[test]
    #[cfg_attr(
        not(px4_sitl),
        ignore = "PX4 SITL not named: set AVIARY_PX4=/path/to/build/px4_sitl_default/bin/px4 to fly it (docs/REAL_DRONES.md)"
    )]
    fn a_stopped_vehicle_is_lost_and_a_restarted_one_restored() {
        let mission = "MISSION Drill:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d Hover WITH 200s\n    ON EXCEPTION ConnectionLost BY d:\n        SIGNAL Offline\n        WAITFOR RECEIVED(Back)\n    ON ConnectionRestored BY d:\n        SIGNAL Back\n";
        let (dir, mut px4, _gcs, mut run) = one("px4_link", "", mission, |_| {});
        airborne(&dir, Duration::from_secs(150));
        px4.kill();
        let lost_at = Instant::now();
        wait_until(Duration::from_secs(30), "ConnectionLost", || {
            exception(&events(&dir.join("t.jsonl")), "ConnectionLost").is_some()
        });
        let noticed = lost_at.elapsed();
        assert!(noticed < Duration::from_secs(10), "the lost link was noticed after {noticed:?}");
        px4.restart();
        let (code, out) = finish(&mut run, &dir, Duration::from_secs(200));
        let flown = events(&dir.join("t.jsonl"));
        let signals = signal_names(&flown);
        for s in ["Offline", "ConnectionRestored", "Back"] {
            assert!(signals.contains(&s), "{s} in {signals:?}:\n{out}");
        }
        assert_eq!(code, 0, "{out}");
    }
}
