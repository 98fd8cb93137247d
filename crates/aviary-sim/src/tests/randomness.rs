//! The seed: chances the world asks for are drawn from it, the same each time for one
//! seed; a world that asks for none flies the same whatever the seed.

use aviary_api::DroneEvent;
use aviary_world::World;

use super::*;

/// Drone `d` with a sensor that finds a `Body` with chance `p`, over a line of 60 bodies
/// 10 m apart.
fn line_of_bodies(p: &str) -> World {
    let mut text = format!(
        "[drones.d]\nhome = [0, 0]\nsensors = [\"eye\"]\n[sensors.eye]\ndetects = [\"Body\"]\nrange = 3\n{p}\n"
    );
    for i in 1..=60 {
        text.push_str(&format!("[[targets]]\nkind = \"Body\"\nat = [{}, 0]\n", i * 10));
    }
    world(&text)
}

/// The x of every body found flying the line with `seed`.
fn found(world: &World, seed: u64) -> Vec<f64> {
    let mut fleet = Fleet::new(world).seeded(seed);
    instant(&mut fleet, 0, Function::Arm, &[]);
    let up = start(&mut fleet, 0, Function::TakeOff, &[num(10.0)]);
    run_until(&mut fleet, 0, up, 60.0);
    assert_eq!(instant(&mut fleet, 0, Function::StartDetection, &[sym("Body")]), CallEnd::Done);
    let go = start(&mut fleet, 0, Function::FlyToPosition, &[pos(700.0, 0.0)]);
    let run = run_until(&mut fleet, 0, go, 200.0);
    run.events
        .iter()
        .map(|e| match e {
            DroneEvent::Detected { location, .. } => location[0],
            other => panic!("{other:?}"),
        })
        .collect()
}

#[test]
fn a_sure_sensor_finds_everything_whatever_the_seed() {
    let w = line_of_bodies("");
    let all: Vec<f64> = (1..=60).map(|i| f64::from(i) * 10.0).collect();
    for seed in [0, 1, 7, u64::MAX] {
        assert_eq!(found(&w, seed), all);
    }
    assert_eq!(found(&line_of_bodies("probability = 1"), 3), all);
}

#[test]
fn an_unsure_sensor_finds_what_its_seed_says() {
    let w = line_of_bodies("probability = 0.5");
    let a = found(&w, 1);
    assert_eq!(found(&w, 1), a, "the same seed, the same finds");
    assert!((15..=45).contains(&a.len()), "{} of 60", a.len());
    let b = found(&w, 2);
    assert_ne!(a, b, "another seed, other finds");
    // Without `seeded`, the seed is 0.
    let mut fleet = Fleet::new(&w);
    assert_eq!(fleet.seed, 0);
    fleet = fleet.seeded(0);
    assert_eq!(fleet.seed, 0);
    assert!(found(&line_of_bodies("probability = 0"), 5).is_empty());
}

/// A target missed stays missed in that detection, and has a new chance in the next.
#[test]
fn a_miss_holds_until_detection_starts_again() {
    let text = "[drones.d]\nhome = [0, 0]\nsensors = [\"eye\"]\n[sensors.eye]\ndetects = [\"Body\"]\nrange = 30\nprobability = 0.5\n\
                [[targets]]\nkind = \"Body\"\nat = [0, 10]\n";
    let w = world(text);
    // The seeds whose first draw misses the body, hovering over it.
    let mut missed = 0;
    for seed in 0..20 {
        let mut fleet = Fleet::new(&w).seeded(seed);
        instant(&mut fleet, 0, Function::Arm, &[]);
        let up = start(&mut fleet, 0, Function::TakeOff, &[num(10.0)]);
        run_until(&mut fleet, 0, up, 60.0);
        instant(&mut fleet, 0, Function::StartDetection, &[sym("Body")]);
        let first = run_for(&mut fleet, 5.0);
        if !first.is_empty() {
            continue;
        }
        missed += 1;
        // Still there, still missed.
        assert!(run_for(&mut fleet, 5.0).is_empty());
        // Each new start is a new chance: within 30 starts, found.
        let mut found = false;
        for _ in 0..30 {
            instant(&mut fleet, 0, Function::StopDetection, &[sym("Body")]);
            instant(&mut fleet, 0, Function::StartDetection, &[sym("Body")]);
            if !run_for(&mut fleet, 0.1).is_empty() {
                found = true;
                break;
            }
        }
        assert!(found, "seed {seed}");
    }
    assert!((3..=17).contains(&missed), "{missed} of 20 missed");
}

fn crash_at(at: &str) -> World {
    world(&format!(
        "[drones.a]\nhome = [0, 0]\n[[faults]]\ndrone = \"a\"\nat = {at}\nkind = \"crash\"\n"
    ))
}

/// When the drone is lost, to the tick.
fn lost_at(world: &World, seed: u64) -> f64 {
    let mut fleet = Fleet::new(world).seeded(seed);
    instant(&mut fleet, 0, Function::Arm, &[]);
    start(&mut fleet, 0, Function::TakeOff, &[num(30.0)]);
    for _ in 0..4000 {
        let reports = fleet.step(DT);
        if reports.iter().any(|r| matches!(r, Report::Event(DroneEvent::Fault { .. }))) {
            return fleet.time();
        }
    }
    panic!("no crash");
}

#[test]
fn a_fault_happens_at_a_time_its_seed_draws() {
    let w = crash_at("[20, 120]");
    let times: Vec<f64> = (0..12).map(|seed| lost_at(&w, seed)).collect();
    for (seed, t) in times.iter().enumerate() {
        assert!((20.0..=120.0 + DT).contains(t), "seed {seed}: {t}");
        assert_eq!(lost_at(&w, seed as u64), *t, "the same seed, the same time");
    }
    let mut distinct = times.clone();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    assert!(distinct.len() >= 10, "{times:?}");
    // A time, not a range: the seed changes nothing.
    let fixed = crash_at("42");
    assert!((0..5).all(|seed| lost_at(&fixed, seed) == lost_at(&fixed, 0)));
    // A range of one time is that time.
    assert_eq!(lost_at(&crash_at("[42, 42]"), 9), lost_at(&fixed, 0));
}
