//! Motion, battery and sensors of the physics core.

use aviary_api::{CallEnd, DroneEvent, FlightState, Interrupt, Value};

use super::*;
use crate::geom::{dist, dist_to_polyline};
use crate::sweep::lawnmower;

#[test]
fn takeoff_climb_time_matches_the_trapezoid() {
    let w = one_drone();
    let mut fleet = Fleet::new(&w);
    instant(&mut fleet, 0, Function::Arm, &[]);
    let id = start(&mut fleet, 0, Function::TakeOff, &[num(20.0)]);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().state, FlightState::TakingOff);
    let run = run_until(&mut fleet, 0, id, 60.0);
    // climb_rate 3 m/s, acceleration 3 m/s²: 1 s up to speed and 1 s to stop (3 m), 17 m at 3 m/s.
    let analytic = 2.0 + 17.0 / 3.0;
    assert!(
        (run.took - analytic).abs() <= 0.05 * analytic,
        "took {} s, trapezoid {analytic} s",
        run.took
    );
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert!((t.position[2] - 20.0).abs() <= 0.1);
    assert_eq!(t.state, FlightState::Flying);
    for w in run.samples.windows(2) {
        let climb = (w[1].position[2] - w[0].position[2]) / DT;
        assert!(climb <= 3.0 + 1e-9, "climbed at {climb} m/s");
    }
}

#[test]
fn a_long_flight_keeps_speed_and_acceleration_bounds() {
    let w = one_drone();
    let mut fleet = airborne(&w, 20.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(300.0, 400.0)]);
    let run = run_until(&mut fleet, 0, id, 200.0);
    // 500 m at 10 m/s, plus the time lost speeding up and braking at 3 m/s² (10/3 s).
    let expected = 500.0 / 10.0 + 10.0 / 3.0;
    assert!(
        (run.took - expected).abs() <= 0.01 * expected,
        "took {} s, expected {expected} s",
        run.took
    );
    let end = fleet.telemetry(DroneId(0)).unwrap();
    assert!(dist([end.position[0], end.position[1]], [300.0, 400.0]) <= 0.5);
    assert_eq!(end.position[2], 20.0);
    assert_eq!(end.speed, 0.0);
    assert!((end.heading - 36.869_897_645_844_02).abs() < 1e-6, "heading {}", end.heading);
    let mut fastest: f64 = 0.0;
    for w in run.samples.windows(2) {
        assert!(w[1].speed <= 10.0 + 1e-9, "speed {}", w[1].speed);
        assert!(
            (w[1].speed - w[0].speed).abs() <= 3.0 * DT + 1e-9,
            "acceleration {}",
            (w[1].speed - w[0].speed) / DT
        );
        fastest = fastest.max(w[1].speed);
    }
    assert!(fastest > 9.99);
    let (metres, seconds) = fleet.odometry(DroneId(0));
    assert!((metres - 520.0).abs() < 1e-6, "{metres}");
    assert!((seconds - fleet.time()).abs() < 1e-9, "in the air since the take-off call");
    assert_eq!(fleet.odometry(DroneId(7)), (0.0, 0.0));
    // A slower speed asked is kept.
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(300.0, 300.0), num(4.0)]);
    let run = run_until(&mut fleet, 0, id, 200.0);
    assert!(run.samples.iter().all(|t| t.speed <= 4.0 + 1e-9));
    assert!((run.took - (100.0 / 4.0 + 4.0 / 3.0)).abs() < 0.3);
}

#[test]
fn battery_drains_exactly_while_airborne_only() {
    let w = world("[drones.d]\nhome = [0, 0]\nbattery = 80\nendurance = 600\n");
    let mut fleet = Fleet::new(&w);
    run_for(&mut fleet, 10.0);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().battery, 0.8, "no drain on the ground");
    instant(&mut fleet, 0, Function::Arm, &[]);
    start(&mut fleet, 0, Function::TakeOff, &[num(30.0)]);
    let steps = 2400; // 120 s
    for _ in 0..steps {
        fleet.step(DT);
    }
    let flown = steps as f64 * DT;
    let battery = fleet.telemetry(DroneId(0)).unwrap().battery;
    assert!((battery - (0.8 - flown / 600.0)).abs() < 1e-9, "{battery}");
}

