//! Aviary against a real autopilot: ArduCopter SITL, each vehicle a process of its own,
//! flown by `aviary run` over MAVLink on TCP. The tests run where `AVIARY_SITL` names the
//! binary (build.rs turns on `cfg(arducopter_sitl)`); elsewhere each is ignored with the
//! line that says how to run it.
//!
//! - `fleet::`: the paper's mission on seven SITL copters, and on two SITL copters with
//!   five simulated drones. These are the long ones (10 minutes of real flight); their
//!   module sorts first so that the test harness starts them first and side by side.
//! - `facts::`: the paper's mission checked (`aviary check --plan`, no flight) on seven
//!   copters that say their own battery: too small by default, enough with 16.5 Ah.
//! - `single::`: one copter: a flight with an orbit whose trace agrees with what SITL
//!   reports to a second ground station; each autopilot failsafe (battery, geofence, GPS,
//!   link) reaching the mission as the language's exception; a refused command; a vehicle
//!   that is not where the world says.
//!
//! SITL runs at real time (`--speedup 1`): the mission clock is the wall clock, which a
//! faster SITL would leave behind (docs/REAL_DRONES.md).

mod common;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use aviary_api::trace::{Event, EventKind, Record, Status};
use aviary_api::Function;
use common::background::{
    events, exception, finish, named, pos, said, signal_names, signalled, start_run, Run,
};
use common::sitl::{wait_until, Sitl, BIG_BATTERY};
use common::{aviary, repo, scratch, PAPER_DRONES};

