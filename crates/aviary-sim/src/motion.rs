//! Moves: a motion call becomes a queue of legs, flown one after the other, each from
//! rest to rest with the trapezoidal profile of [`crate::profile`].

use std::collections::VecDeque;
use std::f64::consts::TAU;

use aviary_api::{CallId, FlightState};

use crate::drone::{SimDrone, Spec};
use crate::geom;
use crate::profile::advance;

/// One piece of a move.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Leg {
    /// A straight line over the ground to `to[0..2]` at up to `speed`, and at the same time
    /// a vertical move to `to[2]` at up to the climb rate. `state` is the flight state
    /// while it lasts: `TakingOff` becomes `Flying` at the end, `Landing` becomes `Landed`
    /// (and disarmed).
    Move { to: [f64; 3], speed: f64, state: FlightState },
    /// Hold position for `left` seconds.
    Hold { left: f64 },
    /// `total` radians of a circle, clockwise seen from above, from angle `start`
    /// (counter-clockwise from east), at up to `speed`.
    Arc { center: [f64; 2], radius: f64, start: f64, total: f64, speed: f64 },
}

/// A motion call in progress (or, with no call, something the drone does on its own, such
/// as the emergency landing after a motor failure).
#[derive(Clone, Debug)]
pub(crate) struct MotionTask {
    pub call: Option<CallId>,
    pub legs: VecDeque<Leg>,
    pub paused: bool,
    /// Speed along the current leg over the ground, vertically, and along an arc.
    pub ground_speed: f64,
    pub climb_speed: f64,
    pub arc_speed: f64,
    /// Radians of the current arc flown.
    pub arc_done: f64,
    /// Seconds separation has held the call back without it getting nearer its goal, and
    /// the nearest it has got (see [`crate::fleet::Fleet::held_back`]).
    pub held: f64,
    pub best: Progress,
    /// For a `Sweep` or `FollowPath`: its path's points and how many the drone has
    /// reached, so that where it stops says which point it was flying to
    /// ([`SimDrone::note_stop`]).
    pub path: Option<PathTrack>,
    /// The wind at the drone this tick, `[east, north]` m/s, with `[air.wind]` (set by the
    /// fleet before each tick): it limits the speed over the ground (the wind triangle,
    /// `aviary_api::flight::ground_speed_limit`). `None`: still air, no limit but the leg's.
    pub wind: Option<[f64; 2]>,
}

/// The points of a `Sweep`'s or `FollowPath`'s path (the contract's, `aviary_api::coverage`)
/// as the drone reaches them. A leg counts when it ends at the next point: the other legs
/// of the task (a detour's corners around a no-fly zone, the way back to where a leash
/// section took the drone from) lead towards a point without being one.
#[derive(Clone, Debug)]
pub(crate) struct PathTrack {
    points: Vec<[f64; 3]>,
    reached: usize,
}

impl PathTrack {
    pub fn new(points: Vec<[f64; 3]>) -> PathTrack {
        PathTrack { points, reached: 0 }
    }

    /// The index of the point the drone flies to next (the number reached).
    pub fn next(&self) -> usize {
        self.reached
    }

    /// A leg ended at `at`.
    fn arrived(&mut self, at: [f64; 3]) {
        if self.points.get(self.reached) == Some(&at) {
            self.reached += 1;
        }
    }
}

/// How far a task is from its end: (legs left, phase, amount left on the current leg),
/// compared in that order. On a straight leg the amount is the 3-D distance to its end, on
/// an arc the length left; on a hover it is the time left (phase 1) and, once that is up,
/// the height to come back to its own altitude (phase 0).
pub(crate) type Progress = (usize, u8, f64);

impl MotionTask {
    pub fn new(call: Option<CallId>, legs: Vec<Leg>) -> MotionTask {
        MotionTask {
            call,
            legs: legs.into(),
            paused: false,
            ground_speed: 0.0,
            climb_speed: 0.0,
            arc_speed: 0.0,
            arc_done: 0.0,
            held: 0.0,
            best: (usize::MAX, u8::MAX, f64::INFINITY),
            path: None,
            wind: None,
        }
    }

    /// Brings every speed to zero (a pause, or the start of a leg).
    pub fn rest(&mut self) {
        self.ground_speed = 0.0;
        self.climb_speed = 0.0;
        self.arc_speed = 0.0;
    }
}

/// The tangential acceleration on an arc: with the centripetal part at most `a / 2`, the
/// total stays within `a`.
pub(crate) fn arc_accel(a: f64) -> f64 {
    a * 0.75f64.sqrt()
}

