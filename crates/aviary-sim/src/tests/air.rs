//! `[air]`: each model against its formula, statistics over a fixed set of seeds, and the
//! seed's determinism. A world without `[air]` has no air state at all.

use aviary_api::{BuiltinSignal, FlightState};

use super::*;

/// Drone `d` at the origin (and `more`), in the test site, off the ground at `alt`.
fn up(text: &str, seed: u64, alt: f64) -> Fleet {
    let w = world(text);
    let mut fleet = Fleet::new(&w).seeded(seed);
    for id in 0..fleet.len() {
        assert_eq!(instant(&mut fleet, id, Function::Arm, &[]), CallEnd::Done);
        let up = start(&mut fleet, id, Function::TakeOff, &[num(alt)]);
        assert_eq!(run_until(&mut fleet, id, up, 120.0).end, CallEnd::Done);
    }
    fleet
}

/// The trapezoid's time for `dist` metres at up to `v` with acceleration `a`.
fn trapezoid(dist: f64, v: f64, a: f64) -> f64 {
    let ramp = v * v / a;
    if dist >= ramp {
        2.0 * v / a + (dist - ramp) / v
    } else {
        2.0 * (dist / a).sqrt()
    }
}

/// Seconds to fly 900 m east at 20 m in the wind of `air`.
fn leg_east(air: &str) -> f64 {
    let mut fleet = up(&format!("[drones.d]\nhome = [0, 0]\n{air}"), 0, 20.0);
    let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(900.0, 0.0)]);
    let run = run_until(&mut fleet, 0, go, 600.0);
    assert_eq!(run.end, CallEnd::Done);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [900.0, 0.0, 20.0]);
    run.took
}

#[test]
fn a_head_wind_lengthens_a_leg_as_the_wind_triangle_says() {
    // max_speed 10, acceleration 3: the ground speed is 10 - 4 against a wind of 4 from
    // the east, sqrt(10^2 - 6^2) = 8 across a wind of 6 from the north, and 10 (the
    // speed asked) with the wind behind.
    let cases = [
        ("", 10.0),
        ("[air.wind]\nspeed = 4\nfrom = 90", 6.0),
        ("[air.wind]\nspeed = 6\nfrom = 0", 8.0),
        ("[air.wind]\nspeed = 4\nfrom = 270", 10.0),
    ];
    for (air, ground) in cases {
        let took = leg_east(air);
        let analytic = trapezoid(900.0, ground, 3.0);
        assert!((took - analytic).abs() <= 2.0 * DT, "{air}: {took} s, formula {analytic} s");
    }
}

/// The charge used hovering 120 s at 20 m (then flying 500 m east) in the air of `air`.
fn used(air: &str, sensors: &str) -> (f64, Fleet) {
    let mut fleet = up(&format!("[drones.d]\nhome = [0, 0]\n{sensors}\n{air}"), 0, 20.0);
    let before = fleet.telemetry(DroneId(0)).unwrap().battery;
    let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(500.0, 0.0)]);
    run_until(&mut fleet, 0, go, 600.0);
    (before - fleet.telemetry(DroneId(0)).unwrap().battery, fleet)
}

#[test]
fn the_drain_grows_with_airspeed() {
    let (still, _) = used("", "");
    let (calm, _) = used("[air.wind]\nspeed = 0\n", "");
    assert_eq!(still.to_bits(), calm.to_bits(), "a wind of 0 drains as still air");
    // Against 4 m/s the leg is longer and flown at airspeed 10 (ground 6): the drain per
    // second is (1 + 0.5) / (1 + 0.5 * 0.36) of still air's, for 10/6 of the time.
    let (head, fleet) = used("[air.wind]\nspeed = 4\nfrom = 90\n", "sensors = [\"wind\"]");
    let cruise = (1.0 + 0.5) / (1.0 + 0.5 * 0.36) * (10.0 / 6.0);
    assert!(head > still * 1.5 && head < still * cruise * 1.05, "{head} vs {still}");
    let wind = fleet.telemetry(DroneId(0)).unwrap().wind.expect("it has a wind sensor");
    assert!((wind[0] + 4.0).abs() < 1e-9 && wind[1].abs() < 1e-9, "{wind:?}");
    // No sensor, no reading.
    let (_, fleet) = used("[air.wind]\nspeed = 4\nfrom = 90\n", "");
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().wind, None);
}

