//! Separation: drones on colliding courses keep `min_separation`, every step, and still
//! get where they were going.

use aviary_api::{CallEnd, CallId, FlightState, Telemetry};
use aviary_world::World;

use super::sky::{call, fly, Act, Flight};
use super::*;

/// A world with these drones (`name = [x, y]` homes, extra keys after a `;`).
fn drones(list: &[(&str, [f64; 2], &str)]) -> World {
    let text: String = list
        .iter()
        .map(|(name, [x, y], extra)| {
            format!("[drones.{name}]\nhome = [{x}, {y}]\n{}\n", extra.replace(';', "\n"))
        })
        .collect();
    world(&text)
}

/// Each drone takes off to `alt` and flies to its target, all at the same moment.
fn go(world: &World, alt: f64, targets: &[[f64; 2]]) -> Flight {
    let scripts = targets
        .iter()
        .map(|t| {
            vec![
                call(Function::Arm, &[]),
                call(Function::TakeOff, &[num(alt)]),
                Act::At(10.0),
                call(Function::FlyToPosition, &[pos(t[0], t[1])]),
            ]
        })
        .collect();
    fly(world, scripts, 300.0)
}

/// The same flight with no separation at all (to show that the courses do collide).
fn unseparated(mut world: World, alt: f64, targets: &[[f64; 2]]) -> f64 {
    world.site.min_separation = 0.0;
    go(&world, alt, targets).closest
}

fn assert_arrived(f: &Flight, alt: f64, targets: &[[f64; 2]]) {
    for (d, t) in targets.iter().enumerate() {
        let end = f.fleet.telemetry(DroneId(d)).unwrap();
        assert_eq!(end.position, [t[0], t[1], alt], "drone {d} at its target");
        assert_eq!((end.speed, end.state), (0.0, FlightState::Flying));
    }
}

/// Every drone kept its ground track: it stayed on the line from its home to its target.
fn assert_tracks_kept(world: &World, f: &Flight, targets: &[[f64; 2]]) {
    for (d, t) in targets.iter().enumerate() {
        let home = [world.drones[d].home[0], world.drones[d].home[1]];
        for snap in &f.log {
            let p = [snap[d].position[0], snap[d].position[1]];
            let off = crate::geom::dist_to_segment(p, home, *t);
            assert!(off < 1e-6, "drone {d} left its track by {off} m");
        }
    }
}

fn highest(f: &Flight, d: usize) -> f64 {
    f.log.iter().map(|s| s[d].position[2]).fold(0.0, f64::max)
}

#[test]
fn head_on_both_arrive_and_the_second_passes_above() {
    let w = drones(&[("a", [-100.0, 0.0], ""), ("b", [100.0, 0.0], "")]);
    let targets = [[100.0, 0.0], [-100.0, 0.0]];
    assert!(unseparated(w.clone(), 20.0, &targets) < 1.0);
    let f = go(&w, 20.0, &targets);
    assert!(f.closest >= 5.0, "{}", f.closest);
    assert_arrived(&f, 20.0, &targets);
    assert_tracks_kept(&w, &f, &targets);
    // The first drone has priority: it keeps its altitude and its time.
    assert_eq!(highest(&f, 0), 20.0);
    let nominal = 10.0 + 200.0 / 10.0 + 10.0 / 3.0;
    assert!((f.finished[0] - nominal).abs() < 0.2, "{}", f.finished[0]);
    let top = highest(&f, 1);
    assert!((25.0..=27.0).contains(&top), "b passed above: {top}");
    assert!(f.finished[1] < nominal + 10.0, "{}", f.finished[1]);
}

#[test]
fn crossing_at_right_angles_both_arrive() {
    let w = drones(&[("a", [0.0, -150.0], ""), ("b", [-150.0, 0.0], "")]);
    let targets = [[0.0, 150.0], [150.0, 0.0]];
    assert!(unseparated(w.clone(), 20.0, &targets) < 1.0);
    let f = go(&w, 20.0, &targets);
    assert!(f.closest >= 5.0, "{}", f.closest);
    assert_arrived(&f, 20.0, &targets);
    assert_tracks_kept(&w, &f, &targets);
    assert_eq!(highest(&f, 0), 20.0);
    let nominal = 10.0 + 300.0 / 10.0 + 10.0 / 3.0;
    assert!((f.finished[0] - nominal).abs() < 0.2, "{}", f.finished[0]);
    assert!(f.finished[1] > f.finished[0], "b gave way");
}