impl SimDrone {
    /// Sets the flight state the first leg of the task flies in.
    pub fn begin_leg(&mut self) {
        if let Some(Leg::Move { state, .. }) = self.motion.as_ref().and_then(|t| t.legs.front()) {
            self.state = *state;
        }
    }

    /// Advances the motion task by `dt`, yielding as [`SimDrone::avoid`] says. Returns the
    /// finished task, if it finished. Without a yield this is the plain move.
    pub fn tick_motion(&mut self, dt: f64) -> Option<MotionTask> {
        let Some(y) = self.avoid else {
            return self.tick_task(dt, None, false);
        };
        let vz = self.vel[2];
        let finished = self.tick_task(dt, Some(y.scale), y.alt.is_some());
        if let Some(alt) = y.alt {
            self.steer_altitude(alt, vz, dt);
        }
        finished
    }

    /// The legs of the task: speeds along the path scaled by `scale` (when yielding), and,
    /// when `owns_z`, the altitude left to [`SimDrone::steer_altitude`] and no leg ending.
    fn tick_task(&mut self, dt: f64, scale: Option<f64>, owns_z: bool) -> Option<MotionTask> {
        let Some(task) = self.motion.as_mut() else {
            self.vel = [0.0; 3];
            return None;
        };
        if task.paused {
            self.vel = [0.0; 3];
            return None;
        }
        let wind = task.wind.map(|w| (w, self.spec.max_airspeed));
        let tick = Tick { dt, scale, owns_z, wind };
        let mut body = Body { pos: &mut self.pos, vel: &mut self.vel, spec: &self.spec };
        let done = match task.legs.front_mut() {
            None => true,
            Some(Leg::Hold { left }) => {
                *body.vel = [0.0; 3];
                *left -= dt;
                *left <= 1e-9 && !owns_z
            }
            Some(&mut Leg::Move { to, speed, state }) => {
                body.straight(task, to, speed, state, tick)
            }
            Some(&mut Leg::Arc { center, radius, start, total, speed }) => {
                let left = (total - task.arc_done) * radius;
                let limit = match tick.wind {
                    None => tick.limit(speed),
                    Some(_) => {
                        let theta = start - task.arc_done;
                        tick.along([theta.sin(), -theta.cos()], speed)
                    }
                };
                let step = advance(left, task.arc_speed, limit, arc_accel(body.spec.accel), dt);
                task.arc_speed = step.speed;
                task.arc_done =
                    if step.arrived { total } else { task.arc_done + step.moved / radius };
                let theta = start - task.arc_done;
                body.pos[0] = center[0] + radius * theta.cos();
                body.pos[1] = center[1] + radius * theta.sin();
                *body.vel = [theta.sin() * step.speed, -theta.cos() * step.speed, 0.0];
                step.arrived && !owns_z
            }
        };
        if !done {
            return None;
        }
        self.next_leg()
    }

    /// Ends the task's current leg, in the flight state it leads to, and begins the next
    /// one; returns the task when that was its last leg.
    fn next_leg(&mut self) -> Option<MotionTask> {
        let task = self.motion.as_mut()?;
        let leg = task.legs.pop_front();
        if let (Some(Leg::Move { to, .. }), Some(track)) = (&leg, task.path.as_mut()) {
            track.arrived(*to);
        }
        task.rest();
        task.arc_done = 0.0;
        self.vel = [0.0; 3];
        if let Some(Leg::Move { state, .. }) = leg {
            match state {
                FlightState::TakingOff => self.state = FlightState::Flying,
                FlightState::Landing => {
                    self.state = FlightState::Landed;
                    self.armed = false;
                }
                _ => {}
            }
        }
        if task.legs.is_empty() {
            return self.motion.take().map(|task| *task);
        }
        self.begin_leg();
        None
    }
}

/// How one tick flies a task (see [`SimDrone::tick_task`]).
#[derive(Clone, Copy)]
struct Tick {
    dt: f64,
    scale: Option<f64>,
    owns_z: bool,
    /// The wind and the drone's airspeed at most (`max_airspeed`), with `[air.wind]`.
    wind: Option<([f64; 2], f64)>,
}

impl Tick {
    /// A speed limit of the path, scaled while yielding.
    fn limit(self, v: f64) -> f64 {
        self.scale.map_or(v, |s| v * s)
    }