fn dist2(a: [f64; 3], b: [f64; 3]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// A world of one SITL copter `d` at home (0, 0): `extra` adds places or a fence.
fn one_copter_world(sitl: &Sitl, extra: &str) -> String {
    format!(
        "[site]\nname = \"SITL\"\norigin = {{ lat = {}, lon = {}, alt = {} }}\nmax_altitude = 60\n{extra}\n[drones.d]\nhome = [0, 0]\nmavlink = \"{}\"\nsystem_id = {}\n",
        common::sitl::ORIGIN.lat,
        common::sitl::ORIGIN.lon,
        common::sitl::ORIGIN.alt,
        sitl.address(),
        sitl.system
    )
}

/// The example world with `mavlink` and `system_id` for the drones `sitls` names.
fn example_world(sitls: &[(&str, &Sitl)]) -> String {
    example_world_with(sitls, "")
}

/// As [`example_world`], with `extra` (keys) added to every drone.
fn example_world_with(sitls: &[(&str, &Sitl)], extra: &str) -> String {
    common::example_world_with(|name| {
        let link = match sitls.iter().find(|(n, _)| *n == name) {
            Some((_, s)) => format!("mavlink = \"{}\"\nsystem_id = {}\n", s.address(), s.system),
            None => String::new(),
        };
        format!("{extra}{link}")
    })
}

/// The paper's mission with the drones in `real` on SITL and the rest simulated: it ends
/// ok with the signals and finds of the simulated run, every beacon is dropped within
/// 5 m of its target, and each SITL drone's flight time is within 15% of what the plan
/// and the simulator give for a drone with ArduCopter's figures.
fn paper_mission(tag: &str, first_instance: u16, real: &[&str]) {
    let dir = scratch(tag);
    let sitls: Vec<(&str, Sitl)> = real
        .iter()
        .enumerate()
        .map(|(i, name)| {
            (
                *name,
                Sitl::start(
                    &dir,
                    first_instance,
                    i as u8 + 1,
                    common::paper_home(name),
                    BIG_BATTERY,
                ),
            )
        })
        .collect();
    let refs: Vec<(&str, &Sitl)> = sitls.iter().map(|(n, s)| (*n, s)).collect();
    std::fs::copy(repo().join("examples/search_and_rescue.mission"), dir.join("m.mission"))
        .expect("mission");
    std::fs::write(dir.join("m.world.toml"), example_world(&refs)).expect("world");
    // The same drones in the simulator: those on SITL with ArduCopter's figures.
    let (sim_out, simulated, plan) = common::simulated_and_planned(&dir, |name| {
        if real.contains(&name) {
            common::ARDUCOPTER.to_owned()
        } else {
            String::new()
        }
    });

    let mut run = start_run(&dir, "m.mission");
    let (code, out) = finish(&mut run, &dir, Duration::from_secs(1500));
    assert_eq!(code, 0, "the mission on SITL ended badly:\n{out}\nsee {}", dir.display());
    let flown = events(&dir.join("t.jsonl"));
    assert_eq!(
        common::paper_outcome(&flown),
        common::paper_outcome(&simulated),
        "the same signals and finds as the simulated run"
    );
    let finds: Vec<[f64; 3]> = named(&flown, EventKind::Detection)
        .map(|e| match e.event {
            Event::Detection { location, .. } => pos(location),
            _ => unreachable!(),
        })
        .collect();
    let drops: Vec<(&str, [f64; 3])> = flown
        .iter()
        .filter_map(|e| match &e.event {
            Event::ApiDone { actor, function: Function::ReleasePayload, position, .. } => {
                Some((&**actor, pos(*position)))
            }
            _ => None,
        })
        .collect();
    assert_eq!(drops.len(), finds.len(), "a beacon for every find");
    for (actor, at) in drops {
        let near = finds.iter().map(|f| dist2(*f, at)).fold(f64::INFINITY, f64::min);
        assert!(near <= 5.0, "{actor:?} dropped its beacon {near:.1} m from the nearest find");
    }
    let end = flown.last().expect("events");
    assert!(matches!(end.event, Event::MissionEnd { status: Status::Ok, .. }), "{end:?}");

    // Flight times: SITL's (from the track it reported) against the simulator's and the
    // plan's for the same drone.
    let off = common::flight_times_apart(&out, &sim_out, &plan, real, 0.15);
    assert!(off.is_empty(), "flight times more than 15% apart:\n{}", off.join("\n"));
}

mod fleet {
    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn paper_mission_on_seven_sitl_copters() {
        super::paper_mission("sitl_paper", 0, &super::PAPER_DRONES);
    }

    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn paper_mission_on_two_sitl_copters_and_five_simulated() {
        super::paper_mission("sitl_mixed", 10, &["flir_drone2", "beacon_drone2"]);
    }
}

/// What the vehicles say of themselves plans the mission: `aviary check --plan` reads each
/// copter's BATT_CAPACITY (and its other figures) before flight. No flight: the copters
/// only boot and answer.
mod facts {
    use super::*;

    /// The paper's mission on seven copters with ArduPilot's default battery (3300 mAh),
    /// in a world whose drones draw SITL's 30 A: 6.6 minutes of flight for a mission whose
    /// longest drone flies about 8. The check warns before flight, naming the drones; with
    /// BATT_CAPACITY 16500 set on the same running vehicles it does not.
    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn check_plan_warns_when_the_vehicles_batteries_cannot_finish_the_paper_mission() {
        let dir = scratch("sitl_facts");
        let sitls: Vec<(&str, Sitl)> = PAPER_DRONES
            .iter()
            .enumerate()
            .map(|(i, n)| (*n, Sitl::start(&dir, 30, i as u8 + 1, common::paper_home(n), &[])))
            .collect();
        let refs: Vec<(&str, &Sitl)> = sitls.iter().map(|(n, s)| (*n, s)).collect();
        std::fs::copy(repo().join("examples/search_and_rescue.mission"), dir.join("m.mission"))
            .expect("mission");
        std::fs::write(
            dir.join("m.world.toml"),
            example_world_with(&refs, "flight_current = 30\n"),
        )
        .expect("world");
        let warned = |out: &str| -> Vec<&str> {
            PAPER_DRONES
                .iter()
                .copied()
                .filter(|n| out.contains(&format!("{n}'s battery is estimated to fall under 20%")))
                .collect()
        };

        // The world alone knows the draw but not the capacity: its 30 minutes, no warning.
        let (code, out, err) = aviary(&["check", "--plan", "--offline", "m.mission"], &dir);
        assert_eq!(code, 0, "{out}{err}");
        assert!(
            warned(&out).is_empty() && !out.contains("W204"),
            "offline, the world's endurance suffices:\n{out}"
        );

        let start = Instant::now();
        let (code, out, err) = aviary(&["check", "--plan", "m.mission"], &dir);
        let took = start.elapsed();
        std::fs::write(dir.join("check-default.txt"), &out).expect("keep the output");
        assert_eq!(code, 0, "a warning is no error:\n{out}{err}");
        for (name, s) in &refs {
            let source = format!(
                "{name}: figures from the vehicle on {} (system {}), charge 100%",
                s.address(),
                s.system
            );
            assert!(out.contains(&source), "{source:?} in:\n{out}");
            assert!(
                out.contains(&format!(
                    "{name}: battery 3300 mAh (the vehicle's BATT_CAPACITY); the world gave none"
                )),
                "{out}"
            );
            assert!(
                out.contains(&format!(
                    "{name}: endurance 6.6 min (3300 mAh at the world's flight_current 30 A)"
                )),
                "{out}"
            );
            assert!(
                out.contains(&format!(
                    "{name}: descent 1.5 m/s (the vehicle's WPNAV_SPEED_DN), not the world's 3 m/s"
                )),
                "{out}"
            );
        }
        let short = warned(&out);
        assert!(
            !short.is_empty() && out.contains("W204") && out.contains("runs out before the end"),
            "the default battery cannot finish:\n{out}"
        );
        eprintln!("check --plan with seven vehicles booting took {took:?}; warned: {short:?}");
        assert!(took < Duration::from_secs(12), "check --plan took {took:?}");

        // A battery that suffices, on the same vehicles (and SITL's simulated one to match).
        for (_, s) in &sitls {
            let gcs = s.gcs(Duration::from_secs(10));
            for (name, value) in BIG_BATTERY {
                gcs.set_param(name, *value as f32);
            }
        }
        let (code, out, err) = aviary(&["check", "--plan", "m.mission"], &dir);
        std::fs::write(dir.join("check-16500.txt"), &out).expect("keep the output");
        assert_eq!(code, 0, "{out}{err}");
        for name in PAPER_DRONES {
            assert!(
                out.contains(&format!("{name}: battery 16500 mAh (the vehicle's BATT_CAPACITY)")),
                "{out}"
            );
        }
        assert!(warned(&out).is_empty() && !out.contains("W204"), "16.5 Ah suffices:\n{out}");
    }

    /// `aviary run` plans again with what the vehicle said at connect and, before anything
    /// flies, warns that the battery runs out (10 minutes of hover on 6.6); then it flies
    /// anyway (the choice: handlers and the autopilot's failsafe may cover it). The run is
    /// stopped once the take-off is under way.
    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn run_warns_before_flight_that_the_battery_runs_out_and_flies() {
        let dir = scratch("sitl_facts_run");
        let sitl = Sitl::start(&dir, 30, 1, [0.0, 0.0], &[]);
        std::fs::write(
            dir.join("m.world.toml"),
            one_copter_world(&sitl, "") + "flight_current = 30\n",
        )
        .expect("world");
        std::fs::write(dir.join("m.mission"), "MISSION Long:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d Hover WITH 600s\n").expect("mission");
        let _run = start_run(&dir, "m.mission");
        let stderr = || std::fs::read_to_string(dir.join("stderr.txt")).unwrap_or_default();
        wait_until(Duration::from_secs(120), "the warning", || stderr().contains("WARNING"));
        let said = stderr();
        assert!(
            said.contains("d: figures from the vehicle on")
                && said.contains("d: endurance 6.6 min"),
            "{said}"
        );
        assert!(
            said.contains("warning[W204]: d's battery") && said.contains("runs out before the end"),
            "{said}"
        );
        assert!(
            said.contains("the plan says d's battery runs out before the mission ends")
                && said.contains("Flying anyway"),
            "{said}"
        );
        // 10 minutes on 6.6: about 150 % (the plan adds the take-off and the way home).
        let needs: f64 = said
            .split("it needs about ")
            .nth(1)
            .and_then(|t| t.split('%').next())
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no need in {said}"));
        assert!((140.0..170.0).contains(&needs) && said.contains("starts with 100%"), "{said}");
        // Said before the take-off, which waits for SITL's GPS and EKF (tens of seconds).
        assert!(
            named(&events(&dir.join("t.jsonl")), EventKind::ApiDone).next().is_none(),
            "the warning comes before anything flies"
        );
        wait_until(Duration::from_secs(120), "the take-off", || {
            events(&dir.join("t.jsonl"))
                .iter()
                .any(|e| matches!(e.event, Event::ApiCall { function: Function::TakeOff, .. }))
        });
    }

    /// In flight the battery rule takes the share of the way home from the current the
    /// vehicle measures (SITL's ~30 A) against its BATT_CAPACITY, here 600 mAh (SITL's
    /// simulated battery stays 3.3 Ah, so its voltage stays healthy and no failsafe of
    /// its own starts). Hovering at home, 10 m up: 5 s above home and 20 s down at
    /// 0.5 m/s, 25 s at 30 A = 35 % of 600 mAh, so BatteryLow comes under ~79 % and
    /// BatteryCritical under ~45 %. On the world's figures alone (30 minutes, no capacity)
    /// both would wait until ~13 % and ~11 %.
    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn the_battery_rule_uses_the_draw_the_vehicle_measures() {
        let dir = scratch("sitl_facts_draw");
        let sitl = Sitl::start(&dir, 30, 1, [0.0, 0.0], &[("BATT_CAPACITY", 600.0)]);
        std::fs::write(dir.join("m.world.toml"), one_copter_world(&sitl, "")).expect("world");
        let mission = "MISSION Drain:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d Hover WITH 120s\n    ON EXCEPTION BatteryCritical BY d:\n        SIGNAL Caught\n    ON BatteryLow BY d:\n        SIGNAL Low\n";
        std::fs::write(dir.join("m.mission"), mission).expect("mission");
        let mut run = start_run(&dir, "m.mission");
        let (_, out) = finish(&mut run, &dir, Duration::from_secs(300));
        let flown = events(&dir.join("t.jsonl"));
        // The charge the drone reported last before `event`.
        let charge_before = |event: &Record| -> f64 {
            let t = event.t;
            flown
                .iter()
                .filter_map(|e| match &e.event {
                    Event::Telemetry { actor, battery, .. } if actor == "d" && e.t <= t => {
                        Some(*battery)
                    }
                    _ => None,
                })
                .next_back()
                .filter(|b| b.is_finite())
                .expect("telemetry before")
        };
        let low = flown
            .iter()
            .find(|e| matches!(&e.event, Event::Signal { name, .. } if name == "BatteryLow"))
            .unwrap_or_else(|| panic!("no BatteryLow:\n{out}"));
        let critical = exception(&flown, "BatteryCritical")
            .unwrap_or_else(|| panic!("no BatteryCritical:\n{out}"));
        let (at_low, at_critical) = (charge_before(low), charge_before(critical));
        eprintln!(
            "BatteryLow at {:.0} %, BatteryCritical at {:.0} %",
            at_low * 100.0,
            at_critical * 100.0
        );
        assert!((0.60..=0.85).contains(&at_low), "BatteryLow at {at_low}:\n{out}");
        assert!((0.30..=0.55).contains(&at_critical), "BatteryCritical at {at_critical}:\n{out}");
        assert!(matches!(critical.event, Event::Exception { handled: true, .. }));
        assert!(
            said(critical).contains("about what it needs to get home"),
            "the backend's rule, not SITL's failsafe: {critical:?}"
        );
    }
}

/// One SITL copter `d` (`params` set), and `aviary run` flying `mission` on it.
fn single_copter(
    tag: &str,
    params: &[(&str, f64)],
    world_extra: &str,
    mission: &str,
) -> (PathBuf, Sitl, Run) {
    let dir = scratch(tag);
    let sitl = Sitl::start(&dir, 20, 1, [0.0, 0.0], params);
    std::fs::write(dir.join("m.world.toml"), one_copter_world(&sitl, world_extra)).expect("world");
    std::fs::write(dir.join("m.mission"), mission).expect("mission");
    let run = start_run(&dir, "m.mission");
    (dir, sitl, run)
}

mod single {
    use super::*;

    /// One copter, and the test's own ground station on the vehicle's second port.
    fn one(
        tag: &str,
        params: &[(&str, f64)],
        world_extra: &str,
        mission: &str,
    ) -> (PathBuf, Sitl, Run) {
        super::single_copter(tag, params, world_extra, mission)
    }

    /// Waits until the trace shows the drone in the air (after GPS lock and take-off).
    fn airborne(dir: &Path) {
        common::background::airborne(dir, Duration::from_secs(150));
    }

    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn takes_off_flies_orbits_and_lands_where_sitl_says() {
        let mission = "MISSION Sitl:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d FlyTo WITH North\n        d FlyCircle WITH North, 20m, 1\n        d Land\n";
        let (dir, sitl, mut run) = one("sitl_one", &[], "[places]\nNorth = [0, 40]\n", mission);
        let gcs = sitl.gcs(Duration::from_secs(30));
        let (code, out) = finish(&mut run, &dir, Duration::from_secs(400));
        assert_eq!(code, 0, "{out}");
        let flown = events(&dir.join("t.jsonl"));
        // Every position the trace gives lies on the track SITL reported to the ground
        // station (10 Hz, so within a metre or two of some point of it).
        let track = gcs.seen.lock().unwrap().track.clone();
        assert!(track.len() > 100, "the ground station saw the flight");
        let points: Vec<[f64; 3]> = named(&flown, EventKind::Telemetry)
            .map(|e| match e.event {
                Event::Telemetry { position, .. } => pos(position),
                _ => unreachable!(),
            })
            .collect();
        assert!(points.len() > 50, "telemetry in the trace");
        for p in &points {
            let near = track
                .iter()
                .map(|(_, q)| dist2(*p, *q).hypot(p[2] - q[2]))
                .fold(f64::INFINITY, f64::min);
            assert!(near < 2.5, "trace position {p:?} is {near:.1} m from anything SITL reported");
        }
        // The orbit went round: points in all four quadrants about North at ~20 m.
        let circle: Vec<[f64; 3]> = track
            .iter()
            .map(|t| t.1)
            .filter(|q| (dist2(*q, [0.0, 40.0, 0.0]) - 20.0).abs() < 3.0)
            .collect();
        for (sx, sy) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            assert!(
                circle.iter().any(|q| q[0] * sx > 5.0 && (q[1] - 40.0) * sy > 5.0),
                "the orbit passed the ({sx}, {sy}) quadrant"
            );
        }
        // It landed where the trace says, and SITL agrees.
        let end = flown
            .iter()
            .filter_map(|e| match e.event {
                Event::ApiDone { function: Function::Land, position, .. } => Some(position),
                _ => None,
            })
            .next_back()
            .expect("Land ended");
        let landed = gcs.last().expect("a last position");
        assert!(dist2(pos(end), landed) < 1.0 && landed[2].abs() < 0.5, "landed at {landed:?}");
        // Orbit legs are flown through: the lap (126 m) takes nowhere near the ~5 s a stop
        // at each of its 24 points would add.
        let orbit = flown
            .iter()
            .find(|e| matches!(e.event, Event::ApiCall { function: Function::Orbit, .. }))
            .expect("orbit");
        let done = flown
            .iter()
            .find(|e| matches!(e.event, Event::ApiDone { function: Function::Orbit, .. }))
            .expect("orbit end");
        let took = done.t - orbit.t;
        assert!(took < 60.0, "the orbit took {took:.0} s");
        // ArduPilot's own flight log (DataFlash, POS): every position of the trace lies
        // within 2.5 m of one it logged.
        let log = common::logs::files_ending(&sitl.dir, ".BIN").pop().expect("a DataFlash log");
        let logged = common::logs::logged_positions(&log, common::sitl::ORIGIN);
        let (off, at) = common::logs::farthest_from_log(&points, &logged);
        assert!(off < 2.5, "the trace's {at:?} is {off:.1} m from anything in {}", log.display());
    }

    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn a_drained_battery_raises_battery_critical() {
        // ArduCopter's own battery failsafe: under 10.5 V for 2 s, RTL.
        let params = [("BATT_LOW_VOLT", 10.5), ("BATT_FS_LOW_ACT", 2.0), ("BATT_LOW_TIMER", 2.0)];
        let mission = "MISSION Drill:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d Hover WITH 120s\n    ON EXCEPTION BatteryCritical BY d:\n        SIGNAL Caught\n";
        let (dir, sitl, mut run) = one("sitl_battery", &params, "", mission);
        airborne(&dir);
        sitl.gcs(Duration::from_secs(10)).set_param("SIM_BATT_VOLTAGE", 10.0);
        let (_, out) = finish(&mut run, &dir, Duration::from_secs(200));
        let flown = events(&dir.join("t.jsonl"));
        let e = exception(&flown, "BatteryCritical")
            .unwrap_or_else(|| panic!("no BatteryCritical:\n{out}"));
        assert!(
            matches!(&e.event, Event::Exception { actor: Some(a), handled: true, .. } if a == "d")
        );
        assert!(signalled(&flown, "Caught"));
    }

    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn the_vehicles_own_fence_raises_geofence_violation() {
        // ArduCopter holds a GUIDED target outside its fence instead of flying there, so
        // the breach is made as on a real site: the drone is 80 m out when the ground
        // station turns on the vehicle's fence, a 50 m circle with RTL, which the world
        // knows nothing of. The breach is the autopilot's, not Aviary's own check.
        let params = [("FENCE_TYPE", 2.0), ("FENCE_RADIUS", 50.0), ("FENCE_ACTION", 1.0)];
        let mission = "MISSION Drill:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d FlyTo WITH Far\n        d Hover WITH 120s\n    ON EXCEPTION GeofenceViolation BY d:\n        SIGNAL Caught\n";
        let (dir, sitl, mut run) = one("sitl_fence", &params, "[places]\nFar = [0, 80]\n", mission);
        wait_until(Duration::from_secs(200), "the flight out", || {
            events(&dir.join("t.jsonl")).iter().any(|e| {
                matches!(e.event, Event::ApiDone { function: Function::FlyToPosition, .. })
            })
        });
        sitl.gcs(Duration::from_secs(10)).set_param("FENCE_ENABLE", 1.0);
        let (_, out) = finish(&mut run, &dir, Duration::from_secs(200));
        let flown = events(&dir.join("t.jsonl"));
        let e = exception(&flown, "GeofenceViolation")
            .unwrap_or_else(|| panic!("no GeofenceViolation:\n{out}"));
        assert!(
            matches!(&e.event, Event::Exception { actor: Some(a), handled: true, .. } if a == "d")
        );
        assert!(signalled(&flown, "Caught"));
    }

    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn gps_loss_raises_position_lost() {
        let mission = "MISSION Drill:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d Hover WITH 120s\n    ON EXCEPTION PositionLost BY d:\n        SIGNAL Caught\n";
        let (dir, sitl, mut run) = one("sitl_gps", &[], "", mission);
        airborne(&dir);
        sitl.gcs(Duration::from_secs(10)).set_param("SIM_GPS1_ENABLE", 0.0);
        let (_, out) = finish(&mut run, &dir, Duration::from_secs(300));
        let flown = events(&dir.join("t.jsonl"));
        let e =
            exception(&flown, "PositionLost").unwrap_or_else(|| panic!("no PositionLost:\n{out}"));
        assert!(matches!(&e.event, Event::Exception { actor: Some(a), .. } if a == "d"));
    }

    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn a_stopped_vehicle_is_lost_and_a_restarted_one_restored() {
        // Lost: later statements on the drone raise ConnectionLost, which a handler
        // catches; restarted: ConnectionRestored is heard.
        let mission = "MISSION Drill:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 10m\n        d Hover WITH 200s\n    ON EXCEPTION ConnectionLost BY d:\n        SIGNAL Offline\n        SEQUENTIAL Again:\n            d FlyTo WITH North\n        ON EXCEPTION ConnectionLost BY d:\n            SIGNAL Still_Offline\n        WAITFOR RECEIVED(Back)\n    ON ConnectionRestored BY d:\n        SIGNAL Back\n";
        let (dir, mut sitl, mut run) =
            one("sitl_link", &[], "[places]\nNorth = [0, 30]\n", mission);
        airborne(&dir);
        sitl.kill();
        let lost_at = Instant::now();
        wait_until(Duration::from_secs(20), "ConnectionLost", || {
            exception(&events(&dir.join("t.jsonl")), "ConnectionLost").is_some()
        });
        let noticed = lost_at.elapsed();
        assert!(noticed < Duration::from_secs(8), "the lost link was noticed after {noticed:?}");
        wait_until(Duration::from_secs(20), "the second ConnectionLost", || {
            signalled(&events(&dir.join("t.jsonl")), "Still_Offline")
        });
        sitl.restart();
        let (code, out) = finish(&mut run, &dir, Duration::from_secs(120));
        let flown = events(&dir.join("t.jsonl"));
        let signals = signal_names(&flown);
        for s in ["Offline", "Still_Offline", "ConnectionRestored", "Back"] {
            assert!(signals.contains(&s), "{s} in {signals:?}:\n{out}");
        }
        let lost: Vec<&Record> = flown
            .iter()
            .filter(
                |e| matches!(&e.event, Event::Exception { name, .. } if name == "ConnectionLost"),
            )
            .collect();
        assert!(
            lost.len() >= 2
                && lost.iter().all(|e| matches!(e.event, Event::Exception { handled: true, .. })),
            "both ConnectionLost handled: {lost:?}"
        );
        assert!(exception(&flown, "CommandFailed").is_none(), "no CommandFailed on a lost drone");
        assert_eq!(code, 0, "{out}");
    }

    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn a_refused_command_fails_with_the_autopilots_reason() {
        // A minimum arming voltage above the battery's: ArduCopter refuses to arm, and
        // says why.
        let mission = "MISSION Drill:\n    d TakeOff WITH 10m\n";
        let (dir, _sitl, mut run) = one("sitl_refused", &[("BATT_ARM_VOLT", 14.0)], "", mission);
        let (code, out) = finish(&mut run, &dir, Duration::from_secs(300));
        assert_eq!(code, 1, "{out}");
        let flown = events(&dir.join("t.jsonl"));
        let e = exception(&flown, "CommandFailed")
            .unwrap_or_else(|| panic!("no CommandFailed:\n{out}"));
        let reason = said(e);
        assert!(reason.to_ascii_lowercase().contains("arm"), "ArduPilot's reason in {reason}");
        assert!(
            reason.contains("PreArm") || reason.contains("Arm:"),
            "ArduPilot's own text in {reason}"
        );
    }

    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn a_vehicle_away_from_its_world_home_is_refused_before_flight() {
        let dir = scratch("sitl_home");
        // SITL stands 40 m east of where the world puts it.
        let sitl = Sitl::start(&dir, 20, 1, [40.0, 0.0], &[]);
        std::fs::write(dir.join("m.world.toml"), one_copter_world(&sitl, "")).expect("world");
        std::fs::write(dir.join("m.mission"), "MISSION M:\n    d TakeOff WITH 10m\n")
            .expect("mission");
        let mut run = start_run(&dir, "m.mission");
        let (code, out) = finish(&mut run, &dir, Duration::from_secs(120));
        assert_eq!(code, 2, "{out}");
        assert!(out.contains("40") && out.contains("home"), "says how far from home: {out}");
        assert!(
            named(&events(&dir.join("t.jsonl")), EventKind::ApiCall).next().is_none(),
            "nothing flew"
        );
    }
}