#[test]
fn three_converging_drones_all_arrive() {
    let (c, s) = (150.0 * 30f64.to_radians().cos(), 75.0);
    let w = drones(&[("a", [0.0, -150.0], ""), ("b", [c, s], ""), ("c", [-c, s], "")]);
    let targets = [[0.0, 150.0], [-c, -s], [c, -s]];
    assert!(unseparated(w.clone(), 15.0, &targets) < 1.0);
    let f = go(&w, 15.0, &targets);
    assert!(f.closest >= 5.0, "{}", f.closest);
    assert_arrived(&f, 15.0, &targets);
    assert_tracks_kept(&w, &f, &targets);
    assert_eq!(highest(&f, 0), 15.0);
}

#[test]
fn different_speeds_head_on_crossing_and_overtaking() {
    // Head-on: slow first drone, fast second.
    let w = drones(&[("a", [-60.0, 0.0], "max_speed = 4"), ("b", [150.0, 0.0], "max_speed = 12")]);
    let targets = [[60.0, 0.0], [-150.0, 0.0]];
    assert!(unseparated(w.clone(), 20.0, &targets) < 1.0);
    let f = go(&w, 20.0, &targets);
    assert!(f.closest >= 5.0);
    assert_arrived(&f, 20.0, &targets);
    // Crossing: the fast drone must give way to the slow one.
    let w = drones(&[("a", [-60.0, 0.0], "max_speed = 4"), ("b", [0.0, -165.0], "max_speed = 12")]);
    let targets = [[60.0, 0.0], [0.0, 100.0]];
    assert!(unseparated(w.clone(), 20.0, &targets) < 5.0);
    let f = go(&w, 20.0, &targets);
    assert!(f.closest >= 5.0);
    assert_arrived(&f, 20.0, &targets);
    assert_tracks_kept(&w, &f, &targets);
    // Overtaking on the same line: the fast drone behind gives way and gets past.
    let w =
        drones(&[("slow", [0.0, 0.0], "max_speed = 3"), ("fast", [-60.0, 0.0], "max_speed = 12")]);
    let targets = [[150.0, 0.0], [300.0, 0.0]];
    assert!(unseparated(w.clone(), 20.0, &targets) < 1.0);
    let f = go(&w, 20.0, &targets);
    assert!(f.closest >= 5.0);
    assert_arrived(&f, 20.0, &targets);
    assert_tracks_kept(&w, &f, &targets);
}

#[test]
fn take_off_side_by_side_at_exactly_the_separation() {
    let w = drones(&[("a", [0.0, 0.0], ""), ("b", [5.0, 0.0], ""), ("c", [0.0, 5.0], "")]);
    let scripts = (0..3)
        .map(|_| vec![call(Function::Arm, &[]), call(Function::TakeOff, &[num(20.0)])])
        .collect();
    let f = fly(&w, scripts, 60.0);
    assert_eq!(f.closest, 5.0);
    // Side by side climbs are not in each other's way: all three take the plain time.
    for d in 0..3 {
        assert!((f.finished[d] - (2.0 + 17.0 / 3.0)).abs() < 0.1, "{:?}", f.finished);
    }
}

/// The paper's world, with calls like the mission's: several drones take off from homes
/// 5 m apart, fly out, two beacon drones cross near home, and all return together.
fn paper_flight(world: &World) -> Flight {
    let to = |x: f64, y: f64| call(Function::FlyToPosition, &[pos(x, y)]);
    let up = |alt: f64| vec![call(Function::Arm, &[]), call(Function::TakeOff, &[num(alt)])];
    let back = [Act::At(70.0), call(Function::ReturnToLaunch, &[])];
    let with = |mut first: Vec<Act>, rest: &[Act]| {
        first.extend_from_slice(rest);
        first.extend_from_slice(&back);
        first
    };
    let later = |t: f64, alt: f64| {
        let mut s = vec![Act::At(t)];
        s.extend(up(alt));
        s
    };
    let scripts = vec![
        with(up(20.0), &[to(150.0, 100.0)]),
        with(up(25.0), &[to(-200.0, 150.0)]),
        with(later(8.0, 10.0), &[to(200.0, 325.0)]),
        with(later(8.0, 10.0), &[to(-250.0, -25.0)]),
        with(up(10.0), &[to(0.0, -300.0)]),
        with(later(20.0, 10.0), &[to(20.0, -20.0), call(Function::DescendTo, &[num(3.0)])]),
        with(later(20.0, 10.0), &[to(-20.0, -20.0), call(Function::DescendTo, &[num(3.0)])]),
    ];
    fly(world, scripts, 400.0)
}

