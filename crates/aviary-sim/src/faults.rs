//! The world file's `[[faults]]`: injected at their mission time (simulated seconds since
//! the fleet was made), each once. A fault whose `at` is a range `[earliest, latest]`
//! happens at a time drawn uniformly from it, from the run's seed ([`Fleet::seeded`]).
//!
//! - `battery_critical`: `BatteryCritical` (counts as the drone's one battery alarm); the
//!   charge falls to the critical level, what the drone needs to get home plus 10 % (if
//!   it had more), so that the mission reads it in `drone.battery`.
//! - `crash`: the drone falls (`DroneLost`), as when its battery runs out.
//! - `motor_failure`: `MotorFailure`; the drone makes an emergency landing where it is and
//!   refuses every later command.
//! - `link_loss` (`duration`): `ConnectionLost`; the drone holds where it is and refuses
//!   commands until the link is back, then raises `ConnectionRestored` (a signal) and takes
//!   commands again. If the link is still lost `[site] link_loss_rtl_after` seconds (default
//!   10) after it went, a drone in the air flies `ReturnToLaunch` on its own (no call: up to
//!   the return altitude, home, and down). That return goes on after the link is back,
//!   until the drone has landed or a new motion command replaces it (stopping it where it
//!   is first, as an abort does). A crash during the outage ends the drone as always.
//! - `gps_loss` (`duration`): `PositionLost`; the drone holds and refuses motion commands
//!   until the fix is back.
//!
//! Each of them ends the drone's calls in progress `Interrupted`. A fault on a lost drone
//! does nothing.

use aviary_api::trace::AutopilotAction;
use aviary_api::{BuiltinException, BuiltinSignal, DroneEvent, DroneId, FlightState};
use aviary_world::FaultKind;

use crate::args::Limits;
use crate::drone::Outage;
use crate::fleet::{Fleet, Report};
use crate::legs::return_legs;
use crate::motion::{Leg, MotionTask};

impl Fleet {
    /// Fires the faults due by `end` (in file order), and ends the outages that are over.
    pub(crate) fn fire_faults(&mut self, end: f64, out: &mut Vec<Report>) {
        for i in 0..self.faults.len() {
            let f = &mut self.faults[i];
            if f.fired || f.at > end + 1e-9 {
                continue;
            }
            f.fired = true;
            let (id, kind, at, until) = (f.drone, f.kind, f.at, f.at + f.duration);
            self.touch(id);
            if self.drones[id.0].state == FlightState::Lost {
                continue;
            }
            self.fire(id, kind, at, until, out);
        }
        self.end_outages(end, out);
        self.return_without_link(end, out);
        let drones = &self.drones;
        self.outages.retain(|&id| {
            drones[id.0]
                .rare
                .as_ref()
                .is_some_and(|r| r.link_loss.is_some() || r.gps_loss.is_some())
        });
    }

    /// One fault on drone `id`, which is not lost; a link or GPS loss lasts from `at` to
    /// `until`.
    pub(crate) fn fire(
        &mut self,
        id: DroneId,
        kind: FaultKind,
        at: f64,
        until: f64,
        out: &mut Vec<Report>,
    ) {
        let name = self.names[id].to_owned();
        match kind {
            FaultKind::BatteryCritical => {
                let capacity = self.capacity(id);
                let d = &mut self.drones[id.0];
                if d.critical_sent {
                    return;
                }
                d.critical_sent = true;
                d.low_sent = true;
                // The charge falls to the critical level: what it needs to get home plus
                // 10 % (never up), so that `drone.battery` reads what the fault says.
                d.battery = d.battery.min(crate::battery::energy_home(d) / capacity + 0.10);
                self.touch(id);
                self.fault(
                    id,
                    BuiltinException::BatteryCritical,
                    format!("{name}: battery critical (simulated fault)"),
                    out,
                );
            }
            FaultKind::Crash => self.lose(id, format!("{name} crashed (simulated fault)"), out),
            FaultKind::MotorFailure => self.motor_failure(id, &name, out),
            FaultKind::LinkLoss => {
                self.lose_link(id, at, until, format!("{name}: link lost (simulated fault)"), out)
            }
            FaultKind::GpsLoss => {
                self.fault(
                    id,
                    BuiltinException::PositionLost,
                    format!("{name}: GPS lost (simulated fault)"),
                    out,
                );
                self.drones[id.0].rare_mut().gps_loss =
                    Some(Outage { since: at, until, returned: false });
                self.outage(id);
                self.on_its_own(id, AutopilotAction::Hold, "GPS lost: holds where it is", out);
            }
        }
    }

