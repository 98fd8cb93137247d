//! The safety filter that keeps drones apart: every move of every tick is checked against
//! the other drones' *stopping envelopes*, and a move that would come too close is replaced
//! by braking.
//!
//! A drone's envelope is every point it could still reach if, from now on, it braked as
//! hard as it can on each axis: along its ground track (a segment ahead of it; on an orbit,
//! the tangent segment as long as the arc it needs, widened by how far the arc bends away
//! from it) times the vertical interval it needs to stop climbing or descending. Separation is 3-D Euclidean distance, and the
//! distance between two such products is `hypot(horizontal gap, vertical gap)`.
//!
//! Invariant: the envelopes of any two drones in the air ([`counts`]) are at least
//! `min_separation` apart. Drones move one at a time in world-file order; a move is kept
//! only if the drone's new envelope is clear of every other drone's (moved already this
//! tick or not), otherwise the drone brakes, and braking only shrinks its envelope. So the
//! invariant holds from tick to tick, and since every drone is inside its own envelope, no
//! two drones in the air are ever closer than `min_separation`. Stopping at once (a pause,
//! an abort, a fault, a separation timeout) also shrinks the envelope, and every new move starts at rest.
//!
//! The filter alone is safe but can stall two drones in front of each other; the planner
//! of [`crate::avoid`] makes the lower-priority one give way early.
//!
//! Neither can make room where there is none (two drones sent to the same point), so a
//! call that separation holds back for too long ends: see [`Fleet::held_back`].

use aviary_api::geometry::{hypot, norm_below};
use aviary_api::{CallEnd, DroneId, Failure, FlightState};

use crate::avoid::MARGIN;
use crate::drone::SimDrone;
use crate::fleet::{Fleet, Report};
use crate::geom::{dist, dist_to_segment};
use crate::motion::{arc_accel, Leg, MotionTask, Progress};
use crate::profile::advance;

/// Whether the drone takes part in separation: in an airborne state and off the ground. A
/// landed drone, a lost one, and one still on the ground waiting to climb do not.
pub(crate) fn counts(d: &SimDrone) -> bool {
    d.state.airborne() && d.pos[2] > 0.0
}

/// One tick of braking from `speed` at `a`: (distance moved, speed after). Stops exactly
/// at the stopping point `speed² / 2a`, so the stopping point never moves.
pub(crate) fn brake(speed: f64, a: f64, dt: f64) -> (f64, f64) {
    let after = (speed - a * dt).max(0.0);
    if after > 0.0 {
        ((speed + after) / 2.0 * dt, after)
    } else {
        (speed * speed / (2.0 * a), 0.0)
    }
}

/// Where a drone could still go if it braked hard from now on (see the module doc).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Envelope {
    /// The ground track to the stopping point.
    pub from: [f64; 2],
    pub to: [f64; 2],
    /// Width around that track (on an orbit).
    pub pad: f64,
    /// The altitudes between here and the vertical stopping point.
    pub low: f64,
    pub high: f64,
}

/// The current leg, when the task is moving along it.
fn current_leg(d: &SimDrone) -> Option<&Leg> {
    d.motion.as_ref().filter(|t| !t.paused).and_then(|t| t.legs.front())
}