fn paper_world() -> World {
    let text = include_str!("../../../../examples/search_and_rescue.world.toml");
    let (world, diags) = aviary_world::parse_world(aviary_diagnostics::FileId(0), text);
    assert!(diags.is_empty(), "{diags:#?}");
    world.unwrap()
}

#[test]
fn the_paper_world_keeps_separation_and_everyone_gets_home() {
    let w = paper_world();
    assert_eq!(w.site.min_separation, 5.0);
    let mut loose = w.clone();
    loose.site.min_separation = 0.0;
    assert!(paper_flight(&loose).closest < 5.0, "the courses do meet");
    let f = paper_flight(&w);
    assert!(f.closest >= 5.0);
    for (d, drone) in w.drones.iter().enumerate() {
        let t = f.fleet.telemetry(DroneId(d)).unwrap();
        assert_eq!(t.state, FlightState::Landed, "{}", drone.name);
        assert_eq!([t.position[0], t.position[1]], [drone.home[0], drone.home[1]]);
    }
}

#[test]
fn separated_flights_are_deterministic_and_far_drones_unchanged() {
    let w = paper_world();
    let (a, b) = (paper_flight(&w), paper_flight(&w));
    assert_eq!(a.log.len(), b.log.len());
    for (x, y) in a.log.iter().flatten().zip(b.log.iter().flatten()) {
        assert_eq!(x, y);
        for k in 0..3 {
            assert_eq!(x.position[k].to_bits(), y.position[k].to_bits());
        }
    }
    assert_eq!(a.reports, b.reports);
    // Drones that never come near each other fly exactly as without separation.
    let w = drones(&[("a", [0.0, 0.0], ""), ("b", [300.0, 0.0], "")]);
    let targets = [[0.0, 200.0], [300.0, -200.0]];
    let with = go(&w, 20.0, &targets);
    let mut loose = w.clone();
    loose.site.min_separation = 0.0;
    let without = go(&loose, 20.0, &targets);
    assert_eq!(with.log, without.log);
}

/// A small deterministic generator for the random encounters.
struct Lcg(u64);

impl Lcg {
    /// A number in [0, 1).
    fn next(&mut self) -> f64 {
        self.0 =
            self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 33) as f64 / (1u64 << 31) as f64
    }

    /// A whole number of metres in [-r, r].
    fn metres(&mut self, r: f64) -> f64 {
        (self.next() * 2.0 * r - r).round()
    }
}

#[test]
fn random_crowds_keep_separation_and_all_finish() {
    let mut rnd = Lcg(12345);
    for _ in 0..40 {
        let n = 2 + (rnd.next() * 7.0) as usize;
        let mut homes: Vec<[f64; 2]> = Vec::new();
        while homes.len() < n {
            let h = [rnd.metres(30.0), rnd.metres(30.0)];
            if homes.iter().all(|o| crate::geom::dist(*o, h) >= 5.0) {
                homes.push(h);
            }
        }
        let text: String = homes
            .iter()
            .enumerate()
            .map(|(i, h)| {
                let speed = 4 + (rnd.next() * 9.0) as i32;
                format!("[drones.d{i}]\nhome = {h:?}\nmax_speed = {speed}\n")
            })
            .collect();
        let scripts = (0..n)
            .map(|_| {
                let alt = [10.0, 10.0, 12.0][(rnd.next() * 3.0) as usize];
                let (a, b) =
                    ([rnd.metres(50.0), rnd.metres(50.0)], [rnd.metres(50.0), rnd.metres(50.0)]);
                let mut s = vec![
                    Act::At((rnd.next() * 20.0).round()),
                    call(Function::Arm, &[]),
                    call(Function::TakeOff, &[num(alt)]),
                    call(Function::FlyToPosition, &[pos(a[0], a[1])]),
                ];
                s.push(match (rnd.next() * 3.0) as usize {
                    0 => call(
                        Function::Orbit,
                        &[pos(b[0], b[1]), num(20.0 + rnd.metres(10.0) + 10.0)],
                    ),
                    1 => {
                        call(Function::FollowPath, &[pos(b[0], b[1]), pos3(a[0], b[1], alt + 5.0)])
                    }
                    _ => call(Function::Hover, &[num(5.0)]),
                });
                s.push(call(Function::ReturnToLaunch, &[]));
                s
            })
            .collect();
        let f = fly(&world(&text), scripts, 600.0);
        assert!(f.closest >= 5.0);
    }
}