    /// The speed limit over the ground along the unit direction `u`: the path's, and, in
    /// a wind, no more than the drone's airspeed allows that way.
    fn along(self, u: [f64; 2], v: f64) -> f64 {
        match self.wind {
            None => self.limit(v),
            Some((w, va)) => self.limit(v.min(aviary_api::flight::ground_speed_limit(u, w, va))),
        }
    }
}

/// What a leg moves: the drone's position and velocity, within its make.
struct Body<'a> {
    pos: &'a mut [f64; 3],
    vel: &'a mut [f64; 3],
    spec: &'a Spec,
}

impl Body<'_> {
    /// One tick of a straight leg to `to`: over the ground and, unless the yield owns the
    /// altitude, vertically at the same time. Returns whether both have arrived.
    fn straight(
        &mut self,
        task: &mut MotionTask,
        to: [f64; 3],
        speed: f64,
        state: FlightState,
        tick: Tick,
    ) -> bool {
        let here = [self.pos[0], self.pos[1]];
        let d = geom::dist(here, [to[0], to[1]]);
        let limit = match tick.wind {
            Some(_) if d > 0.0 => tick.along([(to[0] - here[0]) / d, (to[1] - here[1]) / d], speed),
            _ => tick.limit(speed),
        };
        let h = advance(d, task.ground_speed, limit, self.spec.accel, tick.dt);
        task.ground_speed = h.speed;
        if h.arrived {
            self.pos[0] = to[0];
            self.pos[1] = to[1];
            self.vel[0] = 0.0;
            self.vel[1] = 0.0;
        } else {
            let (ux, uy) = ((to[0] - here[0]) / d, (to[1] - here[1]) / d);
            self.pos[0] += ux * h.moved;
            self.pos[1] += uy * h.moved;
            self.vel[0] = ux * h.speed;
            self.vel[1] = uy * h.speed;
        }
        if tick.owns_z {
            task.climb_speed = 0.0;
            return false;
        }
        // Both moves every tick: the climb must not wait for the ground track.
        let climbed = self.vertical(task, to[2], state, tick);
        h.arrived && climbed
    }

    /// One tick of a straight leg's climb or descent to `to_z`; returns whether it has
    /// arrived.
    fn vertical(
        &mut self,
        task: &mut MotionTask,
        to_z: f64,
        state: FlightState,
        tick: Tick,
    ) -> bool {
        let dz = to_z - self.pos[2];
        let climb = tick.limit(vertical_limit(self.spec, self.pos[2], dz, to_z, state));
        let v = advance(dz.abs(), task.climb_speed, climb, self.spec.accel, tick.dt);
        task.climb_speed = v.speed;
        if v.arrived {
            self.pos[2] = to_z;
            self.vel[2] = 0.0;
        } else {
            self.pos[2] += dz.signum() * v.moved;
            self.vel[2] = dz.signum() * v.speed;
        }
        v.arrived
    }
}

/// The legs of `Orbit`: to the nearest point of the circle, then `laps` turns.
pub(crate) fn orbit_legs(d: &SimDrone, center: [f64; 2], radius: f64, laps: f64) -> Vec<Leg> {
    let (dx, dy) = (d.pos[0] - center[0], d.pos[1] - center[1]);
    let start = if dx == 0.0 && dy == 0.0 { 0.0 } else { dy.atan2(dx) };
    let entry = [center[0] + radius * start.cos(), center[1] + radius * start.sin(), d.level()];
    vec![
        Leg::Move { to: entry, speed: d.spec.max_speed, state: FlightState::Flying },
        Leg::Arc {
            center,
            radius,
            start,
            total: laps * TAU,
            speed: aviary_api::geometry::orbit_speed(d.spec.max_speed, d.spec.accel, radius),
        },
    ]
}

/// The vertical speed limit of a leg `dz` away from its end at `to_z`, for a drone at
/// height `z` in `state`: the take-off speed up from the ground, the climb rate up
/// otherwise, the descent rate down, and the landing speed for the last part of a landing
/// (from `slow_below` to the ground).
fn vertical_limit(spec: &Spec, z: f64, dz: f64, to_z: f64, state: FlightState) -> f64 {
    let descent = spec.descent;
    let landing = state == FlightState::Landing;
    if dz >= 0.0 && state == FlightState::TakingOff {
        spec.takeoff_speed
    } else if dz >= 0.0 {
        spec.climb_rate
    } else if landing && to_z <= 0.0 && z <= descent.slow_below + 1e-9 && descent.slows(z) {
        descent.land_speed
    } else {
        descent.rate
    }
}