#[test]
fn dryden_gusts_have_the_standards_intensity() {
    let (sigma, _) = crate::air::dryden(15.0 * 0.514_444, 30.0);
    let mut along = Vec::new();
    for seed in 0..4 {
        let mut fleet = up(
            "[drones.d]\nhome = [0, 0]\nsensors = [\"wind\"]\n[air.wind]\nspeed = 5\nfrom = 0\nturbulence = \"light\"\n",
            seed,
            30.0,
        );
        let hover = start(&mut fleet, 0, Function::Hover, &[num(1200.0)]);
        let run = run_until(&mut fleet, 0, hover, 1300.0);
        // Every second; the wind blows south, so the gust along it is -(north + 5).
        along.extend(run.samples.iter().step_by(20).map(|t| -(t.wind.unwrap()[1]) - 5.0));
        // The drone held its place whatever the gusts.
        assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [0.0, 0.0, 30.0]);
    }
    let n = along.len() as f64;
    let mean = along.iter().sum::<f64>() / n;
    let sd = (along.iter().map(|g| (g - mean) * (g - mean)).sum::<f64>() / n).sqrt();
    assert!(mean.abs() < 0.35 * sigma, "mean {mean}, sigma {sigma}");
    assert!((sd / sigma - 1.0).abs() < 0.25, "sd {sd}, sigma {sigma}");
}

const RADIO: &str = "[air.radio]\nstation = [0, 0]\nrange = 300\n";

#[test]
fn out_of_radio_reach_the_link_is_lost_and_comes_back_in_reach() {
    let mut fleet = up(&format!("[drones.d]\nhome = [0, 0]\n{RADIO}"), 0, 20.0);
    let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(500.0, 0.0)]);
    let run = run_until(&mut fleet, 0, go, 120.0);
    assert_eq!(run.end, CallEnd::Interrupted);
    let lost = run.samples.iter().position(|t| !t.link).expect("the link is lost");
    let x = run.samples[lost].position[0];
    // Looked at every 0.5 s, at up to 10 m/s: within 5 m past the range.
    assert!((300.0..=306.0).contains(&x), "lost at x = {x}");
    assert!(run.events.iter().any(|e| matches!(
        e,
        DroneEvent::Fault { failure, .. } if failure.exception == BuiltinException::ConnectionLost
    )));
    // It holds, returns on its own after 10 s, and has its link back in reach.
    let events: Vec<Report> = run_for(&mut fleet, 60.0);
    assert!(events.iter().any(|r| matches!(
        r,
        Report::Event(DroneEvent::Signal { signal: BuiltinSignal::ConnectionRestored, .. })
    )));
    let t = fleet.telemetry(DroneId(0)).unwrap();
    assert!(t.link && t.position[0] < 300.0, "{t:?}");
}

#[test]
fn a_relay_in_reach_keeps_the_link_of_a_drone_beyond_it() {
    let text = format!(
        "[drones.d]\nhome = [0, 0]\n[drones.relay]\nhome = [0, 20]\nair = {{ relay = true, range = 300 }}\n{RADIO}"
    );
    let mut fleet = up(&text, 0, 20.0);
    let go = start(&mut fleet, 1, Function::FlyToPosition, &[pos(250.0, 20.0)]);
    assert_eq!(run_until(&mut fleet, 1, go, 120.0).end, CallEnd::Done);
    let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(500.0, 0.0)]);
    let run = run_until(&mut fleet, 0, go, 120.0);
    assert_eq!(run.end, CallEnd::Done);
    assert!(run.samples.iter().all(|t| t.link));
    // Beyond the relay's reach too, it loses it.
    let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(600.0, 0.0)]);
    let run = run_until(&mut fleet, 0, go, 120.0);
    assert_eq!(run.end, CallEnd::Interrupted);
    assert!(!fleet.telemetry(DroneId(0)).unwrap().link);
}

