//! What PX4's navigator (and, for Orbit, FlightTaskOrbit) flies in each mode, as calls to
//! the simulator made one after the other (a plan of [`Step`]s). A mode starts when it is
//! chosen armed, or when the vehicle arms in it (PX4 runs no navigator mode disarmed):
//! - Hold (AUTO.LOITER) stops where it is, or flies to DO_REPOSITION's target: from the
//!   ground it takes off first; a target under the ground is flown at straight until the
//!   vehicle touches down, which the landing detector then sees;
//! - Takeoff climbs to NAV_TAKEOFF's altitude (or MIS_TAKEOFF_ALT above where it is) and
//!   hands over to Hold;
//! - Land lands where it is; Return flies the simulator's return (up to RTL_RETURN_ALT,
//!   home, RTL_LAND_DELAY, down);
//! - Orbit climbs or descends to the centre's altitude and circles it (clockwise, at the
//!   simulator's orbit speed) until another mode;
//! - Mission flies its items in order from the current one, with PX4's climb first when
//!   it starts on the ground.

use aviary_api::{CallEnd, DroneId, Failure, Function, FunctionCall, Interrupt, Place, Point};
use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavMessage, MavSeverity, MISSION_ITEM_REACHED_DATA,
};

use super::mission::Item;
use super::{For, Nav, Reposition, Step, ALT_RADIUS, GRIPPER_TIME};
use crate::autopilot::{Autopilot, Out};

use MavSeverity::{MAV_SEVERITY_CRITICAL as CRITICAL, MAV_SEVERITY_INFO as INFO};

fn position(p: [f64; 3]) -> Place {
    Place::Point(Point { x: p[0], y: p[1], z: Some(p[2]) })
}

fn call(f: FunctionCall, doing: For) -> Step {
    Step::Call(f, doing)
}

/// `FlyToPosition(to, speed)`.
fn fly_to(to: [f64; 3], speed: f64) -> FunctionCall {
    FunctionCall::FlyToPosition { pos: position(to), speed: Some(speed) }
}

/// MAV_CMD numbers of the mission items with a position the vehicle flies to.
const WAYPOINT: u32 = 16;
const LOITER_UNLIM: u32 = 17;
const LOITER_TIME: u32 = 19;
const RETURN_TO_LAUNCH: u32 = 20;
const LAND: u32 = 21;
const TAKEOFF: u32 = 22;
const LOITER_TO_ALT: u32 = 31;
const DELAY: u32 = 93;
const CHANGE_SPEED: u32 = 178;
const GRIPPER: u32 = 211;

fn has_position(command: u32) -> bool {
    matches!(command, WAYPOINT | LOITER_UNLIM | LOITER_TIME | LAND | TAKEOFF | LOITER_TO_ALT)
}

impl Autopilot {
    /// Stops what the vehicle flies: it holds where it is.
    pub(crate) fn px4_stop(&mut self, i: usize) {
        if let Some(call) = self.copters[i].call.take() {
            self.fleet.interrupt(call, Interrupt::Abort);
        }
        let p = self.px4_mut(i);
        p.plan.clear();
        p.doing = For::Other;
        p.flying = None;
    }

    /// Starts a call to the simulator in place of the one in progress: `Ok(true)` while it
    /// goes on, `Ok(false)` when it is done already.
    fn px4_call(&mut self, i: usize, f: &FunctionCall, doing: For) -> Result<bool, Failure> {
        if let Some(call) = self.copters[i].call.take() {
            self.fleet.interrupt(call, Interrupt::Abort);
        }
        if f.function() == Function::TakeOff && !self.state(i).airborne() {
            // The simulator disarms a drone at touchdown; PX4 stays armed a while.
            let _ = self.instant(i, &FunctionCall::Arm);
        }
        self.px4_mut(i).doing = doing;
        let (call, end) = self.fleet.call(DroneId(i), f);
        match end {
            None => {
                self.copters[i].call = Some(call);
                Ok(true)
            }
            Some(CallEnd::Failed(f)) => Err(f),
            Some(_) => Ok(false),
        }
    }