#[test]
fn battery_low_comes_before_critical_each_once_then_the_drone_is_lost() {
    let w = world("[drones.d]\nhome = [0, 0]\nendurance = 150\n");
    let mut fleet = airborne(&w, 20.0);
    // Low at about 40 s of flight, critical at about 64 s: before the 93 s it takes.
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(900.0, 0.0)]);
    let mut seen = Vec::new();
    let mut ended = None;
    for _ in 0..(400.0 / DT) as usize {
        for r in fleet.step(DT) {
            match r {
                Report::Event(DroneEvent::Signal { signal, .. }) => {
                    seen.push(signal.name().to_owned())
                }
                Report::Event(DroneEvent::Fault { failure, .. }) => {
                    seen.push(failure.exception.name().to_owned())
                }
                Report::Ended { call, end } if call == id => ended = Some((end, fleet.time())),
                _ => {}
            }
        }
    }
    assert_eq!(seen, ["BatteryLow", "BatteryCritical", "DroneLost"]);
    // The flight was cut by BatteryCritical: the drone held there and then fell.
    assert_eq!(ended.map(|e| e.0), Some(CallEnd::Interrupted));
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!((t.state, t.battery, t.position[2]), (FlightState::Lost, 0.0, 0.0));
    assert!(t.position[0] > 500.0 && t.position[0] < 700.0, "{t:?}");
    assert_eq!(refused(&mut fleet, 0, Function::Land, &[]).0, BuiltinException::CommandFailed);
}

#[test]
fn detection_fires_once_per_target_per_activation_and_only_in_range() {
    let w = one_drone();
    let mut fleet = airborne(&w, 20.0);
    assert_eq!(instant(&mut fleet, 0, Function::StartDetection, &[sym("Body")]), CallEnd::Done);
    // Passes (100, 10) at 10 m, and (100, 50) at 50 m (out of the 20 m range).
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(200.0, 0.0)]);
    let run = run_until(&mut fleet, 0, id, 100.0);
    let found = |events: &[DroneEvent]| -> Vec<[f64; 3]> {
        events
            .iter()
            .filter_map(|e| match e {
                DroneEvent::Detected { drone: DroneId(0), kind, location } if kind == "Body" => {
                    Some(*location)
                }
                _ => None,
            })
            .collect()
    };
    assert_eq!(found(&run.events), [[100.0, 10.0, 0.0]]);
    // Flying back past it in the same activation finds nothing new.
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(50.0, 0.0)]);
    assert!(found(&run_until(&mut fleet, 0, id, 100.0).events).is_empty());
    // A new activation finds it again.
    instant(&mut fleet, 0, Function::StartDetection, &[Value::Text("Body".into())]);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(150.0, 0.0)]);
    assert_eq!(found(&run_until(&mut fleet, 0, id, 100.0).events), [[100.0, 10.0, 0.0]]);
    // Stopped: nothing.
    instant(&mut fleet, 0, Function::StopDetection, &[sym("Body")]);
    assert!(fleet.detecting(DroneId(0)).is_empty());
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(50.0, 0.0)]);
    assert!(found(&run_until(&mut fleet, 0, id, 100.0).events).is_empty());
}

#[test]
fn orbit_keeps_its_radius_and_speed() {
    let w = one_drone();
    let mut fleet = airborne(&w, 20.0);
    let id = start(&mut fleet, 0, Function::Orbit, &[pos(100.0, 0.0), num(30.0), num(2.0)]);
    let run = run_until(&mut fleet, 0, id, 300.0);
    // The approach ends at (70, 0), the nearest point of the circle.
    let on_circle: Vec<_> = run
        .samples
        .iter()
        .skip_while(|t| dist([t.position[0], t.position[1]], [70.0, 0.0]) > 1e-9)
        .collect();
    assert!(on_circle.len() > 100);
    for t in &on_circle {
        let r = dist([t.position[0], t.position[1]], [100.0, 0.0]);
        assert!((r - 30.0).abs() <= 1.0, "radius {r}");
        assert_eq!(t.position[2], 20.0);
        assert!(t.speed <= (3.0f64 * 30.0 / 2.0).sqrt() + 1e-9);
    }
    // Two laps of 2π·30 m at ≈ 6.7 m/s, at least.
    let laps_time = on_circle.len() as f64 * DT;
    assert!(laps_time >= 2.0 * std::f64::consts::TAU * 30.0 / 45f64.sqrt());
    let end = fleet.telemetry(DroneId(0)).unwrap();
    assert!(dist([end.position[0], end.position[1]], [70.0, 0.0]) < 1e-6, "ends where it began");
}