/// Over `seeds` runs past four bodies 0, 5, 10 and 15 m beside the track, how often each
/// is found, with a sensor of range 20 and probability 0.9 and the falloff `falloff`.
fn detection_rates(falloff: &str, seeds: u64) -> [f64; 4] {
    let mut text = format!(
        "[drones.d]\nhome = [0, 0]\nsensors = [\"eye\"]\n[sensors.eye]\ndetects = [\"Body\"]\nrange = 20\nprobability = 0.9\n[air.detection]\nfalloff = {falloff}\n"
    );
    for (i, off) in [0, 5, 10, 15].iter().enumerate() {
        text.push_str(&format!("[[targets]]\nkind = \"Body\"\nat = [{}, {off}]\n", 100 * (i + 1)));
    }
    let w = world(&text);
    let mut counts = [0u32; 4];
    for seed in 0..seeds {
        let mut fleet = Fleet::new(&w).seeded(seed);
        // Detection works on the ground and in the air alike: fly low, straight east.
        instant(&mut fleet, 0, Function::Arm, &[]);
        let up = start(&mut fleet, 0, Function::TakeOff, &[num(5.0)]);
        run_until(&mut fleet, 0, up, 60.0);
        instant(&mut fleet, 0, Function::StartDetection, &[sym("Body")]);
        let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(450.0, 0.0)]);
        for e in run_until(&mut fleet, 0, go, 120.0).events {
            if let DroneEvent::Detected { location, .. } = e {
                counts[(location[0] / 100.0).round() as usize - 1] += 1;
            }
        }
    }
    counts.map(|c| f64::from(c) / seeds as f64)
}

#[test]
fn detection_follows_the_declared_curve() {
    let seeds = 300;
    let within = |rates: [f64; 4], expected: [f64; 4]| {
        for (got, p) in rates.iter().zip(expected) {
            // Four standard deviations of a binomial proportion.
            let tol = 4.0 * (p * (1.0 - p) / seeds as f64).sqrt() + 1e-9;
            assert!((got - p).abs() <= tol, "{rates:?} vs {expected:?}");
        }
    };
    within(detection_rates("\"linear\"", seeds), [0.9, 0.675, 0.45, 0.225]);
    within(detection_rates("[[0, 1], [0.5, 1], [1, 0]]", seeds), [0.9, 0.9, 0.9, 0.45]);
}

#[test]
fn a_known_fault_rate_fails_within_its_binomial_interval() {
    // 12 crashes per flight hour, 100 s of flight: a crash with 1 - e^(-1/3).
    let w = world("[drones.d]\nhome = [0, 0]\n[air.faults]\ncrash = 12\n");
    let seeds = 200;
    let mut crashed = 0;
    for seed in 0..seeds {
        let mut fleet = Fleet::new(&w).seeded(seed);
        instant(&mut fleet, 0, Function::Arm, &[]);
        start(&mut fleet, 0, Function::TakeOff, &[num(20.0)]);
        while fleet.odometry(DroneId(0)).1 < 100.0 - 1e-9 {
            fleet.step(DT);
            if fleet.telemetry(DroneId(0)).unwrap().state == FlightState::Lost {
                crashed += 1;
                break;
            }
        }
    }
    let p = 1.0 - (-1.0f64 / 3.0).exp();
    let (mean, sd) = (p * seeds as f64, (seeds as f64 * p * (1.0 - p)).sqrt());
    let c = f64::from(crashed);
    assert!((c - mean).abs() <= 3.3 * sd, "{crashed} crashes of {seeds}, expected {mean} ± {sd}");
}