    /// Flies the plan on from where it is: starts its next call, and goes through the
    /// steps that take no time.
    pub(crate) fn px4_run(&mut self, i: usize) -> Vec<Out> {
        let mut out = Vec::new();
        while self.copters[i].call.is_none() {
            let Some(step) = self.px4_mut(i).plan.pop_front() else { break };
            match step {
                Step::Call(f, doing) => {
                    let to = match &f {
                        FunctionCall::FlyToPosition { pos: Place::Point(p), .. } => {
                            Some([p.x, p.y, p.z.unwrap_or(0.0)])
                        }
                        _ => None,
                    };
                    match self.px4_call(i, &f, doing) {
                        Ok(going) => {
                            self.px4_mut(i).flying = to.filter(|_| going).map(|t| (t, doing))
                        }
                        Err(failure) => {
                            out.extend(self.px4_failed(i, &failure));
                            break;
                        }
                    }
                }
                Step::Reached(seq) => out.extend(self.px4_reached(i, seq)),
                Step::TakeoffDone => {
                    // The take-off is done in the air: Hold (COM_TAKEOFF_ACT 0).
                    if self.px4(i).nav == Nav::Takeoff
                        && self.copters[i].armed
                        && self.state(i).airborne()
                    {
                        out.extend(self.px4_change(i, Nav::Loiter, false).unwrap_or_default());
                    }
                }
            }
        }
        out
    }

    /// Starts the mode the vehicle is in (chosen armed, or armed in it).
    pub(crate) fn px4_activate(&mut self, i: usize) -> Vec<Out> {
        self.px4_stop(i);
        let nav = self.px4(i).nav;
        let mut out = Vec::new();
        match nav {
            Nav::Loiter => {
                // Hold starts at the default speed (navigator: reset_cruising_speed).
                self.px4_mut(i).cruise = None;
                if let Some(r) = self.px4_mut(i).reposition.take() {
                    self.px4_plan_reposition(i, r);
                }
            }
            Nav::Takeoff => {
                self.px4_mut(i).cruise = None;
                out.extend(self.px4_plan_takeoff(i));
            }
            Nav::Land if self.state(i).airborne() => {
                self.px4_mut(i).plan.push_back(call(FunctionCall::Land, For::Other));
            }
            Nav::Rtl => {
                self.px4_mut(i).cruise = None;
                self.px4_mut(i).rtl_landing_said = false;
                let c = &self.copters[i];
                let height = aviary_api::flight::return_height(
                    self.here(i)[2],
                    c.return_altitude,
                    self.fence.1,
                );
                let amsl = (self.origin.alt + height).ceil();
                let text = format!(
                    "RTL: start return at {} m ({} m above destination)\t",
                    amsl as i64,
                    (amsl - self.origin.alt).ceil() as i64
                );
                out.extend(self.say(i, INFO, &text));
                self.px4_mut(i).plan.push_back(call(FunctionCall::ReturnToLaunch, For::Other));
            }
            Nav::Mission => out.extend(self.px4_mission_activate(i)),
            // Orbit flies what DO_ORBIT gives it; the manual modes fly nothing here.
            _ => {}
        }
        out.extend(self.px4_run(i));
        out
    }

    /// A DO_REPOSITION for the Hold that is on: flown at once.
    pub(crate) fn px4_hold_target(&mut self, i: usize) -> Vec<Out> {
        let Some(r) = self.px4_mut(i).reposition.take() else { return Vec::new() };
        self.px4_stop(i);
        self.px4_plan_reposition(i, r);
        self.px4_run(i)
    }

    fn px4_plan_reposition(&mut self, i: usize, r: Reposition) {
        if r.pause {
            return;
        }
        let speed = r.speed.unwrap_or_else(|| self.cruise(i)).min(self.copters[i].max_speed);
        let here = self.here(i);
        let to = r.to;
        let airborne = self.state(i).airborne();
        let plan = &mut self.copters[i].px4.plan;
        if to[2] < 0.0 {
            if !airborne {
                return;
            }
            // Straight at a point under the ground: it touches down where the line meets it.
            let t = here[2] / (here[2] - to[2]);
            let ground = [here[0] + t * (to[0] - here[0]), here[1] + t * (to[1] - here[1]), 0.0];
            plan.push_back(call(fly_to(ground, speed), For::Reposition));
            plan.push_back(call(FunctionCall::Land, For::Reposition));
            return;
        }
        if !airborne {
            if to[2] <= 0.0 {
                return;
            }
            plan.push_back(call(FunctionCall::TakeOff { alt: to[2] }, For::Reposition));
        }
        plan.push_back(call(fly_to(to, speed), For::Reposition));
    }

    /// Takeoff's target (Takeoff::set_takeoff_position): NAV_TAKEOFF's altitude above sea
    /// level, or MIS_TAKEOFF_ALT above where the vehicle is; never lower than it is.
    fn px4_plan_takeoff(&mut self, i: usize) -> Vec<Out> {
        let here = self.here(i);
        let mut out = Vec::new();
        let wanted = self.px4_mut(i).takeoff_request.take().filter(|a| a.is_finite());
        let z = match wanted {
            Some(a) => f64::from(a) - self.origin.alt,
            None => {
                let alt = self.px4(i).takeoff_alt;
                out.extend(self.say(
                    i,
                    INFO,
                    &format!("Using default takeoff altitude: {alt:.1} m\t"),
                ));
                here[2] + alt
            }
        };
        let z = if z < here[2] {
            out.extend(self.say(i, CRITICAL, "Already higher than takeoff altitude\t"));
            here[2]
        } else {
            z
        };
        let plan = &mut self.copters[i].px4.plan;
        if z > here[2] + 0.01 {
            plan.push_back(call(FunctionCall::TakeOff { alt: z }, For::Other));
        }
        plan.push_back(Step::TakeoffDone);
        out
    }

