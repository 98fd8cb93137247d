//! Where a planned path leaves the radio's reach (W210): the legs each drone flies in the
//! estimate, followed in time, with the world's rule of who is linked (`Radio::reach`:
//! the station's range, and relays that are linked themselves), the rule the simulator
//! flies by. Only for a world with `[air.radio]`; without one nothing is recorded.

use aviary_ir::Origin;
use aviary_world::World;

/// A stretch of a drone's flight: from `from` at `t` to `to` at `t + took`, straight, for
/// the mission-level statement `at`.
#[derive(Clone, Copy, Debug)]
pub struct Leg {
    pub t: f64,
    pub took: f64,
    pub from: [f64; 2],
    pub to: [f64; 2],
    /// The height at its end (`aviary export-plan`'s waypoints).
    pub z: f64,
    pub at: Option<Origin>,
}

/// Points of a path are looked at this far apart (m) at most.
const STEP: f64 = 10.0;

/// A drone's first place out of reach during a statement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Out {
    pub drone: usize,
    pub at: Origin,
    pub t: f64,
    pub place: [f64; 2],
    /// How far it is from the station there (m).
    pub off: f64,
}

/// Where a drone is at `t`: on the leg it flies then, else where its last leg before `t`
/// ended, else at `home`.
fn position_at(track: &[Leg], home: [f64; 2], t: f64) -> [f64; 2] {
    // Legs are in time order per drone (a drone flies one thing at a time).
    let i = track.partition_point(|l| l.t <= t);
    let Some(l) = i.checked_sub(1).map(|i| &track[i]) else { return home };
    if l.took <= 0.0 || t >= l.t + l.took {
        return l.to;
    }
    let s = (t - l.t) / l.took;
    [l.from[0] + (l.to[0] - l.from[0]) * s, l.from[1] + (l.to[1] - l.from[1]) * s]
}

/// Where each drone's planned path leaves reach: the first place of each outage.
pub fn out_of_reach(world: &World, tracks: &[Vec<Leg>]) -> Vec<Out> {
    let Some(radio) = &world.air.radio else { return Vec::new() };
    let relays = world.relays();
    let homes: Vec<[f64; 2]> = world.drones.iter().map(|d| [d.home[0], d.home[1]]).collect();
    // In time order per drone (a handler walked after the branches may come earlier).
    let tracks: Vec<Vec<Leg>> = tracks
        .iter()
        .map(|tr| {
            let mut tr = tr.clone();
            tr.sort_by(|a, b| a.t.total_cmp(&b.t));
            tr
        })
        .collect();
    let (mut at, mut linked) = (Vec::with_capacity(tracks.len()), Vec::new());
    let mut found: Vec<Out> = Vec::new();
    for (d, track) in tracks.iter().enumerate() {
        // One warning per outage: where the drone first leaves reach, not again while it
        // is still out (its way back starts out of reach too).
        let mut out = false;
        for leg in track {
            let length = (leg.to[0] - leg.from[0]).hypot(leg.to[1] - leg.from[1]);
            let steps = (length / STEP).ceil().max(1.0) as usize;
            for k in 0..=steps {
                let s = k as f64 / steps as f64;
                let t = leg.t + leg.took * s;
                at.clear();
                at.extend(tracks.iter().zip(&homes).map(|(tr, &h)| Some(position_at(tr, h, t))));
                let here = [
                    leg.from[0] + (leg.to[0] - leg.from[0]) * s,
                    leg.from[1] + (leg.to[1] - leg.from[1]) * s,
                ];
                at[d] = Some(here);
                radio.reach(&relays, &at, &mut linked);
                if linked[d] {
                    out = false;
                    continue;
                }
                if !out {
                    out = true;
                    if let Some(origin) = leg.at {
                        let off = (here[0] - radio.station[0]).hypot(here[1] - radio.station[1]);
                        found.push(Out { drone: d, at: origin, t, place: here, off });
                    }
                }
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::{position_at, Leg};

    #[test]
    fn a_drone_is_on_its_leg_then_where_the_leg_ended_and_home_before_any() {
        let track = [
            Leg { t: 10.0, took: 10.0, from: [0.0, 0.0], to: [100.0, 0.0], z: 0.0, at: None },
            Leg { t: 30.0, took: 5.0, from: [100.0, 0.0], to: [100.0, 50.0], z: 0.0, at: None },
        ];
        let home = [-5.0, -5.0];
        assert_eq!(position_at(&track, home, 0.0), home);
        assert_eq!(position_at(&track, home, 15.0), [50.0, 0.0]);
        assert_eq!(position_at(&track, home, 25.0), [100.0, 0.0]);
        assert_eq!(position_at(&track, home, 32.5), [100.0, 25.0]);
        assert_eq!(position_at(&track, home, 99.0), [100.0, 50.0]);
        assert_eq!(position_at(&[], home, 5.0), home);
    }
}
