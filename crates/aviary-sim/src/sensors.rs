//! Detection: while `StartDetection(kind)` is on, every target of that kind that comes
//! within the sensor's range of the drone's ground point is reported once. A sensor with a
//! `probability` below 1 finds it only with that chance, drawn once, when the target first
//! comes within range (a target missed stays missed until detection of its kind starts
//! again); with 1, nothing is drawn.
//!
//! With `[air.detection] falloff` the chance falls with the distance `d` from the drone's
//! ground point: `p(d) = probability * falloff(d / range)`. The one number `u` drawn when
//! a target first comes within range decides, for the whole activation, the distance
//! within which it is found: the largest `d` with `p(d) > u`. So a target whose nearest
//! pass is at `d` is found with the chance `p(d)`, found where the drone comes that near,
//! and a constant falloff is the hard range of before.

use aviary_api::{DroneEvent, DroneId};
use aviary_world::{Sensor, Target};

use crate::geom::dist_to_segment;

/// One activation of detection of a kind: from a `StartDetection` to the next
/// `StartDetection` or `StopDetection` of that kind.
#[derive(Clone, Debug)]
pub(crate) struct Activation {
    pub kind: String,
    /// Metres from the drone's ground point.
    pub range: f64,
    /// The chance of finding a target that comes within range.
    pub probability: f64,
    /// The world targets (their indices, ascending) found, or missed, in this activation:
    /// few, where a flag per target would cost every drone as much memory as the world
    /// has targets.
    pub found: Vec<usize>,
    /// `[air.detection] falloff`: the chance falls with the distance, from `probability`
    /// at 0 m to the curve's value at the range.
    pub falloff: Option<std::sync::Arc<aviary_world::Falloff>>,
    /// With a falloff: the targets of `found` not yet found, each with the distance within
    /// which it will be (its draw `u` against the curve: found where
    /// `probability * falloff(d / range) > u`), ascending by target.
    pub pending: Vec<(usize, f64)>,
}

/// The range at which a drone with `sensors` detects `kind`, and the chance it finds a
/// target there: those of its sensor whose `detects` lists the kind with the largest
/// range (of equal ranges, the likeliest); `None` when none lists it.
pub(crate) fn detection_range(
    world_sensors: &[Sensor],
    sensors: &[String],
    kind: &str,
) -> Option<(f64, f64)> {
    world_sensors
        .iter()
        .filter(|s| sensors.contains(&s.kind) && s.detects.iter().any(|k| k == kind))
        .map(|s| (s.range, s.probability))
        .reduce(|a, b| if (b.0, b.1) > (a.0, a.1) { b } else { a })
}

/// The targets found while the drone flew from `from` to `to` (ground points) this tick,
/// marking them found; events in activation order, then target order. Only `candidates`
/// are looked at: ascending target indices, at least every target inside the way's box
/// widened by the range and a metre (see [`crate::nearby`]). `draw` gives a number from
/// [0, 1) of the drone's stream, for each target of a sensor that may miss it, in that order.
pub(crate) fn scan(
    drone: DroneId,
    activations: &mut [Activation],
    targets: &[Target],
    candidates: &[usize],
    from: [f64; 2],
    to: [f64; 2],
    draw: &mut dyn FnMut() -> f64,
) -> Vec<DroneEvent> {
    let mut events = Vec::new();
    if candidates.is_empty() {
        return events;
    }
    for act in activations.iter_mut() {
        // Far outside the box of the way widened by the range: out of range, without the
        // kind's string or the found list (the margin is far above rounding).
        let slack = act.range * (1.0 + 1e-9) + 1e-9;
        let (lo, hi) = (
            [from[0].min(to[0]) - slack, from[1].min(to[1]) - slack],
            [from[0].max(to[0]) + slack, from[1].max(to[1]) + slack],
        );
        for (i, target) in candidates.iter().map(|&i| (i, &targets[i])) {
            let at = [target.at[0], target.at[1]];
            if at[0] < lo[0] || at[0] > hi[0] || at[1] < lo[1] || at[1] > hi[1] {
                continue;
            }
            let place = match act.found.binary_search(&i) {
                Err(place) => place,
                Ok(_) if act.pending.is_empty() => continue,
                Ok(_) => {
                    // Drawn already: found once the drone comes within its distance.
                    let Ok(p) = act.pending.binary_search_by_key(&i, |&(t, _)| t) else {
                        continue;
                    };
                    if dist_to_segment(at, from, to) <= act.pending[p].1 {
                        act.pending.remove(p);
                        events.push(found(drone, &act.kind, at));
                    }
                    continue;
                }
            };
            if target.kind != act.kind {
                continue;
            }
            let gap = dist_to_segment(at, from, to);
            if gap <= act.range {
                act.found.insert(place, i);
                if let Some(falloff) = &act.falloff {
                    let u = draw();
                    let Some(reach) = (u < act.probability)
                        .then(|| falloff.reach(u / act.probability))
                        .flatten()
                        .map(|f| f * act.range)
                    else {
                        continue;
                    };
                    if gap > reach {
                        let p = act.pending.partition_point(|&(t, _)| t < i);
                        act.pending.insert(p, (i, reach));
                        continue;
                    }
                } else if act.probability < 1.0 && draw() >= act.probability {
                    continue;
                }
                events.push(found(drone, &act.kind, at));
            }
        }
    }
    events
}

fn found(drone: DroneId, kind: &str, at: [f64; 2]) -> DroneEvent {
    DroneEvent::Detected { drone, kind: kind.to_owned(), location: [at[0], at[1], 0.0] }
}