    /// Flies the orbit set: to the centre's altitude, then round it, until another mode.
    /// On the ground nothing flies (FlightTaskOrbit does not take off).
    pub(crate) fn px4_fly_orbit(&mut self, i: usize) -> Vec<Out> {
        let Some(o) = self.px4(i).orbit else { return Vec::new() };
        self.px4_stop(i);
        if !self.state(i).airborne() {
            return Vec::new();
        }
        let here = self.here(i);
        let z = o.z.max(0.0);
        let plan = &mut self.copters[i].px4.plan;
        if (z - here[2]).abs() > ALT_RADIUS {
            plan.push_back(call(FunctionCall::AscendTo { alt: z }, For::Orbit));
        }
        let orbit = FunctionCall::Orbit {
            center: position([o.center[0], o.center[1], z]),
            radius: o.radius,
            // For ever, as far as a flight goes.
            laps: Some(1e6),
        };
        plan.push_back(call(orbit, For::Orbit));
        self.px4_run(i)
    }

    /// DO_CHANGE_SPEED: the flight in progress (a reposition, a mission leg) goes on at
    /// the new speed.
    pub(crate) fn px4_new_speed(&mut self, i: usize) -> Vec<Out> {
        let Some((to, doing)) = self.px4(i).flying.filter(|_| self.copters[i].call.is_some())
        else {
            return Vec::new();
        };
        let speed = self.cruise(i);
        match self.px4_call(i, &fly_to(to, speed), doing) {
            Ok(going) => {
                self.px4_mut(i).flying = going.then_some((to, doing));
                Vec::new()
            }
            Err(f) => self.px4_failed(i, &f),
        }
    }

    /// Where a mission item is, local metres (None for a frame without a place).
    pub(crate) fn px4_item_place(&self, item: &Item) -> Option<[f64; 3]> {
        let [x, y] = self.origin.from_e7(item.x, item.y);
        let z = f64::from(item.z);
        match item.frame {
            // MAV_FRAME_GLOBAL(_INT): above sea level.
            0 | 5 => Some([x, y, z - self.origin.alt]),
            // MAV_FRAME_GLOBAL_RELATIVE_ALT(_INT): above home, at the origin's altitude.
            3 | 6 => Some([x, y, z]),
            _ => None,
        }
    }

    /// Mission mode starts: "Executing Mission", a climb first where the next place to
    /// fly to is higher (Mission::handleTakeoff: a take-off on the ground), then the
    /// current item. A finished mission starts again from its first item.
    fn px4_mission_activate(&mut self, i: usize) -> Vec<Out> {
        let m = &mut self.copters[i].px4.mission;
        if m.finished {
            m.finished = false;
            m.current = 0;
            m.reached = None;
        }
        let seq = m.current;
        let mut out = self.say(i, INFO, "Executing Mission\t");
        let here = self.here(i);
        let next = self
            .px4(i)
            .mission
            .items
            .get(usize::from(seq)..)
            .unwrap_or_default()
            .iter()
            .find(|it| has_position(it.command as u32))
            .and_then(|it| self.px4_item_place(it));
        if let Some(to) = next.filter(|to| to[2] - here[2] > ALT_RADIUS) {
            out.extend(self.say(i, INFO, &format!("Climb to {:.1} meters above home\t", to[2])));
            let f = if self.state(i).airborne() {
                FunctionCall::AscendTo { alt: to[2] }
            } else {
                FunctionCall::TakeOff { alt: to[2] }
            };
            self.px4_mut(i).plan.push_back(call(f, For::Other));
        }
        out.extend(self.px4_item(i, seq));
        out
    }