#[test]
fn sweep_flies_the_lawnmower_path_and_covers_the_area() {
    let w = one_drone();
    let mut fleet = airborne(&w, 15.0);
    let l = crate::geom::L_SHAPE.to_vec();
    let id = start(&mut fleet, 0, Function::Sweep, &[Value::Area(l.clone()), num(20.0)]);
    let run = run_until(&mut fleet, 0, id, 1000.0);
    let flown: Vec<[f64; 2]> = run.samples.iter().map(|t| [t.position[0], t.position[1]]).collect();
    let path = lawnmower(&l, 20.0);
    for p in &path {
        assert!(dist_to_polyline(*p, &flown) < 1e-6, "the drone passed {p:?}");
    }
    assert_eq!(flown.last(), path.last());
    assert!(run.samples.iter().all(|t| t.position[2] == 15.0 && t.speed <= 10.0 + 1e-9));
    for x in 0..=100 {
        for y in 0..=100 {
            let p = [x as f64, y as f64];
            if crate::geom::contains(&l, p) {
                assert!(dist_to_polyline(p, &flown) <= 10.0 + 0.05, "{p:?} is far from the sweep");
            }
        }
    }
}

#[test]
fn pause_holds_the_drone_and_resume_completes_the_move() {
    let w = one_drone();
    let mut fleet = airborne(&w, 20.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(200.0, 0.0)]);
    run_for(&mut fleet, 5.0);
    assert_eq!(fleet.interrupt(id, Interrupt::Pause), None);
    let held = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!(held.speed, 0.0);
    for r in run_for(&mut fleet, 10.0) {
        assert!(!matches!(r, Report::Ended { call, .. } if call == id), "a paused call goes on");
        assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, held.position);
    }
    let after = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!(after.position, held.position);
    assert!(after.battery < held.battery, "hovering still drains");
    fleet.interrupt(id, Interrupt::Resume);
    let run = run_until(&mut fleet, 0, id, 100.0);
    assert_eq!(run.end, CallEnd::Done);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [200.0, 0.0, 20.0]);
}

/// A motion call while another is paused (a leash section while its activity's body is
/// held) sets the paused one aside; when the newer one ends, the paused one is back, still
/// paused, and once resumed it flies back to where it was held and goes on from there.
#[test]
fn a_paused_motion_call_gives_way_to_a_newer_one_and_comes_back_after_it() {
    let w = one_drone();
    let mut fleet = airborne(&w, 20.0);
    let orbit = start(&mut fleet, 0, Function::Orbit, &[pos(0.0, 100.0), num(50.0), num(1.0)]);
    run_for(&mut fleet, 20.0);
    fleet.interrupt(orbit, Interrupt::Pause);
    let held = fleet.telemetry(DroneId(0)).unwrap().position;
    let section = start(&mut fleet, 0, Function::FlyToPosition, &[pos(0.0, 0.0)]);
    let run = run_until(&mut fleet, 0, section, 100.0);
    assert_eq!(run.end, CallEnd::Done, "not refused as busy");
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [0.0, 0.0, 20.0]);
    for r in run_for(&mut fleet, 5.0) {
        assert!(!matches!(r, Report::Ended { call, .. } if call == orbit), "still paused");
    }
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [0.0, 0.0, 20.0], "held: not flying");
    fleet.interrupt(orbit, Interrupt::Resume);
    let run = run_until(&mut fleet, 0, orbit, 300.0);
    assert_eq!(run.end, CallEnd::Done);
    let back = run.samples.iter().position(|t| {
        let p = t.position;
        (p[0] - held[0]).hypot(p[1] - held[1]) < 1e-6
    });
    let back = back.expect("it flies back to where it was held");
    // From there along the circle, the rest of its lap only: it ends where the lap began.
    let on_circle = |p: [f64; 3]| (p[0].hypot(p[1] - 100.0) - 50.0).abs() < 1e-6;
    assert!(run.samples[back..].iter().all(|t| on_circle(t.position)));
    let end = fleet.telemetry(DroneId(0)).unwrap().position;
    assert!(end[0].abs() < 1e-6 && (end[1] - 50.0).abs() < 1e-6, "{end:?}");
}

