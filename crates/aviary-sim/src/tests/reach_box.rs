//! The law of [`crate::reach_box`]: every point the planner would predict for a drone
//! flying as it does now lies in the box its legs give, whatever the legs, the speeds it
//! carries into them and the wind.

use super::*;
use crate::avoid::{predict_with, HORIZON};
use crate::motion::{Leg, MotionTask};
use crate::reach_box::reach_box;
use aviary_api::FlightState;
use proptest::prelude::*;

fn leg() -> impl Strategy<Value = Leg> {
    prop_oneof![
        ((-300f64..300.0, -300f64..300.0, 0f64..100.0), 0f64..20.0).prop_map(|(to, speed)| {
            Leg::Move { to: [to.0, to.1, to.2], speed, state: FlightState::Flying }
        }),
        (0f64..3.0).prop_map(|left| Leg::Hold { left }),
        ((-200f64..200.0, -200f64..200.0), 1f64..80.0, -7f64..7.0, 0f64..13.0, 0.5f64..15.0)
            .prop_map(|(c, radius, start, total, speed)| Leg::Arc {
                center: [c.0, c.1],
                radius,
                start,
                total,
                speed,
            }),
    ]
}

proptest! {
    #[test]
    fn the_predicted_track_stays_in_the_reach_box(
        pos in (-300f64..300.0, -300f64..300.0, 0f64..100.0),
        legs in proptest::collection::vec(leg(), 1..5),
        carried in (0f64..25.0, 0f64..6.0, 0f64..25.0, 0f64..3.0),
        wind in proptest::option::of((-12f64..12.0, -12f64..12.0)),
        accel in 0.5f64..10.0,
        paused in proptest::bool::weighted(0.1),
    ) {
        let world = one_drone();
        let mut spec = crate::drone::Spec::of(&world.drones[0]);
        spec.accel = accel;
        let mut d = crate::drone::SimDrone::new(&world.drones[0], std::sync::Arc::new(spec));
        d.pos = [pos.0, pos.1, pos.2];
        d.state = FlightState::Flying;
        d.armed = true;
        let mut task = MotionTask::new(None, legs);
        (task.ground_speed, task.climb_speed, task.arc_speed) = (carried.0, carried.1, carried.2);
        // An arc already part flown.
        if let Some(Leg::Arc { total, .. }) = task.legs.front() {
            task.arc_done = carried.3.min(*total);
            if let Some(Leg::Arc { center, radius, start, .. }) = task.legs.front() {
                let theta = start - task.arc_done;
                d.pos = [center[0] + radius * theta.cos(), center[1] + radius * theta.sin(), pos.2];
            }
        }
        task.wind = wind.map(|w| [w.0, w.1]);
        task.paused = paused;
        d.motion = Some(Box::new(task));
        let b = reach_box(&d, DT + HORIZON).expect("a box for finite legs");
        let (track, _) = predict_with(&d, None, DT, &[], 5.0);
        for p in track.iter().flatten() {
            prop_assert!(b.holds(*p), "{p:?} outside {b:?}");
        }
    }
}
