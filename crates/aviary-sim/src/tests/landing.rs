//! A drone with an autopilot's figures: it descends slower than it climbs, lands slowly
//! in its last metres, returns home at its own altitude and waits above home first
//! (ArduCopter's defaults: WPNAV_SPEED_UP 2.5 m/s, WPNAV_SPEED_DN 1.5 m/s, LAND_SPEED
//! 0.5 m/s under LAND_ALT_LOW 10 m, RTL_ALT 15 m, RTL_LOIT_TIME 5 s, WPNAV_ACCEL 2.5).

use aviary_api::{CallEnd, FlightState};

use super::*;

fn arducopter() -> World {
    world(
        "[drones.d]\nhome = [0, 0]\nclimb_rate = 2.5\ndescent_rate = 1.5\nacceleration = 2.5\nland_speed = 0.5\nland_speed_below = 10\nreturn_altitude = 15\nreturn_loiter = 5\n",
    )
}

/// The time of a vertical move of `d` metres from rest to rest at up to `v`, accelerating
/// and braking at `a`.
fn trapezoid(d: f64, v: f64, a: f64) -> f64 {
    if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

#[test]
fn a_landing_descends_at_its_rate_and_touches_down_at_the_landing_speed() {
    let w = arducopter();
    let mut fleet = airborne(&w, 25.0);
    let id = start(&mut fleet, 0, Function::Land, &[]);
    let run = run_until(&mut fleet, 0, id, 120.0);
    assert_eq!(run.end, CallEnd::Done);
    let expected = trapezoid(15.0, 1.5, 2.5) + trapezoid(10.0, 0.5, 2.5);
    assert!((run.took - expected).abs() < 0.2, "took {} s, expected {expected} s", run.took);
    for pair in run.samples.windows(2) {
        let down = (pair[0].position[2] - pair[1].position[2]) / DT;
        let limit = if pair[0].position[2] <= 10.0 + 1e-9 { 0.5 } else { 1.5 };
        assert!(down <= limit + 1e-9, "{down} m/s down at {} m", pair[0].position[2]);
    }
    let end = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!((end.position[2], end.state), (0.0, FlightState::Landed));
}

#[test]
fn a_low_landing_is_slow_all_the_way() {
    let w = arducopter();
    let mut fleet = airborne(&w, 4.0);
    let id = start(&mut fleet, 0, Function::Land, &[]);
    let run = run_until(&mut fleet, 0, id, 60.0);
    let expected = trapezoid(4.0, 0.5, 2.5);
    assert!((run.took - expected).abs() < 0.2, "took {} s, expected {expected} s", run.took);
}

#[test]
fn a_return_climbs_to_the_return_altitude_waits_above_home_and_lands() {
    let w = arducopter();
    let mut fleet = airborne(&w, 5.0);
    let out = start(&mut fleet, 0, Function::FlyToPosition, &[pos(100.0, 0.0)]);
    run_until(&mut fleet, 0, out, 120.0);
    let id = start(&mut fleet, 0, Function::ReturnToLaunch, &[]);
    let run = run_until(&mut fleet, 0, id, 200.0);
    assert_eq!(run.end, CallEnd::Done);
    let highest = run.samples.iter().map(|s| s.position[2]).fold(0.0, f64::max);
    assert!((highest - 15.0).abs() < 1e-6, "flew home at {highest} m");
    // Above home at 15 m, still, for the wait.
    let waiting = run
        .samples
        .iter()
        .filter(|s| {
            s.position[0].abs() < 1e-6 && (s.position[2] - 15.0).abs() < 1e-9 && s.speed == 0.0
        })
        .count() as f64
        * DT;
    assert!((waiting - 5.0).abs() <= 2.0 * DT, "waited {waiting} s above home");
    let expected = trapezoid(10.0, 2.5, 2.5)
        + trapezoid(100.0, 10.0, 2.5)
        + 5.0
        + trapezoid(5.0, 1.5, 2.5)
        + trapezoid(10.0, 0.5, 2.5);
    assert!((run.took - expected).abs() < 0.5, "took {} s, expected {expected} s", run.took);
}

/// PX4's figures: it takes off at MPC_TKO_SPEED (half its climb rate) and returns at
/// MPC_XY_CRUISE, slower than the mission flies.
fn px4() -> World {
    world(
        "[drones.d]\nhome = [0, 0]\nmax_speed = 10\nclimb_rate = 3\ntakeoff_speed = 1.5\ndescent_rate = 1.5\nacceleration = 3\nland_speed = 0.7\nland_speed_below = 10\nreturn_altitude = 30\nreturn_speed = 5\n",
    )
}

#[test]
fn a_take_off_climbs_at_the_take_off_speed_and_later_climbs_at_the_climb_rate() {
    let w = px4();
    let mut fleet = Fleet::new(&w);
    assert_eq!(instant(&mut fleet, 0, Function::Arm, &[]), CallEnd::Done);
    let up = start(&mut fleet, 0, Function::TakeOff, &[num(12.0)]);
    let run = run_until(&mut fleet, 0, up, 60.0);
    assert_eq!(run.end, CallEnd::Done);
    let expected = trapezoid(12.0, 1.5, 3.0);
    assert!((run.took - expected).abs() < 0.2, "took {} s, expected {expected} s", run.took);
    // In the air, a higher take-off is a climb like any other.
    let higher = start(&mut fleet, 0, Function::TakeOff, &[num(24.0)]);
    let run = run_until(&mut fleet, 0, higher, 60.0);
    let expected = trapezoid(12.0, 3.0, 3.0);
    assert!((run.took - expected).abs() < 0.2, "took {} s, expected {expected} s", run.took);
}

#[test]
fn a_return_flies_home_at_the_return_speed() {
    let w = px4();
    let mut fleet = airborne(&w, 30.0);
    let out = start(&mut fleet, 0, Function::FlyToPosition, &[pos(200.0, 0.0)]);
    run_until(&mut fleet, 0, out, 120.0);
    let id = start(&mut fleet, 0, Function::ReturnToLaunch, &[]);
    let run = run_until(&mut fleet, 0, id, 300.0);
    assert_eq!(run.end, CallEnd::Done);
    let fastest = run.samples.iter().map(|s| s.speed).fold(0.0, f64::max);
    assert!((fastest - 5.0).abs() < 1e-6, "flew home at up to {fastest} m/s");
    let expected =
        trapezoid(200.0, 5.0, 3.0) + trapezoid(20.0, 1.5, 3.0) + trapezoid(10.0, 0.7, 3.0);
    assert!((run.took - expected).abs() < 0.5, "took {} s, expected {expected} s", run.took);
}