pub(crate) fn envelope(d: &SimDrone) -> Envelope {
    let here = d.xy();
    let vh = hypot(d.vel[0], d.vel[1]);
    // Straight on: the stopping distance ahead. On an arc of radius r, the arc of length L
    // it needs to stop stays within L²/2r of the tangent segment of length L; and braking
    // along the arc keeps that region nested (for arcs under a right angle, which orbit
    // speeds ensure).
    let (stop, pad) = match current_leg(d) {
        _ if vh == 0.0 => (0.0, 0.0),
        Some(Leg::Arc { radius, .. }) => {
            let l = vh * vh / (2.0 * arc_accel(d.spec.accel));
            (l, l * l / (2.0 * radius))
        }
        _ => (vh * vh / (2.0 * d.spec.accel), 0.0),
    };
    let to = if vh == 0.0 {
        here
    } else {
        [here[0] + d.vel[0] / vh * stop, here[1] + d.vel[1] / vh * stop]
    };
    let z = d.pos[2];
    let stop = z + d.vel[2] * d.vel[2].abs() / (2.0 * d.spec.accel);
    Envelope { from: here, to, pad, low: z.min(stop).max(0.0), high: z.max(stop) }
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Distance between the segments `p`-`q` and `a`-`b`.
pub(crate) fn segment_gap(p: [f64; 2], q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (d1, d2) = (cross(a, b, p), cross(a, b, q));
    let (d3, d4) = (cross(p, q, a), cross(p, q, b));
    if d1 * d2 < 0.0 && d3 * d4 < 0.0 {
        return 0.0;
    }
    dist_to_segment(p, a, b)
        .min(dist_to_segment(q, a, b))
        .min(dist_to_segment(a, p, q))
        .min(dist_to_segment(b, p, q))
}

/// The smallest distance between a point of `e` and a point of `f`.
pub(crate) fn gap(e: &Envelope, f: &Envelope) -> f64 {
    let h = (segment_gap(e.from, e.to, f.from, f.to) - e.pad - f.pad).max(0.0);
    let v = (f.low - e.high).max(e.low - f.high).max(0.0);
    hypot(h, v)
}

/// How far from where it is a drone's envelope could reach after one tick (generous: on
/// each axis a tick at a higher speed, then twice the straight stopping distance, which
/// also covers the longer stop along an arc and its width).
fn reach(d: &SimDrone, dt: f64) -> f64 {
    let a = d.spec.accel;
    let grow = |v: f64| (v + a * dt) * dt + (v + a * dt).powi(2) / a;
    grow(hypot(d.vel[0], d.vel[1])) + grow(d.vel[2].abs()) + 1.0
}

/// How far a drone's envelope reaches from it.
pub(crate) fn extent(e: &Envelope) -> f64 {
    dist(e.from, e.to) + e.pad + (e.high - e.low)
}

/// At least `extent(&envelope(d))` (or NaN), without building the envelope: the stopping
/// distance stands for the track's length, widened beyond the rounding of both. Enough
/// for [`Fleet::max_extent`], which only needs to be large enough.
pub(crate) fn extent_bound(d: &SimDrone) -> f64 {
    // The square of the speed, without its root.
    let vh2 = d.vel[0] * d.vel[0] + d.vel[1] * d.vel[1];
    let (stop, pad) = match current_leg(d) {
        _ if d.vel[0] == 0.0 && d.vel[1] == 0.0 => (0.0, 0.0),
        Some(Leg::Arc { radius, .. }) => {
            let l = vh2 / (2.0 * arc_accel(d.spec.accel));
            (l, l * l / (2.0 * radius))
        }
        _ => (vh2 / (2.0 * d.spec.accel), 0.0),
    };
    let climb = (d.vel[2] * d.vel[2].abs() / (2.0 * d.spec.accel)).abs();
    let scale = 1.0 + d.pos[0].abs() + d.pos[1].abs() + d.pos[2].abs();
    (stop + pad + climb) * (1.0 + 1e-9) + 1e-9 * scale
}

/// What a move may change, to put back when the filter refuses it.
struct Snapshot {
    pos: [f64; 3],
    vel: [f64; 3],
    state: FlightState,
    armed: bool,
    motion: Option<Box<MotionTask>>,
}

impl SimDrone {
    /// Steers the altitude to `target` at up to the climb rate, from vertical speed `vz`
    /// (braking first when moving away from it).
    pub(crate) fn steer_altitude(&mut self, target: f64, vz: f64, dt: f64) {
        let dz = target - self.pos[2];
        if vz != 0.0 && (dz == 0.0 || dz.signum() != vz.signum()) {
            let (moved, after) = brake(vz.abs(), self.spec.accel, dt);
            self.pos[2] += vz.signum() * moved;
            self.vel[2] = vz.signum() * after;
        } else {
            let v = advance(dz.abs(), vz.abs(), self.spec.climb_rate, self.spec.accel, dt);
            if v.arrived {
                self.pos[2] = target;
                self.vel[2] = 0.0;
            } else {
                self.pos[2] += dz.signum() * v.moved;
                self.vel[2] = dz.signum() * v.speed;
            }
        }
        self.pos[2] = self.pos[2].max(0.0);
    }

    /// One tick of hard braking on every axis, along the path: the drone ends inside its
    /// envelope, whose stopping points do not move. No leg ends.
    pub(crate) fn brake_all(&mut self, dt: f64) {
        let (a, here, z) = (self.spec.accel, self.xy(), self.pos[2]);
        let owns_z = self.avoid.is_some_and(|y| y.alt.is_some());
        let Some(task) = self.motion.as_mut().filter(|t| !t.paused) else {
            self.vel[0] = 0.0;
            self.vel[1] = 0.0;
            self.brake_vertical(dt);
            return;
        };
        match task.legs.front() {
            Some(Leg::Move { to, .. }) => {
                let to = *to;
                let (moved, after) = brake(task.ground_speed, a, dt);
                let d = dist(here, [to[0], to[1]]);
                if moved >= d {
                    self.pos[0] = to[0];
                    self.pos[1] = to[1];
                    task.ground_speed = 0.0;
                    self.vel[0] = 0.0;
                    self.vel[1] = 0.0;
                } else {
                    let (ux, uy) = ((to[0] - here[0]) / d, (to[1] - here[1]) / d);
                    self.pos[0] += ux * moved;
                    self.pos[1] += uy * moved;
                    task.ground_speed = after;
                    self.vel[0] = ux * after;
                    self.vel[1] = uy * after;
                }
                if !owns_z {
                    let dz = to[2] - z;
                    let (moved, after) = brake(task.climb_speed, a, dt);
                    if moved >= dz.abs() {
                        self.pos[2] = to[2];
                        task.climb_speed = 0.0;
                        self.vel[2] = 0.0;
                    } else {
                        self.pos[2] += dz.signum() * moved;
                        task.climb_speed = after;
                        self.vel[2] = dz.signum() * after;
                    }
                    return;
                }
            }
            Some(Leg::Arc { center, radius, start, total, .. }) => {
                let (moved, after) = brake(task.arc_speed, arc_accel(a), dt);
                task.arc_done = (task.arc_done + moved / radius).min(*total);
                task.arc_speed = after;
                let theta = start - task.arc_done;
                self.pos[0] = center[0] + radius * theta.cos();
                self.pos[1] = center[1] + radius * theta.sin();
                self.vel[0] = theta.sin() * after;
                self.vel[1] = -theta.cos() * after;
            }
            Some(Leg::Hold { .. }) | None => {
                self.vel[0] = 0.0;
                self.vel[1] = 0.0;
            }
        }
        self.brake_vertical(dt);
    }

    fn brake_vertical(&mut self, dt: f64) {
        let vz = self.vel[2];
        let (moved, after) = brake(vz.abs(), self.spec.accel, dt);
        self.pos[2] = (self.pos[2] + vz.signum() * moved).max(0.0);
        self.vel[2] = vz.signum() * after;
    }

    fn snapshot(&self) -> Snapshot {
        Snapshot {
            pos: self.pos,
            vel: self.vel,
            state: self.state,
            armed: self.armed,
            motion: self.motion.clone(),
        }
    }

    fn restore(&mut self, s: Snapshot) {
        self.pos = s.pos;
        self.vel = s.vel;
        self.state = s.state;
        self.armed = s.armed;
        self.motion = s.motion;
    }
}

/// Whether the drone, as it is now, keeps `sep` from every envelope of `near`.
pub(crate) fn clear_of(d: &SimDrone, near: &[Envelope], sep: f64) -> bool {
    if !counts(d) {
        return true;
    }
    let mine = envelope(d);
    near.iter().all(|e| gap(&mine, e) >= sep)
}

impl Fleet {
    /// The envelopes of the other drones in the air that drone `id` could reach in a tick.
    fn near(&self, id: DroneId, dt: f64) -> Vec<Envelope> {
        let me = &self.drones[id.0];
        let (here, reach) = (me.pos, reach(me, dt));
        // The sky's grid gives every drone that could be that near, in index order.
        let mut candidates = Vec::new();
        let xy = [here[0], here[1]];
        self.sky.around(xy, xy, self.min_separation + reach + self.max_extent, &mut candidates);
        candidates
            .iter()
            .filter(|&&j| j != id.0 && counts(&self.drones[j]))
            .map(|&j| (self.drones[j].pos, envelope(&self.drones[j])))
            .filter(|(p, e)| {
                let apart = [p[0] - here[0], p[1] - here[1], p[2] - here[2]];
                norm_below(apart, self.min_separation + reach + extent(e))
            })
            .map(|(_, e)| e)
            .collect()
    }

    /// Whether no other drone of the sky is within reach of drone `id`, neither of
    /// separation (`near`) nor of the planner (`plan`), and it is giving way to nobody.
    fn alone(&mut self, id: DroneId, dt: f64) -> bool {
        let d = &self.drones[id.0];
        if d.avoid.is_some() {
            return false;
        }
        let separation = self.min_separation + reach(d, dt) + self.max_extent;
        let r = separation.max(crate::avoid::reach(self, d));
        let p = d.xy();
        if self.clearance.clear(id.0, p, r) {
            #[cfg(test)]
            self.check_clear(id.0, r);
            return true;
        }
        // The sky holds every drone of `aloft` where it is now (moved ones included).
        self.fresh_sky();
        !self.sky.any_within(p, r, id.0)
    }

    /// Moves drone `id` by one tick: the planner's choice if its envelope stays clear of
    /// every other drone in the air, else hard braking. Returns the task that finished.
    pub(crate) fn move_drone(&mut self, id: DroneId, dt: f64) -> Option<MotionTask> {
        if self.min_separation <= 0.0 || !self.drones[id.0].state.airborne() {
            self.drones[id.0].avoid = None;
            self.drones[id.0].stalled = 0.0;
            return self.drones[id.0].tick_motion(dt);
        }
        if self.alone(id, dt) {
            // What `near` and `plan` would conclude with nobody in reach: nothing to keep
            // clear of, no way to give (most drones of a large fleet, most of the time).
            let d = &mut self.drones[id.0];
            d.humble = false;
            d.stalled = 0.0;
            return d.tick_motion(dt);
        }
        self.fresh_sky();
        let near = self.near(id, dt);
        self.plan(id, dt, &near);
        if near.is_empty() {
            self.drones[id.0].stalled = 0.0;
            return self.drones[id.0].tick_motion(dt);
        }
        let saved = self.drones[id.0].snapshot();
        let finished = self.drones[id.0].tick_motion(dt);
        if clear_of(&self.drones[id.0], &near, self.min_separation) {
            self.drones[id.0].stalled = 0.0;
            return finished;
        }
        let d = &mut self.drones[id.0];
        d.restore(saved);
        d.brake_all(dt);
        d.stalled += dt;
        None
    }
}

/// A task gets nearer its end only by more than this (metres, or seconds of a hover).
const GAIN: f64 = 1e-6;

/// How far the drone's task is from its end (see [`Progress`]).
fn progress(d: &SimDrone, task: &MotionTask) -> Progress {
    let n = task.legs.len();
    match task.legs.front() {
        Some(Leg::Move { to, .. }) => {
            let gap = |k: usize| d.pos[k] - to[k];
            (n, 0, hypot(hypot(gap(0), gap(1)), gap(2)))
        }
        Some(Leg::Arc { radius, total, .. }) => (n, 0, (total - task.arc_done) * radius),
        Some(Leg::Hold { left }) if *left > 1e-9 => (n, 1, *left),
        Some(Leg::Hold { .. }) => (n, 0, (d.pos[2] - d.level()).abs()),
        None => (0, 0, 0.0),
    }
}

fn nearer(now: Progress, best: Progress) -> bool {
    (now.0, now.1) < (best.0, best.1)
        || ((now.0, now.1) == (best.0, best.1) && now.2 < best.2 - GAIN)
}

impl Fleet {
    /// After drone `id` moved by one tick (and its call did not end): counts how long
    /// separation has held its motion call back, and ends the call once that reaches
    /// `[site] separation_timeout`.
    ///
    /// *Held back* means: in this tick, separation acted on the drone (the planner had it
    /// give way, or the filter made it brake) and its task got no nearer its end than the
    /// nearest it had been (see [`Progress`]: a leg finished, or the distance, arc or hover
    /// time left on the current leg fell below its lowest value so far). Each tick that
    /// gets the task nearer than ever resets the count; so does a pause, or the drone not
    /// being airborne, and a tick in which separation did not act leaves it as it is. A
    /// yield that goes on moving along the path (slower, or above or below another drone)
    /// keeps getting nearer and is never held back; a climb or descent while stopped
    /// counts until the drone is past its nearest point again. Only calls count: a task
    /// the drone flies on its own (a return after a link loss, an emergency landing) waits
    /// as long as it takes.
    ///
    /// The call ends `Failed` with `Timeout`, naming the nearest drone in the air within
    /// `2 × min_separation + MARGIN` (the one in the way), and the drone stops at once where
    /// it is, as after an abort, and hovers (or stays on the ground, for a take-off that
    /// never left it).
    pub(crate) fn held_back(&mut self, id: DroneId, dt: f64) -> Option<Report> {
        let (sep, limit) = (self.min_separation, self.separation_timeout);
        let d = &self.drones[id.0];
        let task = d.motion.as_ref()?;
        let now = progress(d, task);
        let acted = d.stalled > 0.0 || d.avoid.is_some();
        let counting = sep > 0.0 && d.state.airborne() && task.call.is_some() && !task.paused;
        let d = &mut self.drones[id.0];
        let task = d.motion.as_mut()?;
        if !counting || nearer(now, task.best) {
            task.best = now;
            task.held = 0.0;
            return None;
        }
        if !acted {
            return None;
        }
        task.held += dt;
        if task.held < limit - 1e-9 {
            return None;
        }
        let call = task.call?;
        let d = &self.drones[id.0];
        let blocker = (self.drones.iter().enumerate())
            .filter(|&(j, o)| j != id.0 && counts(o))
            .map(|(j, o)| {
                let gap = |k: usize| o.pos[k] - d.pos[k];
                (hypot(hypot(gap(0), gap(1)), gap(2)), j)
            })
            .filter(|(apart, _)| *apart <= 2.0 * sep + MARGIN)
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map_or_else(
                || "the drones near it".to_owned(),
                |(_, j)| self.names[DroneId(j)].to_owned(),
            );
        let reason = format!("{} waited {limit} s for {blocker} to make room", &self.names[id]);
        let d = &mut self.drones[id.0];
        d.note_stop();
        d.motion = None;
        d.avoid = None;
        d.humble = false;
        d.stalled = 0.0;
        d.settle();
        Some(Report::Ended { call, end: CallEnd::Failed(Failure::separation(reason)) })
    }
}
