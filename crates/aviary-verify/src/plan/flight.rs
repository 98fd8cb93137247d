//! Each middle-layer function's cost in the estimate (docs/LANGUAGE.md, section 19), as the simulator
//! flies it.

use aviary_api::{DroneId, Place, PlannedCall, Waypoint};
use aviary_ir::Origin;

use super::estimate::{Estimator, Raise};
use super::radio::Leg;
use aviary_api::flight::LOAD_TIME;

/// How long `call` takes on drone `d` from time `t`, and the detections on the way. An
/// argument known only in flight is `None` ([`PlannedCall`]).
pub fn fly(
    e: &mut Estimator,
    d: DroneId,
    call: &PlannedCall,
    at: Option<Origin>,
    t: f64,
) -> (f64, Vec<Raise>) {
    let max_altitude = e.world.site.max_altitude;
    let mut raises = Vec::new();
    e.leg_origin = at;
    let (before, legs) = (e.s.drones[d].pos, e.s.tracks[d].len());
    // An orbit's centre, radius and laps, for the radio's check below.
    let mut circle = None;
    let duration = match call {
        PlannedCall::TakeOff { alt } => {
            let alt = alt.unwrap_or(10.0);
            let f = &mut e.s.drones[d];
            let from_the_ground = !f.airborne;
            f.take_off(t);
            if from_the_ground {
                f.lift_off(alt)
            } else {
                f.leg([f.pos[0], f.pos[1], alt])
            }
        }
        PlannedCall::Land => {
            let f = &mut e.s.drones[d];
            let took = f.land_here();
            f.land(t + took);
            took
        }
        PlannedCall::ReturnToLaunch => {
            let f = &mut e.s.drones[d];
            let took = f.return_home(&e.airspace, max_altitude);
            f.land(t + took);
            took
        }
        PlannedCall::DescendTo { alt } | PlannedCall::AscendTo { alt } => match alt {
            Some(alt) => {
                let f = &mut e.s.drones[d];
                f.leg([f.pos[0], f.pos[1], *alt])
            }
            None => 0.0,
        },
        PlannedCall::Hover { duration } => duration.unwrap_or(0.0),
        PlannedCall::FlyToPosition { pos, speed } => {
            fly_to_position(e, d, pos.as_ref(), speed.flatten(), at, t, &mut raises)
        }
        PlannedCall::Orbit { center, radius, laps } => {
            let center = e.position_arg(center.as_ref(), d, at);
            match (center, radius) {
                (Some(c), Some(r)) => {
                    let laps = laps.flatten().unwrap_or(1.0);
                    circle = Some((c, *r, laps));
                    e.s.drones[d].orbit(&e.airspace, [c[0], c[1]], *r, laps)
                }
                _ => 0.0,
            }
        }
        PlannedCall::Sweep { area, spacing } => match (area, spacing) {
            (Some(area), Some(spacing)) => {
                match aviary_api::coverage::sweep_lanes(area, *spacing) {
                    Ok(lanes) => sweep(e, d, &aviary_api::sweep::path(&lanes), t, &mut raises),
                    Err(_) => 0.0,
                }
            }
            (None, _) => {
                e.note(at, "an area known only in flight (a signal's value, or what a Sweep left: `drone.remaining`) is not counted: the plan assumes every Sweep finishes and leaves nothing".into());
                0.0
            }
            (Some(_), None) => 0.0,
        },
        PlannedCall::FollowPath { points, speed } => {
            follow_path(e, d, points, speed.flatten(), at, t, &mut raises)
        }
        PlannedCall::StartDetection { kind } => {
            if let Some(kind) = kind {
                start_detection(e, d, kind);
            }
            0.0
        }
        PlannedCall::StopDetection { kind } => {
            if let Some(kind) = kind {
                e.s.drones[d].detecting.retain(|(k, _, _)| k != kind);
            }
            0.0
        }
        PlannedCall::LoadPayload { .. } => LOAD_TIME,
        PlannedCall::Arm
        | PlannedCall::Disarm
        | PlannedCall::StartStreaming
        | PlannedCall::StopStreaming
        | PlannedCall::ReleasePayload => 0.0,
    };
    if e.radio && e.s.tracks[d].len() == legs && duration > 0.0 {
        // A motion not flown as legs here (an orbit, the way home): its points, in turn.
        let end = e.s.drones[d].pos;
        let mut points = vec![[before[0], before[1]]];
        if let Some((c, r, laps)) = circle {
            let n = (laps * 24.0).ceil().max(1.0) as usize;
            let start = (end[1] - c[1]).atan2(end[0] - c[0]);
            points.extend((0..=n).map(|k| {
                let a = start - laps * std::f64::consts::TAU * k as f64 / n as f64;
                [c[0] + r * a.cos(), c[1] + r * a.sin()]
            }));
        }
        points.push([end[0], end[1]]);
        record_polyline(e, d, &points, t, duration);
    }
    (duration, raises)
}

