//! Link loss (hold, return to launch on its own, `ConnectionRestored`) and the battery
//! reserve.

use aviary_api::{CallEnd, DroneEvent, FlightState};
use aviary_world::World;

use super::*;

/// Drone `d` at the origin; `site` adds keys to `[site]`, `faults` the `[[faults]]`.
fn linked(site: &str, faults: &str) -> World {
    world(&format!("{site}\n[drones.d]\nhome = [0, 0]\n\n{faults}"))
}

fn link_loss(at: f64, duration: f64) -> String {
    format!("[[faults]]\ndrone = \"d\"\nat = {at}\nkind = \"link_loss\"\nduration = {duration}\n")
}

/// Steps until the fleet's time reaches `t` (to within half a step); returns the reports.
fn run_to(fleet: &mut Fleet, t: f64) -> Vec<Report> {
    let mut out = Vec::new();
    while fleet.time() < t - DT / 2.0 {
        out.extend(fleet.step(DT));
    }
    out
}

fn names(reports: &[Report]) -> Vec<&'static str> {
    reports
        .iter()
        .filter_map(|r| match r {
            Report::Event(DroneEvent::Signal { signal, .. }) => Some(signal.name()),
            Report::Event(DroneEvent::Fault { failure, .. }) => Some(failure.exception.name()),
            _ => None,
        })
        .collect()
}

/// Whether `name` comes in the step that ends at `t` (and not before, from now).
fn comes_at(fleet: &mut Fleet, name: &str, t: f64) -> bool {
    while fleet.time() < t + DT / 2.0 {
        if names(&fleet.step(DT)).contains(&name) {
            return (fleet.time() - t).abs() < 1e-6;
        }
    }
    false
}

/// Takes off, flies east, and is cut off at 20 s: returns the fleet at that moment.
fn cut_off(w: &World) -> Fleet {
    let mut fleet = airborne(w, 20.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(400.0, 0.0)]);
    let reports = run_to(&mut fleet, 20.0);
    assert_eq!(names(&reports), ["ConnectionLost"]);
    assert!(reports.contains(&Report::Ended { call: id, end: CallEnd::Interrupted }));
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert!(!t.link && t.position[0] > 50.0, "{t:?}");
    fleet
}

#[test]
fn link_loss_holds_then_returns_to_launch_after_the_timeout() {
    let w = linked("link_loss_rtl_after = 8", &link_loss(20.0, 60.0));
    assert_eq!(w.site.link_loss_rtl_after, 8.0);
    let mut fleet = cut_off(&w);
    let held = fleet.telemetry(DroneId(0)).unwrap().position;
    // Holds for 8 s, taking no commands.
    while fleet.time() + DT < 28.0 - DT / 2.0 {
        assert!(names(&fleet.step(DT)).is_empty());
        let t = fleet.telemetry(DroneId(0)).unwrap();
        assert_eq!((t.position, t.speed), (held, 0.0));
        let (_, reason) = refused(&mut fleet, 0, Function::FlyToPosition, &[pos(0.0, 0.0)]);
        assert!(reason.contains("no link"), "{reason}");
    }
    // Then flies home on its own and lands, still without a link.
    run_to(&mut fleet, 28.5);
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert!(t.position[0] < held[0] && t.speed > 0.0, "{t:?}");
    let reports = run_to(&mut fleet, 79.9);
    assert!(names(&reports).is_empty());
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!((t.position, t.state, t.link), ([0.0, 0.0, 0.0], FlightState::Landed, false));
    // The link comes back when the fault's duration ends.
    assert!(comes_at(&mut fleet, "ConnectionRestored", 80.0));
    assert!(fleet.telemetry(DroneId(0)).unwrap().link);
    assert_eq!(instant(&mut fleet, 0, Function::Arm, &[]), CallEnd::Done);
}

#[test]
fn a_short_loss_only_holds_and_the_default_timeout_is_ten_seconds() {
    let faults = link_loss(20.0, 9.5) + &link_loss(40.0, 30.0);
    let w = linked("", &faults);
    assert_eq!(w.site.link_loss_rtl_after, 10.0);
    let mut fleet = cut_off(&w);
    let held = fleet.telemetry(DroneId(0)).unwrap().position;
    assert!(comes_at(&mut fleet, "ConnectionRestored", 29.5));
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!((t.position, t.speed, t.link), (held, 0.0, true));
    // Commands again: fly on, until the second loss at 40 s.
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(400.0, 0.0)]);
    let reports = run_to(&mut fleet, 40.0);
    assert_eq!(names(&reports), ["ConnectionLost"]);
    assert!(reports.contains(&Report::Ended { call: id, end: CallEnd::Interrupted }));
    let held = fleet.telemetry(DroneId(0)).unwrap().position;
    run_to(&mut fleet, 50.0 - DT);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, held, "holds 10 s");
    fleet.step(DT);
    run_to(&mut fleet, 50.5);
    assert!(fleet.telemetry(DroneId(0)).unwrap().position[0] < held[0], "returns after 10 s");
}

