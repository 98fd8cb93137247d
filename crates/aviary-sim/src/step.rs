//! One step of the fleet: the faults due, then every drone in turn (in world-file order)
//! moved, held to separation, and its loading, detection and battery advanced.

use aviary_api::geometry::hypot;
use aviary_api::{
    BuiltinException, BuiltinSignal, CallEnd, DroneEvent, DroneId, Failure, FlightState,
};

use crate::battery;
use crate::drone::Rare;
use crate::fleet::{Fleet, Report};
use crate::randomness::{Purpose, Stream};
use crate::sensors::scan;
use crate::step_view::Hot;

/// Metres the drones of the sky may drift from where [`Fleet::clearance`] measured them
/// before it measures again.
const REMEASURE: f64 = 25.0;
/// How many drones ahead [`Fleet::step`] warms the caches for the leg (twice as many for
/// the task before it).
const AHEAD: usize = 6;

impl Fleet {
    /// Advances every drone by `dt` simulated seconds.
    // `!(drift <= REMEASURE)` on purpose: a NaN drift forces the rebuild.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn step(&mut self, dt: f64) -> Vec<Report> {
        let end = self.time + dt;
        let mut out = Vec::new();
        if self.air.is_some() {
            self.air_before(end, dt, &mut out);
        }
        self.fire_faults(end, &mut out);
        #[cfg(test)]
        self.check_hot();
        self.tracks.clear();
        self.aloft.clear();
        self.sky_fresh = false;
        self.max_extent = 0.0;
        let mut joined = false;
        for (id, h) in self.hot.iter_mut().enumerate() {
            // A known copy is where the drone was at its last `moved`, if a member.
            let fresh = !h.known;
            if fresh {
                *h = Hot::of(&self.drones[id]);
            }
            self.in_sky[id] = h.up;
            if !h.up {
                self.clearance.leave(id);
                continue;
            }
            self.aloft.push(id);
            joined |=
                !if fresh { self.clearance.moved(id, h.xy) } else { self.clearance.is_member(id) };
            self.max_extent = self.max_extent.max(h.extent);
        }
        if joined || !(self.clearance.drift() <= REMEASURE) {
            self.fresh_sky();
            let cap = self.clearance_cap();
            self.clearance.rebuild(&self.aloft, &self.sky, cap);
        }
        for id in 0..self.drones.len() {
            // Overlap the cache misses of the drones to come (tasks, then their legs).
            if let Some(d) = self.drones.get(id + 2 * AHEAD) {
                d.warm();
            }
            if let Some(d) = self.drones.get(id + AHEAD) {
                d.warm_leg();
            }
            if self.hot[id].idle {
                continue;
            }
            self.step_drone(DroneId(id), dt, &mut out);
            let h = Hot::of(&self.drones[id]);
            self.hot[id] = h;
            // Keep the sky current for the drones after this one.
            if self.in_sky[id] {
                if self.sky_fresh {
                    self.sky.put(id, h.xy);
                }
                self.clearance.moved(id, h.xy);
                self.max_extent = self.max_extent.max(h.extent);
            }
        }
        self.time = end;
        for report in &out {
            if let Report::Ended { call, .. } = report {
                self.calls.remove(call);
            }
        }
        out
    }

    /// Makes the sky hold every drone of `aloft` where it is now (once per step at most).
    pub(crate) fn fresh_sky(&mut self) {
        if self.sky_fresh {
            return;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for &id in &self.aloft {
            let p = self.drones[id].xy();
            (lo, hi) = ([lo[0].min(p[0]), lo[1].min(p[1])], [hi[0].max(p[0]), hi[1].max(p[1])]);
        }
        self.sky.reframe(lo, hi, self.aloft.len());
        for &id in &self.aloft {
            self.sky.put(id, self.drones[id].xy());
        }
        self.sky_fresh = true;
    }

    /// How far [`Fleet::clearance`] measures: twice the planner's longest reach, plus the
    /// drift allowed (farther gaps would tell nothing more).
    fn clearance_cap(&self) -> f64 {
        let reach = self.min_separation
            + crate::avoid::MARGIN
            + crate::avoid::HORIZON * 2.0 * self.fastest
            + 1.0;
        2.0 * reach + 2.0 * REMEASURE
    }

    fn step_drone(&mut self, id: DroneId, dt: f64, out: &mut Vec<Report>) {
        if self.drones[id.0].state == FlightState::Lost {
            return;
        }
        let airborne = self.drones[id.0].state.airborne();
        let from = self.drones[id.0].xy();
        let before = self.drones[id.0].pos;
        if self.air.is_some() {
            self.air_wind(id);
        }
        let finished = self.move_drone(id, dt);
        if finished.is_none() {
            if let Some(report) = self.held_back(id, dt) {
                out.push(report);
            }
        }
        let d = &mut self.drones[id.0];
        if let Some(task) = finished {
            if let Some(call) = task.call {
                out.push(Report::Ended { call, end: CallEnd::Done });
            }
        }
        // A call set aside for the one that just ended (or gave up) is back.
        d.bring_back();
        // The hypotenuse is at least either side: most ticks need not compute it.
        let [vx, vy, _] = d.vel;
        if vx.abs() > 1e-9 || vy.abs() > 1e-9 || hypot(vx, vy) > 1e-9 {
            d.facing = [vx, vy];
        }
        if let Some(rare) = d.rare.as_deref_mut() {
            tick_loading(rare, dt, out);
        }
        let to = d.xy();
        let moved = [d.pos[0] - before[0], d.pos[1] - before[1], d.pos[2] - before[2]];
        d.odometer += (moved[0] * moved[0] + moved[1] * moved[1] + moved[2] * moved[2]).sqrt();
        if airborne {
            d.flight_time += dt;
        }
        self.detect_along(id, from, to, out);
        self.drain_battery(id, dt, airborne, out);
        if airborne && self.air.is_some() {
            self.air_faults(id, self.time + dt, out);
        }
    }

    /// Detection along the way drone `id` flew in this tick, from `from` to `to`.
    fn detect_along(&mut self, id: DroneId, from: [f64; 2], to: [f64; 2], out: &mut Vec<Report>) {
        let d = &mut self.drones[id.0];
        // Only the targets near the way flown, in their order.
        let nearby = match d.detections().iter().map(|a| a.range).reduce(f64::max) {
            Some(range) => self.near_targets[id.0].get_or_insert_with(Box::default).around(
                &self.target_grid,
                from,
                to,
                range,
            ),
            None => &[],
        };
        if let Some(rare) = d.rare.as_deref_mut() {
            let (luck, seed) = (&mut rare.luck, self.seed);
            let mut draw = || {
                luck.get_or_insert_with(|| Box::new(Stream::new(seed, Purpose::Detection, id.0)))
                    .uniform()
            };
            let found = scan(id, &mut rare.detections, &self.targets, nearby, from, to, &mut draw);
            if !found.is_empty() {
                out.extend(found.into_iter().map(Report::Event));
            }
        }
    }

    /// The battery drained by a tick of `dt`, and the alarms it raises: `BatteryLow`,
    /// `BatteryCritical`, and a drone lost when it is empty.
    fn drain_battery(&mut self, id: DroneId, dt: f64, airborne: bool, out: &mut Vec<Report>) {
        let factor = if airborne { self.air_drain(id) } else { None };
        let d = &mut self.drones[id.0];
        let alarms = battery::drain(d, dt, airborne, factor);
        if alarms.low {
            out.push(Report::Event(DroneEvent::Signal {
                drone: id,
                signal: BuiltinSignal::BatteryLow,
            }));
        }
        if alarms.critical {
            let reason = format!(
                "{}: {:.0}% left, about what it needs to get home",
                &self.names[id],
                d.battery * 100.0
            );
            self.fault(id, BuiltinException::BatteryCritical, reason, out);
        }
        if alarms.empty {
            let reason = format!("{}: battery empty", &self.names[id]);
            self.lose(id, reason, out);
        }
    }

    /// Raises a fault on a drone and ends its calls in progress (`Interrupted`).
    pub(crate) fn fault(
        &mut self,
        id: DroneId,
        exception: BuiltinException,
        reason: String,
        out: &mut Vec<Report>,
    ) {
        out.push(Report::Event(DroneEvent::Fault {
            drone: id,
            failure: Failure::new(exception, reason),
        }));
        for call in self.drones[id.0].cut_calls() {
            out.push(Report::Ended { call, end: CallEnd::Interrupted });
        }
    }

    /// The drone falls to the ground and is gone for good (`DroneLost`).
    pub(crate) fn lose(&mut self, id: DroneId, reason: String, out: &mut Vec<Report>) {
        self.fault(id, BuiltinException::DroneLost, reason, out);
        let d = &mut self.drones[id.0];
        d.state = FlightState::Lost;
        d.avoid = None;
        d.armed = false;
        d.pos[2] = 0.0;
        d.vel = [0.0; 3];
        d.streaming = false;
        if let Some(rare) = d.rare.as_deref_mut() {
            rare.detections.clear();
        }
    }
}

/// A tick of `dt` of a payload being loaded (unless paused): done, it is carried.
fn tick_loading(rare: &mut Rare, dt: f64, out: &mut Vec<Report>) {
    if let Some(load) = rare.loading.as_mut().filter(|l| !l.paused) {
        load.left -= dt;
        if load.left <= 1e-9 {
            let call = load.call;
            rare.carrying = rare.loading.take().map(|l| l.kind);
            out.push(Report::Ended { call, end: CallEnd::Done });
        }
    }
}