/// A newer call that is refused leaves the paused one where it was; an abort of a call set
/// aside ends it, and a fault ends every call, those set aside too.
#[test]
fn a_call_set_aside_is_kept_on_a_refusal_and_ended_by_an_abort_or_a_fault() {
    let w = one_drone();
    let mut fleet = airborne(&w, 20.0);
    let first = start(&mut fleet, 0, Function::FlyToPosition, &[pos(200.0, 0.0)]);
    run_for(&mut fleet, 3.0);
    fleet.interrupt(first, Interrupt::Pause);
    let (_, refused) = fleet.call(DroneId(0), &fc(Function::FlyToPosition, &[pos(5000.0, 0.0)]));
    assert!(matches!(refused, Some(CallEnd::Failed(_))), "outside the geofence: {refused:?}");
    let (busy, end) = fleet.call(DroneId(0), &fc(Function::Hover, &[num(60.0)]));
    assert_eq!(end, None, "the paused call was back, and gives way again");
    assert_eq!(fleet.interrupt(first, Interrupt::Abort), Some(CallEnd::Interrupted));
    fleet.interrupt(busy, Interrupt::Pause);
    let (last, _) = fleet.call(DroneId(0), &fc(Function::Hover, &[num(60.0)]));
    let mut reports = Vec::new();
    fleet.fault(
        DroneId(0),
        aviary_api::BuiltinException::MotorFailure,
        "test".into(),
        &mut reports,
    );
    let ended: Vec<CallId> = reports
        .iter()
        .filter_map(|r| match r {
            Report::Ended { call, end: CallEnd::Interrupted } => Some(*call),
            _ => None,
        })
        .collect();
    assert_eq!(ended, vec![last, busy]);
}

#[test]
fn abort_ends_the_call_interrupted_and_the_drone_hovers() {
    let w = one_drone();
    let mut fleet = airborne(&w, 20.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(200.0, 0.0)]);
    run_for(&mut fleet, 5.0);
    assert_eq!(fleet.interrupt(id, Interrupt::Abort), Some(CallEnd::Interrupted));
    assert_eq!(fleet.interrupt(id, Interrupt::Abort), None, "once");
    let here = fleet.telemetry(DroneId(0)).unwrap();
    run_for(&mut fleet, 5.0);
    let later = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!(
        (later.position, later.speed, later.state),
        (here.position, 0.0, FlightState::Flying)
    );
    // The drone takes a new move at once.
    let id = start(&mut fleet, 0, Function::Land, &[]);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().state, FlightState::Landing);
    assert_eq!(run_until(&mut fleet, 0, id, 100.0).end, CallEnd::Done);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().state, FlightState::Landed);
}

/// A scripted mission on two drones: every telemetry sample and report.
fn script() -> (Vec<Telemetry>, Vec<Report>) {
    let w = world(
        r#"
[drones.a]
home = [0, 0]
sensors = ["thermal"]
[drones.b]
home = [5, 5]
max_speed = 7.5
[sensors.thermal]
detects = ["Body"]
range = 15.0
[[targets]]
kind = "Body"
at = [120, 60]
"#,
    );
    let mut fleet = Fleet::new(&w);
    let mut log = Vec::new();
    let mut reports = Vec::new();
    for d in 0..2 {
        fleet.call(DroneId(d), &fc(Function::Arm, &[]));
        fleet.call(DroneId(d), &fc(Function::TakeOff, &[num(12.5 + d as f64)]));
    }
    for i in 0..6000 {
        match i {
            300 => {
                fleet.call(DroneId(0), &fc(Function::StartDetection, &[sym("Body")]));
                fleet.call(
                    DroneId(0),
                    &fc(
                        Function::Sweep,
                        &[
                            Value::Area(vec![
                                [50.0, 20.0],
                                [200.0, 20.0],
                                [200.0, 90.0],
                                [50.0, 90.0],
                            ]),
                            num(15.0),
                        ],
                    ),
                );
                fleet.call(
                    DroneId(1),
                    &fc(Function::Orbit, &[pos(-40.0, 30.0), num(25.0), num(1.5)]),
                );
            }
            4000 => {
                fleet.call(DroneId(1), &fc(Function::ReturnToLaunch, &[]));
            }
            _ => {}
        }
        reports.extend(fleet.step(DT));
        log.extend((0..2).map(|d| fleet.telemetry(DroneId(d)).unwrap()));
    }
    (log, reports)
}

#[test]
fn the_same_calls_give_the_same_run_bit_for_bit() {
    let (a, ra) = script();
    let (b, rb) = script();
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x, y);
        for k in 0..3 {
            assert_eq!(x.position[k].to_bits(), y.position[k].to_bits());
        }
        assert_eq!(x.battery.to_bits(), y.battery.to_bits());
    }
    assert_eq!(ra, rb);
    assert!(ra.iter().any(|r| matches!(r, Report::Event(DroneEvent::Detected { .. }))));
}