/// Two drones (`site`: extra `[site]` keys) take off to 20 m and, at 10 s, are both sent to the same point. Returns the
/// fleet, each call's end and when it came (simulated seconds), and the second drone's
/// telemetry after every step from then on.
fn same_point(site: &str) -> (Fleet, Vec<(CallEnd, f64)>, Vec<Telemetry>) {
    let w = world(&format!("{site}\n[drones.a]\nhome = [0, 0]\n\n[drones.b]\nhome = [10, 0]\n"));
    let mut fleet = Fleet::new(&w);
    for d in 0..2 {
        assert_eq!(instant(&mut fleet, d, Function::Arm, &[]), CallEnd::Done);
        start(&mut fleet, d, Function::TakeOff, &[num(20.0)]);
    }
    run_for(&mut fleet, 10.0);
    let calls: Vec<CallId> =
        (0..2).map(|d| start(&mut fleet, d, Function::FlyToPosition, &[pos(0.0, 100.0)])).collect();
    let mut ends: Vec<Option<(CallEnd, f64)>> = vec![None, None];
    let mut log = Vec::new();
    while ends.iter().any(Option::is_none) && fleet.time() < 200.0 {
        for r in fleet.step(DT) {
            if let Report::Ended { call, end } = r {
                if let Some(d) = calls.iter().position(|c| *c == call) {
                    ends[d] = Some((end, fleet.time()));
                }
            }
        }
        log.push(fleet.telemetry(DroneId(1)).unwrap());
    }
    let ends = ends.into_iter().map(|e| e.expect("the call ended")).collect();
    (fleet, ends, log)
}

/// When drone 1 last got nearer the point (0, 100, 20), after `log`.
fn last_gain(log: &[Telemetry], until: f64) -> f64 {
    let far = |t: &Telemetry| {
        let p = t.position;
        p[0].hypot(p[1] - 100.0).hypot(p[2] - 20.0)
    };
    let mut best = f64::INFINITY;
    let mut when = 0.0;
    for (k, t) in log.iter().enumerate() {
        if far(t) < best - 1e-6 {
            best = far(t);
            when = 10.0 + (k + 1) as f64 * DT;
        }
    }
    assert!(when < until);
    when
}

#[test]
fn two_drones_sent_to_the_same_point_the_second_times_out_and_hovers() {
    let (mut fleet, ends, log) = same_point("");
    // The first drone arrives, on time.
    assert_eq!(ends[0].0, CallEnd::Done);
    let nominal = 10.0 + 100.0 / 10.0 + 10.0 / 3.0;
    assert!((ends[0].1 - nominal).abs() < 0.2, "{}", ends[0].1);
    assert_eq!(fleet.telemetry(DroneId(0)).unwrap().position, [0.0, 100.0, 20.0]);
    // The second one passes above it and waits there, over the point; 30 s after it last
    // got nearer, its call ends with `Timeout`.
    let (end, at) = &ends[1];
    let CallEnd::Failed(failure) = end else { panic!("{end:?}") };
    assert_eq!(failure.exception, BuiltinException::Timeout);
    assert_eq!(failure.reason, "b waited 30 s for a to make room");
    assert_eq!(
        failure.cause,
        Some(aviary_api::Cause::Separation),
        "said as data, not only in words"
    );
    let waited = at - last_gain(&log, *at);
    assert!((29.99..31.0).contains(&waited), "{waited}");
    // Then it hovers where it is, clear of the first drone, and takes new calls.
    let held = fleet.telemetry(DroneId(1)).unwrap();
    assert_eq!((held.speed, held.state), (0.0, FlightState::Flying));
    let apart = |t: &Telemetry| {
        let p = t.position;
        p[0].hypot(p[1] - 100.0).hypot(p[2] - 20.0)
    };
    assert!(apart(&held) >= 5.0, "{held:?}");
    run_for(&mut fleet, 10.0);
    assert_eq!(fleet.telemetry(DroneId(1)).unwrap().position, held.position);
    let id = start(&mut fleet, 1, Function::FlyToPosition, &[pos(10.0, 0.0)]);
    assert_eq!(run_until(&mut fleet, 1, id, 60.0).end, CallEnd::Done);
}

#[test]
fn the_separation_timeout_is_the_sites() {
    let (_, ends, log) = same_point("separation_timeout = 5");
    assert_eq!(ends[0].0, CallEnd::Done);
    let (end, at) = &ends[1];
    match end {
        CallEnd::Failed(f) => {
            assert_eq!(f.exception, BuiltinException::Timeout);
            assert_eq!(f.reason, "b waited 5 s for a to make room");
        }
        other => panic!("{other:?}"),
    }
    let waited = at - last_gain(&log, *at);
    assert!((4.99..6.0).contains(&waited), "{waited}");
}
