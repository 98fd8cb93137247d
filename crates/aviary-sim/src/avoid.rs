//! The priority planner: who gives way, and how.
//!
//! Priority is the drone's index in the world file: the first drone has the highest. Every
//! tick, before a drone moves, the planner predicts (with the drone's own motion code, in
//! steps of [`STEP`] over [`HORIZON`] seconds, straight between the points) its path and
//! the paths of the higher-priority drones near it, as they are flying now (their own
//! yields included). When the drone's path would come closer than `min_separation` to one
//! of theirs, it tries these ways to give way, in this order:
//!
//! 1. go on as planned (when yielding already: come back to its own altitude);
//! 2. when off its altitude already, go on at full speed at the altitude it is holding;
//! 3. go on at full speed at the altitude it is at now;
//! 4. slow to half speed along its path;
//! 5. stop on its path (only when every drone in the way is moving, so that waiting helps);
//! 6. pass above them, 7. below them, at full speed;
//! 8. the same two, stopped on the path until the altitude is reached.
//!
//! It takes the first one that it can fly now (the safety filter of [`crate::separation`]
//! lets the first step through) and that is clear: its predicted path keeps
//! `min_separation +` [`MARGIN`] from theirs, or, when it is that close already, never gets
//! any closer. When none is, it takes the flyable one that comes least short. A yield
//! starts when going on as planned would come closer than `min_separation`, and ends
//! when coming back keeps the margin. Passing altitudes are `min_separation +`
//! [`MARGIN`] above the highest (below the lowest) point of the drones in the way over the
//! horizon, within the site's `max_altitude` and [`FLOOR`] (and, in a world with no-fly
//! zones that hold up to a height, [`MARGIN`] above the highest of them: a drone passing
//! over such a zone must not pass below another one into it).
//!
//! A yield never changes the ground track, only the speed along it and the altitude
//! (within the climb rate and the acceleration). A leg does not end while the drone is off
//! its altitude, so a call still ends at its own target. Lower-priority drones are not
//! planned around: they give way themselves; the filter holds this drone back if one of
//! them does not get out of the way in time. A drone held back for [`STALL`] seconds
//! gives way to every drone near it, whatever their priority (their paths taken as they
//! would fly without yielding), until its yield is over: this breaks the standstills in
//! which the drone with priority is the one that has to move.

use aviary_api::geometry::{norm, norm_below};
use aviary_api::DroneId;

use crate::drone::SimDrone;
use crate::fleet::Fleet;
use crate::motion::Leg;
use crate::reach_box::{reach_box, Bounds};
use crate::separation::{clear_of, counts, Envelope};

/// Seconds of look-ahead.
pub(crate) const HORIZON: f64 = 6.0;
/// Seconds between predicted points (straight between them).
pub(crate) const STEP: f64 = 0.25;
/// Metres kept beyond `min_separation` by a yield.
pub(crate) const MARGIN: f64 = 1.0;
/// A drone does not pass below another one lower than this (metres).
pub(crate) const FLOOR: f64 = 2.0;
/// Seconds held back by the safety filter after which a drone gives way to every drone,
/// whatever their priority (this breaks the rare standstill in which the drone with
/// priority is the one that has to move).
pub(crate) const STALL: f64 = 3.0;

/// How a drone gives way.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Yield {
    /// Fraction of the path speeds flown (horizontal; vertical too when `alt` is `None`).
    pub scale: f64,
    /// Altitude flown instead of the leg's, to pass above or below.
    pub alt: Option<f64>,
    /// Altitude to come back to when the leg does not set one (a hover, an orbit, none).
    pub back_to: f64,
}

/// Predicted positions every [`STEP`]; `None` while the drone is not in the air.
pub(crate) type Track = Vec<Option<[f64; 3]>>;

/// The drone's path if it keeps flying as it does now, from now.
fn predict(d: &SimDrone) -> Track {
    let steps = (HORIZON / STEP) as usize;
    let mut ghost = d.clone();
    let mut track = vec![counts(&ghost).then_some(ghost.pos)];
    for _ in 0..steps {
        ghost.tick_motion(STEP);
        track.push(counts(&ghost).then_some(ghost.pos));
    }
    track
}