/// ArduCopter SITL's wind (`SIM_WIND_SPD`, `SIM_WIND_DIR`, no turbulence) against the
/// simulator's `[air.wind]`: one copter out 400 m and back in still air, along an 8 m/s
/// wind (a head wind out, a tail wind back), and across it. The still-air flight sets
/// the simulated twin's battery (its current from what SITL's battery lost); in each
/// wind, the simulator's flight time and battery used are within 15% of SITL's. The twin
/// has the copter's figures as SITL showed them: ArduCopter's, an airspeed of 13.6 m/s
/// (it holds 10 m/s over the ground into the wind as far as its tilt allows), and a
/// battery whose drain does not grow with airspeed (SITL's drew 0.248 %/s into the wind
/// and 0.247 %/s with it: `drain = 0`).
mod wind {
    use super::*;

    const OUT_AND_BACK: &str = "CAPABILITY Out_And_Back BY drone:\n    PERFORM:\n        drone.FollowPath((0, 400), (0, 0))\n\nMISSION Windy:\n    SEQUENTIAL Fly:\n        d TakeOff WITH 20m\n        d Out_And_Back\n        d Land\n";

    /// SITL's default battery, which the backend reads (BATT_CAPACITY).
    const CAPACITY_MAH: f64 = 3300.0;