#[test]
fn the_gps_reading_errs_by_its_size_and_the_truth_stays() {
    let mut fleet =
        up("[drones.d]\nhome = [0, 0]\n[air.gps]\nerror = 2.5\ncorrelation = 5\n", 3, 20.0);
    let hover = start(&mut fleet, 0, Function::Hover, &[num(2000.0)]);
    let run = run_until(&mut fleet, 0, hover, 2100.0);
    let errs: Vec<f64> = run
        .samples
        .iter()
        .map(|t| {
            assert_eq!(t.position, [0.0, 0.0, 20.0]);
            assert_eq!(t.gps_position[2], 20.0);
            t.gps_position[0]
        })
        .collect();
    let n = errs.len() as f64;
    let sd = (errs.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
    assert!((sd / 2.5 - 1.0).abs() < 0.15, "{sd}");
    // Correlated in time: a step apart, e^(-0.05/5).
    let lag: f64 = errs.windows(2).map(|w| w[0] * w[1]).sum::<f64>() / (n - 1.0) / (sd * sd);
    assert!((lag - (-0.01f64).exp()).abs() < 0.01, "{lag}");
    // A drone's own error.
    let own = world("[drones.d]\nhome = [0, 0]\nair = { gps_error = 0 }\n[air.gps]\nerror = 2.5\n");
    let t = Fleet::new(&own).seeded(1).telemetry(DroneId(0)).unwrap();
    assert_eq!(t.gps_position, t.position);
}

#[test]
fn capacities_spread_from_drone_to_drone() {
    let w = world(
        "[fleets.f]\ncount = 400\nhomes = { grid = [0, 0], spacing = 10, columns = 40 }\n[air.battery]\ncapacity_spread = 0.05\n",
    );
    let fleet = Fleet::new(&w).seeded(5);
    let caps: Vec<f64> = (0..fleet.len()).map(|i| fleet.capacity(DroneId(i))).collect();
    let n = caps.len() as f64;
    let mean = caps.iter().sum::<f64>() / n;
    let sd = (caps.iter().map(|c| (c - mean) * (c - mean)).sum::<f64>() / n).sqrt();
    assert!((mean - 1.0).abs() < 0.01 && (sd - 0.05).abs() < 0.008, "{mean} {sd}");
    assert!(caps.iter().all(|c| (0.85..=1.15).contains(c)));
    // A smaller battery drains faster, by its capacity.
    let one = "[drones.d]\nhome = [0, 0]\n[air.battery]\ncapacity_spread = 0.1\n";
    let mut fleet = up(one, 9, 20.0);
    let (b0, c) = (fleet.telemetry(DroneId(0)).unwrap().battery, fleet.capacity(DroneId(0)));
    run_for(&mut fleet, 100.0);
    let used = b0 - fleet.telemetry(DroneId(0)).unwrap().battery;
    assert!((used - 100.0 / 1800.0 / c).abs() < 1e-9, "{used} with capacity {c}");
    // Its critical level is the way home as a part of its own capacity.
    let fault = "[[faults]]\ndrone = \"d\"\nat = 60\nkind = \"battery_critical\"\n";
    let mut fleet = up(&format!("{one}{fault}"), 9, 20.0);
    let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(800.0, 800.0)]);
    assert_eq!(run_until(&mut fleet, 0, go, 400.0).end, CallEnd::Interrupted);
    let level = crate::battery::energy_home(&fleet.drones[0]) / c + 0.10;
    let reading = fleet.telemetry(DroneId(0)).unwrap().battery;
    assert!((reading - level).abs() < 1e-3 && (c - 1.0).abs() > 1e-3, "{reading} vs {level}");
}