/// The drone's path one tick from now (after `dt`) on, flying `way`, and whether the
/// safety filter would let it take the first step.
pub(crate) fn predict_with(
    d: &SimDrone,
    way: Option<Yield>,
    dt: f64,
    near: &[Envelope],
    sep: f64,
) -> (Track, bool) {
    let mut ghost = d.clone();
    ghost.avoid = way;
    ghost.tick_motion(dt);
    let free = clear_of(&ghost, near, sep);
    (predict(&ghost), free)
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The smallest distance between two tracks sampled at the same times, moving straight
/// between samples.
pub(crate) fn closest(a: &Track, b: &Track) -> f64 {
    let mut best = f64::INFINITY;
    for k in 0..a.len().min(b.len()) {
        let (Some(p), Some(q)) = (a[k], b[k]) else {
            continue;
        };
        let r0 = sub(p, q);
        best = nearer(best, r0);
        if let (Some(Some(p1)), Some(Some(q1))) = (a.get(k + 1), b.get(k + 1)) {
            let r1 = sub(*p1, *q1);
            let dr = sub(r1, r0);
            let len2 = dr[0] * dr[0] + dr[1] * dr[1] + dr[2] * dr[2];
            if len2 > 0.0 {
                let t = (-(r0[0] * dr[0] + r0[1] * dr[1] + r0[2] * dr[2]) / len2).clamp(0.0, 1.0);
                best = nearer(best, [r0[0] + t * dr[0], r0[1] + t * dr[1], r0[2] + t * dr[2]]);
            }
        }
    }
    best
}

/// `best.min(norm(r))`, without the norm when `r` is clearly the longer: its sum of
/// squares beyond `best²` by far more than the rounding of either.
fn nearer(best: f64, r: [f64; 3]) -> f64 {
    let squares = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    if best < 1e140 && squares.is_finite() && squares > best * best * (1.0 + 1e-9) {
        return best;
    }
    best.min(norm(r))
}

/// The distance between two tracks at their first common point.
fn first_gap(a: &Track, b: &Track) -> f64 {
    a.iter().zip(b).find_map(|(p, q)| Some(norm(sub((*p)?, (*q)?)))).unwrap_or(f64::INFINITY)
}

/// The altitude the drone's own plan holds it at: the leg's, or where it came from.
fn own_altitude(d: &SimDrone, back_to: f64) -> f64 {
    match d.motion.as_ref().and_then(|t| t.legs.front()) {
        Some(Leg::Move { to, .. }) => to[2],
        _ => back_to,
    }
}

/// Whether the drone has somewhere to go along its path (so that slowing means something).
fn on_the_move(d: &SimDrone) -> bool {
    d.motion.as_ref().is_some_and(|t| {
        !t.paused && matches!(t.legs.front(), Some(Leg::Move { .. } | Leg::Arc { .. }))
    })
}

/// How far from drone `d` another drone can be and still matter to its planning: at
/// least `range` below for every drone of the fleet.
pub(crate) fn reach(fleet: &Fleet, d: &SimDrone) -> f64 {
    fleet.min_separation + MARGIN + HORIZON * (d.spec.fastest + fleet.fastest) + 1.0
}

impl Fleet {
    /// The predicted track of drone `j` for the planning of drone `id`: for a drone before
    /// `id`, which has moved in this step already, computed once per step. Drones after
    /// `id` (only a humble drone looks at them) have not moved yet: they are predicted
    /// afresh, going their own way as if they did not yield.
    fn track(&mut self, j: DroneId, id: DroneId) -> Track {
        let d = &self.drones[j.0];
        if j > id {
            let mut plain = d.clone();
            plain.avoid = None;
            return predict(&plain);
        }
        self.tracks.entry(j).or_insert_with(|| predict(d)).clone()
    }

    /// Chooses how drone `id` gives way this tick (see the module doc); sets its `avoid`.
    pub(crate) fn plan(&mut self, id: DroneId, dt: f64, near: &[Envelope]) {
        let d = &self.drones[id.0];
        if !d.state.airborne() {
            self.drones[id.0].avoid = None;
            return;
        }
        // A drone held back for long gives way to everyone, not only to those before it,
        // until it no longer needs to give way.
        let humble = d.humble || d.stalled >= STALL;
        let higher = self.to_give_way_to(id, humble);
        if higher.is_empty() && d.avoid.is_none() {
            self.drones[id.0].humble = false;
            return;
        }
        if d.avoid.is_none() && self.clear_ahead(id, &higher, dt) {
            // Going on as planned is clear: what the prediction below would find.
            self.drones[id.0].humble = false;
            return;
        }
        let theirs: Vec<Track> = higher.iter().map(|&j| self.track(j, id)).collect();
        let d = &self.drones[id.0];
        let judge = Judge { d, theirs: &theirs, dt, near, sep: self.min_separation };
        let current = d.avoid;
        let back_to = current.filter(|y| y.alt.is_some()).map_or(d.pos[2], |y| y.back_to);
        let nominal = coming_back(d, current, back_to);
        let first = judge.score(nominal, current.is_none());
        if first.room >= 0.0 {
            self.drones[id.0].avoid = nominal;
            self.drones[id.0].humble = humble && nominal.is_some();
            return;
        }
        let ways = self.ways_to_give_way(d, current, back_to, &theirs, &first.close);
        let way = judge.choose(ways, (first.free, first.room, nominal));
        self.drones[id.0].avoid = way;
        self.drones[id.0].humble = humble && way.is_some();
    }

    /// Whether drone `id`, going on as planned without a yield, surely keeps
    /// `min_separation` from every drone of `higher` over the horizon: the boxes they can
    /// be in ([`reach_box`], or a yielding drone's predicted track) are that far apart.
    /// Then no track need be predicted (most ticks, when drones fly apart).
    fn clear_ahead(&mut self, id: DroneId, higher: &[DroneId], dt: f64) -> bool {
        let sep = self.min_separation;
        let Some(mine) = reach_box(&self.drones[id.0], dt + HORIZON) else {
            return false;
        };
        for &j in higher {
            if self.their_box(j, id).is_some_and(|b| !mine.apart(&b, sep)) {
                return false;
            }
        }
        #[cfg(debug_assertions)]
        self.check_boxes(id, dt, mine, higher);
        true
    }

    /// Where drone `j` can be over the horizon, for the planning of drone `id`: the box
    /// of its legs, or, when it yields, of its predicted track (`None`: never in the air).
    fn their_box(&mut self, j: DroneId, id: DroneId) -> Option<Bounds> {
        match reach_box(&self.drones[j.0], HORIZON) {
            Some(b) => Some(b),
            None => Bounds::of_points(self.track(j, id).iter().flatten()),
        }
    }

    /// That the boxes [`Fleet::clear_ahead`] judged by hold the tracks the planner would
    /// have predicted (a debug build's check of [`reach_box`]'s reasoning).
    #[cfg(debug_assertions)]
    #[allow(clippy::panic)] // a debug build's own check of its reasoning: it must stop loudly
    fn check_boxes(&mut self, id: DroneId, dt: f64, mine: Bounds, higher: &[DroneId]) {
        let (track, _) = predict_with(&self.drones[id.0], None, dt, &[], self.min_separation);
        let outside = |t: &Track, b: Bounds| t.iter().flatten().find(|p| !b.holds(**p)).copied();
        if let Some(p) = outside(&track, mine) {
            panic!("drone {id} reaches {p:?} outside its box {mine:?}");
        }
        for &j in higher {
            let b = self.their_box(j, id);
            let track = self.track(j, id);
            match b {
                Some(b) => {
                    if let Some(p) = outside(&track, b) {
                        panic!("drone {j} reaches {p:?} outside its box {b:?}");
                    }
                }
                None => assert!(track.iter().all(Option::is_none), "drone {j}: no box"),
            }
        }
    }

    /// The drones `id` gives way to: those in the air before it (every other one when it is
    /// humble) that could come near it within the horizon, in index order.
    fn to_give_way_to(&self, id: DroneId, humble: bool) -> Vec<DroneId> {
        let sep = self.min_separation;
        let d = &self.drones[id.0];
        let speed = |d: &SimDrone| d.spec.fastest;
        let range = |o: &SimDrone| sep + MARGIN + HORIZON * (speed(d) + speed(o)) + 1.0;
        // Every drone that could be in range, in index order, from the sky's grid.
        let mut candidates = Vec::new();
        self.sky.around(d.xy(), d.xy(), reach(self, d), &mut candidates);
        (candidates.iter().copied())
            .filter(|&j| j < id.0 || (humble && j != id.0))
            .filter(|&j| {
                let o = &self.drones[j];
                o.state.airborne() && norm_below(sub(o.pos, d.pos), range(o))
            })
            .map(DroneId)
            .collect()
    }

    /// The ways for `d` to give way, in the order they are tried (the module doc's 2 to 8),
    /// with `close` the drones (of `theirs`) in its way.
    fn ways_to_give_way(
        &self,
        d: &SimDrone,
        current: Option<Yield>,
        back_to: f64,
        theirs: &[Track],
        close: &[usize],
    ) -> Vec<Option<Yield>> {
        let them = InTheWay::of(theirs, close);
        let held = current.and_then(|y| y.alt);
        let mut ways: Vec<Option<Yield>> = Vec::new();
        if on_the_move(d) {
            if held.is_some() {
                ways.push(Some(Yield { scale: 1.0, alt: held, back_to }));
            }
            ways.push(Some(Yield { scale: 1.0, alt: Some(d.pos[2]), back_to }));
            ways.push(Some(Yield { scale: 0.5, alt: held, back_to }));
            if them.moving {
                ways.push(Some(Yield { scale: 0.0, alt: held, back_to }));
            }
        }
        let mut levels = if close.is_empty() { Vec::new() } else { self.passing_levels(&them) };
        // Passing below already: below first.
        if held.is_some_and(|h| h < own_altitude(d, back_to)) {
            levels.reverse();
        }
        for &scale in &[1.0, 0.0] {
            for &alt in &levels {
                ways.push(Some(Yield { scale, alt: Some(alt), back_to }));
            }
        }
        ways
    }

    /// The altitudes to pass the drones in the way at: above them, then below them, each
    /// when the site's `max_altitude` (above) or [`FLOOR`] (below; higher over height-limited
    /// no-fly zones) leaves room.
    fn passing_levels(&self, them: &InTheWay) -> Vec<f64> {
        let sep = self.min_separation;
        let ceiling = self.max_altitude.unwrap_or(f64::INFINITY);
        let up = (them.top + sep + MARGIN).min(ceiling);
        // Never down into a no-fly zone that holds only up to a height: the ground track
        // may be over one (a route flies over a zone its height is above).
        let floor = self.airspace.highest_up_to().map_or(FLOOR, |top| FLOOR.max(top + MARGIN));
        let down = (them.bottom - sep - MARGIN).max(floor);
        let mut levels = Vec::new();
        if up >= them.top + sep {
            levels.push(up);
        }
        if down <= them.bottom - sep {
            levels.push(down);
        }
        levels
    }
}

/// Going on as planned: when passing above or below, back to the drone's own altitude
/// (`None` once it is there, at rest vertically).
fn coming_back(d: &SimDrone, current: Option<Yield>, back_to: f64) -> Option<Yield> {
    current.filter(|y| y.alt.is_some())?;
    let home = own_altitude(d, back_to);
    (d.pos[2] != home || d.vel[2] != 0.0).then_some(Yield { scale: 1.0, alt: Some(home), back_to })
}

/// The drones in the way, over the horizon: the highest and the lowest point they fly
/// through, and whether every one of them is going somewhere (so that waiting helps).
struct InTheWay {
    top: f64,
    bottom: f64,
    moving: bool,
}

impl InTheWay {
    /// Of the tracks `close` names among `theirs`.
    fn of(theirs: &[Track], close: &[usize]) -> InTheWay {
        let (mut top, mut bottom, mut moving) = (f64::NEG_INFINITY, f64::INFINITY, true);
        for &k in close {
            let t = &theirs[k];
            for p in t.iter().flatten() {
                top = top.max(p[2]);
                bottom = bottom.min(p[2]);
            }
            let ends: Vec<[f64; 3]> = t.iter().flatten().copied().collect();
            let still = match (ends.first(), ends.last()) {
                (Some(a), Some(b)) => norm(sub(*a, *b)) < 1.0,
                _ => false,
            };
            moving &= !still;
        }
        InTheWay { top, bottom, moving }
    }
}

/// A drone's ways to fly this tick, judged against the tracks of the drones it gives way
/// to.
struct Judge<'a> {
    d: &'a SimDrone,
    theirs: &'a [Track],
    dt: f64,
    near: &'a [Envelope],
    sep: f64,
}