    /// A flight: its time in the air (s) and the share of the battery it used.
    #[derive(Debug, Clone, Copy)]
    struct Flight {
        time: f64,
        used: f64,
    }

    fn flight(dir: &Path, out: &str) -> Flight {
        let flown = events(&dir.join("t.jsonl"));
        let charge: Vec<f64> = flown
            .iter()
            .filter_map(|e| match &e.event {
                Event::Telemetry { actor, battery, .. } if actor == "d" => Some(*battery),
                _ => None,
            })
            .filter(|b| b.is_finite())
            .collect();
        let row = common::summary_rows(out).into_iter().find(|r| r.0 == "d").expect("d's row");
        Flight { time: row.2, used: charge[0] - charge[charge.len() - 1] }
    }

    /// The route flown on SITL in a wind of `speed` m/s from `from` degrees.
    fn on_sitl(tag: &str, speed: f64, from: f64) -> Flight {
        let params = [("SIM_WIND_SPD", speed), ("SIM_WIND_DIR", from), ("SIM_WIND_TURB", 0.0)];
        let (dir, _sitl, mut run) = super::single_copter(tag, &params, "", OUT_AND_BACK);
        let (code, out) = finish(&mut run, &dir, Duration::from_secs(600));
        assert_eq!(code, 0, "{out}");
        flight(&dir, &out)
    }

