//! A scripted sky for the separation tests: several drones, each with its own list of
//! calls, stepped together while every step's telemetry is checked for separation.

use std::collections::VecDeque;

use aviary_api::{CallEnd, CallId, DroneId, Function, Telemetry, Value};
use aviary_world::World;

use super::{fc, DT};
use crate::{Fleet, Report};

/// One step of a drone's script.
#[derive(Clone, Debug)]
pub(crate) enum Act {
    /// Wait until this simulated time.
    At(f64),
    /// Call a function and wait until it is done (it must end `Done`).
    Call(Function, Vec<Value>),
}

pub(crate) fn call(f: Function, args: &[Value]) -> Act {
    Act::Call(f, args.to_vec())
}

/// What a scripted flight saw.
pub(crate) struct Flight {
    pub fleet: Fleet,
    /// Telemetry of every drone after every step.
    pub log: Vec<Vec<Telemetry>>,
    pub reports: Vec<Report>,
    /// The smallest distance between two drones in the air, over every step.
    pub closest: f64,
    /// When each drone's script ended (simulated seconds).
    pub finished: Vec<f64>,
}

/// Whether a drone counts for separation: in an airborne state and above the ground.
pub(crate) fn in_the_air(t: &Telemetry) -> bool {
    t.state.airborne() && t.position[2] > 0.0
}

/// The smallest 3-D distance between two drones in the air in one snapshot.
pub(crate) fn closest_pair(snapshot: &[Telemetry]) -> f64 {
    let mut best = f64::INFINITY;
    for (i, a) in snapshot.iter().enumerate() {
        for b in &snapshot[i + 1..] {
            if in_the_air(a) && in_the_air(b) {
                let d: f64 =
                    (0..3).map(|k| (a.position[k] - b.position[k]).powi(2)).sum::<f64>().sqrt();
                best = best.min(d);
            }
        }
    }
    best
}

/// Flies the scripts (one per drone, by index) for at most `limit` seconds, asserting after
/// every step that no two drones in the air are closer than the world's `min_separation`.
pub(crate) fn fly(world: &World, scripts: Vec<Vec<Act>>, limit: f64) -> Flight {
    let sep = world.site.min_separation;
    let mut fleet = Fleet::new(world);
    let mut todo: Vec<VecDeque<Act>> = scripts.into_iter().map(VecDeque::from).collect();
    todo.resize(fleet.len(), VecDeque::new());
    let mut waiting: Vec<Option<(CallId, Function)>> = vec![None; fleet.len()];
    let mut finished = vec![f64::NAN; fleet.len()];
    let mut log = Vec::new();
    let mut reports = Vec::new();
    let mut closest = f64::INFINITY;
    loop {
        for d in 0..fleet.len() {
            while waiting[d].is_none() {
                match todo[d].front().cloned() {
                    None => {
                        if finished[d].is_nan() {
                            finished[d] = fleet.time();
                        }
                        break;
                    }
                    Some(Act::At(t)) if fleet.time() + 1e-9 < t => break,
                    Some(Act::At(_)) => {}
                    Some(Act::Call(f, args)) => match fleet.call(DroneId(d), &fc(f, &args)) {
                        (_, Some(CallEnd::Done)) => {}
                        (_, Some(end)) => panic!("drone {d}: {f} ended {end:?}"),
                        (id, None) => waiting[d] = Some((id, f)),
                    },
                }
                todo[d].pop_front();
            }
        }
        if todo.iter().all(VecDeque::is_empty) && waiting.iter().all(Option::is_none) {
            break;
        }
        if fleet.time() >= limit {
            let stuck: Vec<String> = (0..fleet.len())
                .filter_map(|d| {
                    let (_, f) = waiting[d]?;
                    let x = &fleet.drones[d];
                    Some(format!("{d} in {f} at {:?}, yielding {:?}", x.pos, x.avoid))
                })
                .collect();
            panic!("not done within {limit} s: {stuck:#?}");
        }
        for r in fleet.step(DT) {
            if let Report::Ended { call, end } = &r {
                for (d, w) in waiting.iter_mut().enumerate() {
                    if let Some((id, f)) = *w {
                        if id == *call {
                            assert_eq!(*end, CallEnd::Done, "drone {d}: {f}");
                            *w = None;
                        }
                    }
                }
            }
            reports.push(r);
        }
        let snapshot: Vec<Telemetry> =
            (0..fleet.len()).map(|d| fleet.telemetry(DroneId(d)).unwrap()).collect();
        let c = closest_pair(&snapshot);
        assert!(
            c >= sep - 1e-9,
            "at {:.2} s two drones are {c} m apart: {snapshot:#?}",
            fleet.time()
        );
        closest = closest.min(c);
        log.push(snapshot);
    }
    Flight { fleet, log, reports, closest, finished }
}