/// How a way to fly does.
struct Score {
    /// How far its path keeps from theirs beyond what is needed: clear when not negative.
    room: f64,
    /// Whether the safety filter lets its first step through.
    free: bool,
    /// Which of theirs come within the margin.
    close: Vec<usize>,
}

impl Judge<'_> {
    /// Going on as planned (`strict`) needs `min_separation`; a way to give way needs the
    /// margin too, or, when the drone is that close already, never to get any closer.
    fn score(&self, way: Option<Yield>, strict: bool) -> Score {
        let sep = self.sep;
        let (mine, free) = predict_with(self.d, way, self.dt, self.near, sep);
        let mut worst = f64::INFINITY;
        let mut close = Vec::new();
        for (k, t) in self.theirs.iter().enumerate() {
            let c = closest(&mine, t);
            let need = if strict { sep } else { (sep + MARGIN).min(first_gap(&mine, t)).max(sep) };
            worst = worst.min(c - need);
            if c < sep + MARGIN {
                close.push(k);
            }
        }
        Score { room: worst, free, close }
    }

    /// The first way that is clear and can be flown now; else the one that keeps the most
    /// distance, among those that can be flown if any can. `planned` is going on as
    /// planned: whether it can be flown, its room, and the way.
    fn choose(
        &self,
        ways: Vec<Option<Yield>>,
        planned: (bool, f64, Option<Yield>),
    ) -> Option<Yield> {
        let mut best = planned;
        for way in ways {
            let Score { room, free, .. } = self.score(way, false);
            if room >= 0.0 && free {
                return way;
            }
            if (free, room) > (best.0, best.1) {
                best = (free, room, way);
            }
        }
        best.2
    }
}