    /// Plans mission item `seq`, the current one from now on.
    pub(crate) fn px4_item(&mut self, i: usize, seq: u16) -> Vec<Out> {
        let mut out = Vec::new();
        let Some(item) = self.px4(i).mission.items.get(usize::from(seq)).cloned() else {
            return out;
        };
        if self.px4(i).mission.current != seq {
            self.px4_mut(i).mission.current = seq;
            out.push(Out {
                system: self.copters[i].system,
                msg: self.px4_mission_current(i).into(),
            });
        }
        let command = item.command as u32;
        let airborne = self.state(i).airborne();
        let here = self.here(i);
        let speed = self.cruise(i);
        let place = self.px4_item_place(&item);
        let mut steps = Vec::new();
        match command {
            WAYPOINT | TAKEOFF | LOITER_TIME | LOITER_UNLIM | LOITER_TO_ALT => {
                if let Some(to) = place {
                    if !airborne && to[2] > 0.0 {
                        steps.push(call(FunctionCall::TakeOff { alt: to[2] }, For::Waypoint(seq)));
                    }
                    if airborne || to[2] > 0.0 {
                        let to = [to[0], to[1], to[2].max(0.0)];
                        steps.push(call(fly_to(to, speed), For::Waypoint(seq)));
                    }
                }
                // The time inside: WAYPOINT's param1, LOITER_TIME's.
                let inside = f64::from(item.p[0]);
                if matches!(command, WAYPOINT | LOITER_TIME) && inside > 0.0 {
                    steps.push(call(FunctionCall::Hover { duration: inside }, For::Other));
                }
                if command != LOITER_UNLIM {
                    steps.push(Step::Reached(seq));
                }
            }
            LAND => {
                if airborne {
                    let at = match place {
                        Some(to) if !(item.x == 0 && item.y == 0) => [to[0], to[1]],
                        _ => [here[0], here[1]],
                    };
                    if (at[0] - here[0]).hypot(at[1] - here[1]) > self.px4(i).nav_acc_rad {
                        let to = [at[0], at[1], here[2]];
                        steps.push(call(fly_to(to, speed), For::Waypoint(seq)));
                    }
                    steps.push(call(FunctionCall::Land, For::Other));
                }
                steps.push(Step::Reached(seq));
            }
            RETURN_TO_LAUNCH => {
                // The mission hands over to Return (the commander's NAV_RETURN_TO_LAUNCH);
                // no MISSION_ITEM_REACHED for it.
                out.extend(self.say(i, INFO, "Returning to launch\t"));
                out.extend(self.px4_change(i, Nav::Rtl, false).unwrap_or_default());
                return out;
            }
            DELAY => {
                let wait = f64::from(item.p[0]).max(0.0);
                steps.push(call(FunctionCall::Hover { duration: wait }, For::Other));
                steps.push(Step::Reached(seq));
            }
            CHANGE_SPEED => {
                let s = f64::from(item.p[1]);
                self.px4_mut(i).cruise = (s > 0.0).then_some(s);
                steps.push(Step::Reached(seq));
            }
            GRIPPER => {
                // The payload deliverer's action, and the item's wait of PD_GRIPPER_TO.
                if self.px4(i).has_gripper {
                    let grab = item.p[1].round() == 1.0;
                    let done = if grab {
                        let kind = self.copters[i].payload.clone().unwrap_or_default();
                        self.instant(i, &FunctionCall::LoadPayload { kind })
                    } else {
                        self.instant(i, &FunctionCall::ReleasePayload)
                    };
                    match done {
                        Ok(()) => self.px4_mut(i).grabbed = Some(grab),
                        Err(why) => {
                            out.extend(self.say(i, MavSeverity::MAV_SEVERITY_WARNING, &why))
                        }
                    }
                }
                steps.push(call(FunctionCall::Hover { duration: GRIPPER_TIME }, For::Other));
                steps.push(Step::Reached(seq));
            }
            // Camera, gimbal, ROI and the other DO items: done at once.
            _ => steps.push(Step::Reached(seq)),
        }
        self.px4_mut(i).plan.extend(steps);
        out
    }

    /// Item `seq` is reached: MISSION_ITEM_REACHED, then the next item, or the end of the
    /// mission ("Mission finished", and Hold in the air).
    fn px4_reached(&mut self, i: usize, seq: u16) -> Vec<Out> {
        let system = self.copters[i].system;
        self.px4_mut(i).mission.reached = Some(seq);
        let mut out = vec![Out {
            system,
            msg: MavMessage::MISSION_ITEM_REACHED(MISSION_ITEM_REACHED_DATA { seq }).into(),
        }];
        if self.px4(i).nav != Nav::Mission {
            return out;
        }
        let next = seq.saturating_add(1);
        if usize::from(next) < self.px4(i).mission.items.len() {
            out.extend(self.px4_item(i, next));
            return out;
        }
        self.px4_mut(i).mission.finished = true;
        if self.state(i).airborne() {
            out.extend(self.say(i, INFO, "Mission finished, loitering\t"));
            if self.copters[i].armed {
                out.extend(self.px4_change(i, Nav::Loiter, false).unwrap_or_default());
            }
        } else {
            out.extend(self.say(i, INFO, "Mission finished, landed\t"));
        }
        out
    }
}