#[test]
fn a_return_started_on_its_own_goes_on_after_the_link_is_back_until_commanded() {
    let w = linked("link_loss_rtl_after = 2", &link_loss(20.0, 5.0));
    let mut fleet = cut_off(&w);
    assert!(comes_at(&mut fleet, "ConnectionRestored", 25.0));
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert!(t.speed > 0.0 && t.link, "still returning: {t:?}");
    // Left alone, it lands at home.
    let mut alone = fleet.clone();
    run_to(&mut alone, 80.0);
    let t = alone.telemetry(DroneId(0)).unwrap();
    assert_eq!((t.position, t.state), ([0.0, 0.0, 0.0], FlightState::Landed));
    // A command replaces the return (the drone stops where it is, then obeys).
    let id = start(&mut fleet, 0, Function::Hover, &[num(3.0)]);
    let here = fleet.telemetry(DroneId(0)).unwrap().position;
    let run = run_until(&mut fleet, 0, id, 10.0);
    assert_eq!(run.end, CallEnd::Done);
    assert!(run.samples.iter().all(|t| t.position == here));
    run_to(&mut fleet, 80.0);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, here, "the return is over");
}

#[test]
fn a_crash_during_a_link_loss_ends_the_drone() {
    let crash = "[[faults]]\ndrone = \"d\"\nat = 25.0\nkind = \"crash\"\n";
    let w = linked("", &(link_loss(20.0, 30.0) + crash));
    let mut fleet = cut_off(&w);
    let reports = run_to(&mut fleet, 70.0);
    assert_eq!(names(&reports), ["DroneLost"], "no return, no ConnectionRestored");
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!((t.state, t.position[2]), (FlightState::Lost, 0.0));
}

#[test]
fn battery_critical_two_km_out_leaves_enough_to_get_home() {
    let text = "[site]\ngeofence = [[-3000, -3000], [3000, -3000], [3000, 3000], [-3000, 3000]]\n\
        max_altitude = 120.0\n[drones.d]\nhome = [0, 0]\nendurance = 600\n";
    let (w, diags) = aviary_world::parse_world(aviary_diagnostics::FileId(0), text);
    assert!(diags.is_empty(), "{diags:#?}");
    let mut fleet = airborne(&w.unwrap(), 20.0);
    let id = start(&mut fleet, 0, Function::FlyToPosition, &[pos(2000.0, 0.0)]);
    let out = run_until(&mut fleet, 0, id, 300.0);
    assert_eq!(out.end, CallEnd::Done);
    // Waits out there until the battery says it is time to go home.
    let id = start(&mut fleet, 0, Function::Hover, &[num(1000.0)]);
    let wait = run_until(&mut fleet, 0, id, 1000.0);
    assert_eq!(wait.end, CallEnd::Interrupted);
    let mut seen: Vec<&str> = Vec::new();
    for e in out.events.iter().chain(&wait.events) {
        match e {
            DroneEvent::Signal { signal, .. } => seen.push(signal.name()),
            DroneEvent::Fault { failure, .. } => seen.push(failure.exception.name()),
            _ => {}
        }
    }
    assert_eq!(seen, ["BatteryLow", "BatteryCritical"]);
    let critical = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!(critical.position, [2000.0, 0.0, 20.0]);
    let id = start(&mut fleet, 0, Function::ReturnToLaunch, &[]);
    let home = run_until(&mut fleet, 0, id, 400.0);
    assert_eq!(home.end, CallEnd::Done);
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert_eq!((t.position, t.state), ([0.0, 0.0, 0.0], FlightState::Landed));
    assert!(t.battery > 0.05, "landed with {:.3} left", t.battery);
    // Raised at "energy to get home + 10 %", and the way home took about that energy.
    let need = (2000.0 / 10.0 + 20.0 / 3.0) / 600.0;
    assert!((critical.battery - (need + 0.10)).abs() < 0.01, "{critical:?}");
    assert!((home.took / 600.0 - need).abs() < 0.02, "took {} s", home.took);
}