/// Every report and telemetry of a flight in all the air there is.
fn windy_flight(seed: u64) -> String {
    let text = "[drones.d]\nhome = [0, 0]\nsensors = [\"wind\", \"eye\"]\n[drones.r]\nhome = [0, 20]\nair = { relay = true }\n[sensors.eye]\ndetects = [\"Body\"]\nrange = 30\nprobability = 0.8\n[[targets]]\nkind = \"Body\"\nat = [300, 10]\n[air.wind]\nspeed = 5\nfrom = 45\nturbulence = \"moderate\"\n[air.radio]\nstation = [0, 0]\nrange = 250\n[air.gps]\nerror = 2\n[air.detection]\nfalloff = \"linear\"\n[air.battery]\ncapacity_spread = 0.05\n[air.faults]\ngps_loss = 20\nlink_loss = { rate = 20, duration = 5 }\n";
    let mut fleet = up(text, seed, 20.0);
    instant(&mut fleet, 0, Function::StartDetection, &[sym("Body")]);
    let mut log = String::new();
    start(&mut fleet, 0, Function::FollowPath, &[pos(400.0, 0.0), pos(400.0, 300.0)]);
    for _ in 0..4000 {
        for r in fleet.step(DT) {
            log.push_str(&format!("{r:?}\n"));
        }
        log.push_str(&format!("{:?}\n", fleet.telemetry(DroneId(0))));
    }
    log
}

#[test]
fn the_same_seed_flies_the_same_air_bit_for_bit() {
    let a = windy_flight(11);
    assert_eq!(a, windy_flight(11));
    assert_ne!(a, windy_flight(12));
    // The air did something: faults fired, the wind was read.
    assert!(a.contains("PositionLost") || a.contains("ConnectionLost"), "no fault");
    assert!(a.contains("wind: Some"));
}

#[test]
fn a_world_without_air_has_no_air_state() {
    assert!(Fleet::new(&one_drone()).air.is_none());
    assert!(Fleet::new(&world("[drones.d]\nhome = [0, 0]\nair = {}\n")).air.is_some());
}

#[test]
fn a_battery_critical_fault_sets_the_reading() {
    let w = world(
        "[drones.d]\nhome = [0, 0]\n[[faults]]\ndrone = \"d\"\nat = 30\nkind = \"battery_critical\"\n",
    );
    let mut fleet = Fleet::new(&w);
    instant(&mut fleet, 0, Function::Arm, &[]);
    let up = start(&mut fleet, 0, Function::TakeOff, &[num(20.0)]);
    run_until(&mut fleet, 0, up, 60.0);
    let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(500.0, 0.0)]);
    let run = run_until(&mut fleet, 0, go, 120.0);
    assert_eq!(run.end, CallEnd::Interrupted);
    let t = fleet.telemetry(DroneId(0)).unwrap();
    let d = &fleet.drones[0];
    let critical = crate::battery::energy_home(d) + 0.10;
    assert!((t.battery - critical).abs() < 1e-3, "{} vs {critical}", t.battery);
    assert!(t.battery < 0.2, "{}", t.battery);
}

#[test]
fn a_link_loss_fault_out_of_reach_gives_no_link_back_until_in_reach() {
    let fault = "[[faults]]\ndrone = \"d\"\nat = 43\nkind = \"link_loss\"\nduration = 2\n";
    let mut fleet = up(&format!("[drones.d]\nhome = [0, 0]\n{fault}{RADIO}"), 0, 20.0);
    let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(500.0, 0.0)]);
    let run = run_until(&mut fleet, 0, go, 120.0);
    assert_eq!(run.end, CallEnd::Interrupted);
    assert!(fleet.time() < 43.0, "out of reach before the fault: {}", fleet.time());
    let mut restored_at = None;
    while fleet.time() < 120.0 {
        for r in fleet.step(DT) {
            if let Report::Event(DroneEvent::Signal {
                signal: BuiltinSignal::ConnectionRestored,
                ..
            }) = r
            {
                restored_at.get_or_insert(fleet.time());
            }
        }
        let t = fleet.telemetry(DroneId(0)).unwrap();
        if t.position[0] > 300.5 {
            assert!(!t.link, "linked out of reach at {}: {t:?}", fleet.time());
        }
    }
    let back = restored_at.expect("the link comes back in reach");
    assert!(back > 45.0, "{back}");
    assert!(fleet.telemetry(DroneId(0)).unwrap().link);
}