    /// The same route in the simulator, the copter with ArduCopter's figures, the
    /// battery `current` (A) draws from `CAPACITY_MAH`, and `[air.wind]`.
    fn simulated(tag: &str, current: f64, speed: f64, from: f64) -> Flight {
        let dir = scratch(tag);
        let air = if speed > 0.0 {
            format!("[air.wind]\nspeed = {speed}\nfrom = {from}\ndrain = 0\n")
        } else {
            String::new()
        };
        let world = format!(
            "[site]\nname = \"SITL twin\"\nmax_altitude = 60\n{air}\n[drones.d]\nhome = [0, 0]\n{}max_airspeed = 13.6\nbattery_capacity = {CAPACITY_MAH}\nflight_current = {current}\n",
            common::ARDUCOPTER
        );
        std::fs::write(dir.join("m.world.toml"), world).expect("world");
        std::fs::write(dir.join("m.mission"), OUT_AND_BACK).expect("mission");
        let (code, out, err) =
            aviary(&["run", "m.mission", "--trace", "t.jsonl", "--telemetry-hz", "2"], &dir);
        assert_eq!(code, 0, "{out}{err}");
        flight(&dir, &out)
    }

    #[test]
    #[cfg_attr(
        not(arducopter_sitl),
        ignore = "ArduCopter SITL not named: set AVIARY_SITL=/path/to/arducopter to fly it (docs/REAL_DRONES.md)"
    )]
    fn the_simulators_wind_agrees_with_sitls_within_15_percent() {
        let still = on_sitl("sitl_wind_still", 0.0, 0.0);
        // The current that empties the battery as SITL's did in still air.
        let current = still.used * CAPACITY_MAH / 1000.0 / (still.time / 3600.0);
        let twin = simulated("sim_wind_still", current, 0.0, 0.0);
        eprintln!("still air: SITL {still:?}, simulator {twin:?} at {current:.1} A");
        let mut apart = Vec::new();
        for (what, from) in [("along", 0.0), ("across", 90.0)] {
            let real = on_sitl(&format!("sitl_wind_{what}"), 8.0, from);
            let sim = simulated(&format!("sim_wind_{what}"), current, 8.0, from);
            eprintln!("8 m/s {what}: SITL {real:?}, simulator {sim:?}");
            for (figure, r, s) in [("time", real.time, sim.time), ("battery", real.used, sim.used)]
            {
                if (r - s).abs() > 0.15 * r {
                    apart.push(format!("{what}: {figure} {r:.3} on SITL, {s:.3} simulated"));
                }
            }
        }
        assert!(apart.is_empty(), "more than 15% apart:\n{}", apart.join("\n"));
    }
}