    /// The link of drone `id` is lost from `at` to `until` (`ConnectionLost`): it holds,
    /// and returns on its own after `link_loss_rtl_after`.
    pub(crate) fn lose_link(
        &mut self,
        id: DroneId,
        at: f64,
        until: f64,
        reason: String,
        out: &mut Vec<Report>,
    ) {
        self.fault(id, BuiltinException::ConnectionLost, reason, out);
        self.drones[id.0].rare_mut().link_loss = Some(Outage { since: at, until, returned: false });
        self.outage(id);
        self.on_its_own(id, AutopilotAction::Hold, "link lost: holds where it is", out);
    }

    /// `MotorFailure`: the drone refuses every later command, and, in the air, lands
    /// where it is.
    fn motor_failure(&mut self, id: DroneId, name: &str, out: &mut Vec<Report>) {
        self.fault(
            id,
            BuiltinException::MotorFailure,
            format!("{name}: motor failure (simulated fault)"),
            out,
        );
        self.on_its_own(id, AutopilotAction::Land, "motor failure: lands where it is", out);
        let d = &mut self.drones[id.0];
        d.rare_mut().disabled = Some(format!("{name} had a motor failure"));
        if d.state.airborne() {
            let to = [d.pos[0], d.pos[1], 0.0];
            let leg = Leg::Move { to, speed: d.spec.max_speed, state: FlightState::Landing };
            d.motion = Some(Box::new(MotionTask::new(None, vec![leg])));
            d.begin_leg();
        }
    }

    /// Tells the engine what the autopilot of drone `id` does on its own after a fault,
    /// when the drone is in the air (on the ground it just stays there).
    fn on_its_own(&self, id: DroneId, action: AutopilotAction, why: &str, out: &mut Vec<Report>) {
        if self.drones[id.0].state.airborne() {
            let reason = format!("{}: {why}", &self.names[id]);
            out.push(Report::Event(DroneEvent::Autopilot { drone: id, action, reason }));
        }
    }

    /// Ends the link and GPS losses over by `end`; a drone not lost has its link back
    /// (`ConnectionRestored`). Only drones with an outage have anything to end.
    fn end_outages(&mut self, end: f64, out: &mut Vec<Report>) {
        for &id in &self.outages {
            let d = &mut self.drones[id.0];
            let Some(rare) = d.rare.as_deref_mut() else { continue };
            if rare.link_loss.as_ref().is_some_and(|o| o.until <= end + 1e-9) {
                rare.link_loss = None;
                if d.state != FlightState::Lost {
                    out.push(Report::Event(DroneEvent::Signal {
                        drone: id,
                        signal: BuiltinSignal::ConnectionRestored,
                    }));
                }
            }
            if rare.gps_loss.as_ref().is_some_and(|o| o.until <= end + 1e-9) {
                rare.gps_loss = None;
            }
        }
    }

    /// A drone whose link has been lost for `link_loss_rtl_after` by `end` returns to
    /// launch on its own, once per outage: when it is in the air, idle and able to fly.
    fn return_without_link(&mut self, end: f64, out: &mut Vec<Report>) {
        let limits = Limits {
            fence: self.fence.as_deref(),
            max_altitude: self.max_altitude,
            airspace: &self.airspace,
        };
        for &id in &self.outages {
            let d = &mut self.drones[id.0];
            let Some(outage) = d.rare.as_mut().and_then(|r| r.link_loss.as_mut()) else {
                continue;
            };
            if outage.returned || end + 1e-9 < outage.since + self.link_loss_rtl_after {
                continue;
            }
            outage.returned = true;
            self.hot[id.0].known = false;
            let on_its_own = d.state.airborne() && d.motion.is_none() && d.disabled().is_none();
            if on_its_own {
                if let Ok(legs) = return_legs(d, &self.names[id], false, &limits) {
                    d.motion = Some(Box::new(MotionTask::new(None, legs)));
                    d.begin_leg();
                    let why = format!(
                        "no link for {} s: returns to launch on its own",
                        aviary_api::show::number(self.link_loss_rtl_after)
                    );
                    self.on_its_own(id, AutopilotAction::ReturnHome, &why, out);
                }
            }
        }
    }

    /// Notes that drone `id` has an outage (the list stays ascending, without repeats).
    pub(crate) fn outage(&mut self, id: DroneId) {
        if let Err(at) = self.outages.binary_search(&id) {
            self.outages.insert(at, id);
        }
    }
}