/// Keeps the legs through `points` for the radio's check, the time `took` shared by
/// their lengths.
fn record_polyline(e: &mut Estimator, d: DroneId, points: &[[f64; 2]], t: f64, took: f64) {
    let length = |a: [f64; 2], b: [f64; 2]| (b[0] - a[0]).hypot(b[1] - a[1]);
    let total: f64 = points.windows(2).map(|w| length(w[0], w[1])).sum();
    let mut at = t;
    for w in points.windows(2) {
        let share = if total > 0.0 { took * length(w[0], w[1]) / total } else { 0.0 };
        let z = e.s.drones[d].pos[2];
        e.s.tracks[d].push(Leg { t: at, took: share, from: w[0], to: w[1], z, at: e.leg_origin });
        at += share;
    }
}

/// `FlyToPosition`: one leg, at the speed asked for (at most the drone's).
fn fly_to_position(
    e: &mut Estimator,
    d: DroneId,
    pos: Option<&Place>,
    speed: Option<f64>,
    at: Option<Origin>,
    t: f64,
    raises: &mut Vec<Raise>,
) -> f64 {
    let Some(to) = e.position_arg(pos, d, at) else {
        return 0.0;
    };
    let f = &e.s.drones[d];
    let speed = speed.map_or(f.max_speed, |s| s.min(f.max_speed));
    transit(e, d, to, speed, t, raises)
}

/// `Sweep`: to its path (an area's lawnmower path, or a remainder's lanes; a transit),
/// then along it, at the altitude the drone is at.
fn sweep(e: &mut Estimator, d: DroneId, path: &[[f64; 2]], t: f64, raises: &mut Vec<Raise>) -> f64 {
    let z = e.s.drones[d].pos[2];
    let mut took = 0.0;
    for (i, p) in path.iter().enumerate() {
        let speed = e.s.drones[d].max_speed;
        let to = [p[0], p[1], z];
        took += if i == 0 {
            transit(e, d, to, speed, t + took, raises)
        } else {
            leg(e, d, to, speed, t + took, raises)
        };
    }
    took
}

/// `FollowPath`: a transit to each point that is known before the flight, at the speed
/// asked for (at most the drone's; one the flight refuses flies nothing, as there). A
/// point known only in flight is the worst case ([`Estimator::position_arg`]).
fn follow_path(
    e: &mut Estimator,
    d: DroneId,
    points: &[Option<Waypoint>],
    speed: Option<f64>,
    at: Option<Origin>,
    t: f64,
    raises: &mut Vec<Raise>,
) -> f64 {
    // A speed the flight refuses (not above 0 m/s) fails the call there: no flight here.
    let Ok(speed) = aviary_api::coverage::follow_speed(speed) else { return 0.0 };
    let max = e.s.drones[d].max_speed;
    let speed = speed.map_or(max, |s| s.min(max));
    let mut took = 0.0;
    for point in points {
        // A line of the world file (or what a FollowPath left) stands for its points.
        let places: Vec<Option<Place>> = match point {
            Some(Waypoint::Left(left)) => {
                left.path().into_iter().map(|p| Some(Place::Point(p))).collect()
            }
            Some(Waypoint::Point(p)) => vec![Some(Place::Point(*p))],
            Some(Waypoint::Area(corners)) => vec![Some(Place::Area(corners.clone()))],
            None => vec![None],
        };
        for place in &places {
            if let Some(to) = e.position_arg(place.as_ref(), d, at) {
                took += transit(e, d, to, speed, t + took, raises);
            }
        }
    }
    took
}

/// `StartDetection(kind)`: detecting `kind` at the longest range of the drone's sensors
/// that detect it (an activation of the same kind is replaced).
fn start_detection(e: &mut Estimator, d: DroneId, kind: &String) {
    let f = &e.s.drones[d];
    let range = e
        .world
        .sensors
        .iter()
        .filter(|s| f.sensors.contains(&s.kind) && s.detects.contains(kind))
        .map(|s| s.range)
        .reduce(f64::max);
    let f = &mut e.s.drones[d];
    f.detecting.retain(|(k, _, _)| k != kind);
    if let Some(range) = range {
        f.detecting.push((kind.clone(), range, Vec::new()));
    }
}

/// A transit: the legs of the planner's way around the no-fly zones (one straight leg
/// when nothing is in the way), scanning for targets on the way.
fn transit(
    e: &mut Estimator,
    d: DroneId,
    to: [f64; 3],
    speed: f64,
    t: f64,
    raises: &mut Vec<Raise>,
) -> f64 {
    let mut took = 0.0;
    for p in e.s.drones[d].way(&e.airspace, to) {
        took += leg(e, d, p, speed, t + took, raises);
    }
    took
}

/// A straight leg, scanning for targets on the way.
fn leg(
    e: &mut Estimator,
    d: DroneId,
    to: [f64; 3],
    speed: f64,
    t: f64,
    raises: &mut Vec<Raise>,
) -> f64 {
    let from = e.s.drones[d].pos;
    let took = e.s.drones[d].leg_at(to, speed);
    raises.extend(e.scan(d, [from[0], from[1]], [to[0], to[1]], t, took));
    if e.radio {
        let leg = Leg {
            t,
            took,
            from: [from[0], from[1]],
            to: [to[0], to[1]],
            z: to[2],
            at: e.leg_origin,
        };
        e.s.tracks[d].push(leg);
    }
    took
}
