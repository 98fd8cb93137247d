//! The safety filter's ground rules: braking never moves a stopping point, so envelopes
//! only shrink; and the distance between envelopes.

use super::*;
use crate::separation::{brake, envelope, gap, Envelope};

fn point(p: [f64; 3]) -> Envelope {
    Envelope { from: [p[0], p[1]], to: [p[0], p[1]], pad: 0.0, low: p[2], high: p[2] }
}

/// Brakes drone 0 of `fleet` to a stop, checking at every tick that its new envelope lies
/// within the old one (no probe point gets nearer to it) and that it stays inside the
/// first envelope.
fn brake_to_a_stop(fleet: &Fleet) -> usize {
    let mut d = fleet.drones[0].clone();
    let first = envelope(&d);
    let here = d.pos;
    let probes: Vec<Envelope> = (-12..=12)
        .flat_map(|i| (-12..=12).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            [-6.0, 0.0, 6.0]
                .map(|dz| point([here[0] + 3.0 * i as f64, here[1] + 3.0 * j as f64, here[2] + dz]))
        })
        .collect();
    let mut before = first;
    let mut ticks = 0;
    while d.vel.iter().any(|v| *v != 0.0) {
        d.brake_all(DT);
        let now = envelope(&d);
        for p in &probes {
            assert!(gap(&now, p) >= gap(&before, p) - 1e-9, "{before:?} -> {now:?}");
        }
        assert!(gap(&point(d.pos), &first) < 1e-9, "left its envelope: {:?}", d.pos);
        before = now;
        ticks += 1;
        assert!(ticks < 1000);
    }
    ticks
}

#[test]
fn braking_only_shrinks_the_envelope_straight_on_an_arc_and_vertically() {
    let w = one_drone();
    // Straight, at full speed: stops exactly v²/2a further on.
    let mut fleet = airborne(&w, 20.0);
    start(&mut fleet, 0, Function::FlyToPosition, &[pos(300.0, 0.0)]);
    run_for(&mut fleet, 6.0);
    let (x, v) = (fleet.drones[0].pos[0], fleet.drones[0].vel[0]);
    assert_eq!(v, 10.0);
    let e = envelope(&fleet.drones[0]);
    assert!((e.to[0] - (x + 100.0 / 6.0)).abs() < 1e-9, "{e:?}");
    assert!(brake_to_a_stop(&fleet) > 60);
    // On an orbit.
    let mut fleet = airborne(&w, 20.0);
    start(&mut fleet, 0, Function::Orbit, &[pos(40.0, 0.0), num(40.0)]);
    run_for(&mut fleet, 15.0);
    assert!(fleet.drones[0].vel[0].hypot(fleet.drones[0].vel[1]) > 5.0);
    assert!(envelope(&fleet.drones[0]).pad > 0.0);
    brake_to_a_stop(&fleet);
    // Climbing.
    let mut fleet = Fleet::new(&w);
    instant(&mut fleet, 0, Function::Arm, &[]);
    start(&mut fleet, 0, Function::TakeOff, &[num(30.0)]);
    run_for(&mut fleet, 3.0);
    assert_eq!(fleet.drones[0].vel[2], 3.0);
    let e = envelope(&fleet.drones[0]);
    assert!((e.high - e.low - 1.5).abs() < 1e-9, "{e:?}");
    brake_to_a_stop(&fleet);
}

#[test]
fn one_braking_tick_moves_at_most_to_the_stopping_point() {
    for v in [0.0, 0.05, 0.15, 0.3, 1.0, 9.85, 10.0] {
        let (mut speed, mut gone) = (v, 0.0);
        while speed > 0.0 {
            let (moved, after) = brake(speed, 3.0, DT);
            assert!(after <= speed && speed - after <= 3.0 * DT + 1e-12);
            gone += moved;
            speed = after;
        }
        assert!((gone - v * v / 6.0).abs() < 1e-9, "{v}: {gone}");
    }
}

#[test]
fn the_distance_between_envelopes_combines_ground_and_height() {
    let a = Envelope { from: [0.0, 0.0], to: [10.0, 0.0], pad: 0.0, low: 10.0, high: 12.0 };
    // Crossing tracks, 3 m and 4 m of height apart: 4 m.
    let b = Envelope { from: [5.0, -5.0], to: [5.0, 5.0], pad: 0.0, low: 16.0, high: 20.0 };
    assert_eq!(gap(&a, &b), 4.0);
    // Parallel tracks 5 m apart at the same height, one of them 1 m wide: 4 m.
    let c = Envelope { from: [0.0, 5.0], to: [10.0, 5.0], pad: 1.0, low: 11.0, high: 11.0 };
    assert_eq!(gap(&a, &c), 4.0);
    // 3 m over the ground and 4 m of height: 5 m.
    assert_eq!(gap(&point([13.0, 0.0, 16.0]), &a), 5.0);
}

mod bound {
    use super::*;
    use crate::motion::{Leg, MotionTask};
    use crate::separation::{extent, extent_bound};
    use aviary_api::FlightState;
    use proptest::prelude::*;

    proptest! {
        /// `extent_bound` never falls below the extent of the envelope it stands for, on
        /// straight legs, arcs and hovers, far from the origin too.
        #[test]
        fn extent_bound_is_at_least_the_extent(
            pos in (-1e5f64..1e5, -1e5f64..1e5, 0f64..150.0),
            vel in (-20f64..20.0, -20f64..20.0, -6f64..6.0),
            axis in 0u8..3, accel in 0.5f64..10.0, radius in 1f64..500.0, leg in 0u8..3,
        ) {
            let world = one_drone();
            let mut spec = crate::drone::Spec::of(&world.drones[0]);
            spec.accel = accel;
            let mut d = crate::drone::SimDrone::new(&world.drones[0], std::sync::Arc::new(spec));
            d.pos = [pos.0, pos.1, pos.2];
            d.vel = match axis { 0 => [vel.0, 0.0, vel.2], 1 => [0.0, vel.1, 0.0], _ => [vel.0, vel.1, vel.2] };
            d.state = FlightState::Flying;
            let legs = match leg {
                0 => vec![Leg::Move { to: [0.0, 0.0, 20.0], speed: 10.0, state: FlightState::Flying }],
                1 => vec![Leg::Arc { center: [0.0, 0.0], radius, start: 0.0, total: 6.0, speed: 10.0 }],
                _ => vec![Leg::Hold { left: 3.0 }],
            };
            d.motion = Some(Box::new(MotionTask::new(None, legs)));
            let (exact, bound) = (extent(&envelope(&d)), extent_bound(&d));
            prop_assert!(bound >= exact, "{bound} < {exact}");
        }
    }
}
