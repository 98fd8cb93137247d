//! What PX4's commander (Commander.cpp), its mavlink receiver (mavlink_receiver.cpp) and
//! the modules they hand commands to (navigator, FlightTaskOrbit, payload_deliverer)
//! answer, and the commander's own doings: modes as the user's intention (any mode while
//! disarmed, only one that can run while armed), arming with its checks, the landing
//! detector's messages and the auto-disarm after landing (COM_DISARM_LAND) or without a
//! take-off (COM_DISARM_PRFLT).

// PROTOCOL_VERSION, which PX4 still answers.
#![allow(deprecated)]

use aviary_api::{Failure, FlightState, FunctionCall};
use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavCmd, MavMessage, MavResult, MavSeverity, COMMAND_ACK_DATA, PROTOCOL_VERSION_DATA,
};
use aviary_mavlink::mode::px4;

use super::{Gripper, Nav, Orbit, Reposition};
use crate::autopilot::{Autopilot, Out, Reply};
use crate::commands::{Answer, Command};

use MavResult::*;
use MavSeverity::{MAV_SEVERITY_CRITICAL as CRITICAL, MAV_SEVERITY_INFO as INFO};

/// MAV_COMP_ID_MISSIONPLANNER: PX4 says why a mode change is refused only to it.
const MISSION_PLANNER: u8 = 190;
/// ARM_DISARM's param2 that forces it.
const FORCE: i64 = 21196;

/// The mode DO_SET_MODE's base mode, main and sub mode ask for, as Commander's
/// handle_command maps them.
enum Wanted {
    /// A mode PX4 has and the simulator flies (or, for the manual ones, shows).
    Mode(Nav),
    /// A mode PX4 has that is not simulated (Offboard, Follow Target, Precision Landing,
    /// the external modes): refused as a mode that cannot run.
    NotSimulated(&'static str),
    /// AUTO with a sub mode PX4 does not know: "Unsupported auto mode".
    UnsupportedAuto,
    /// Nothing PX4 maps (another main mode, or no mode flag): accepted, nothing changes.
    Nothing,
}

fn wanted(base: u8, main: u8, sub: u8) -> Wanted {
    const CUSTOM: u8 = 1;
    const AUTO: u8 = 4;
    const GUIDED: u8 = 8;
    const STABILIZE: u8 = 16;
    const MANUAL_INPUT: u8 = 64;
    if base & CUSTOM != 0 {
        match main {
            px4::MANUAL => Wanted::Mode(Nav::Manual),
            px4::ALTCTL => Wanted::Mode(Nav::Altctl),
            // POSCTL's other sub modes (ORBIT too) are plain Position.
            px4::POSCTL if sub == px4::POSCTL_SLOW => Wanted::Mode(Nav::PositionSlow),
            px4::POSCTL => Wanted::Mode(Nav::Posctl),
            px4::AUTO => match sub {
                0 | px4::AUTO_MISSION => Wanted::Mode(Nav::Mission),
                px4::AUTO_LOITER => Wanted::Mode(Nav::Loiter),
                px4::AUTO_RTL => Wanted::Mode(Nav::Rtl),
                px4::AUTO_TAKEOFF => Wanted::Mode(Nav::Takeoff),
                px4::AUTO_LAND => Wanted::Mode(Nav::Land),
                px4::AUTO_FOLLOW_TARGET => Wanted::NotSimulated("Follow Target"),
                px4::AUTO_PRECLAND => Wanted::NotSimulated("Precision Landing"),
                px4::AUTO_EXTERNAL1..=px4::AUTO_EXTERNAL8 => Wanted::NotSimulated(
                    [
                        "External 1",
                        "External 2",
                        "External 3",
                        "External 4",
                        "External 5",
                        "External 6",
                        "External 7",
                        "External 8",
                    ][usize::from(sub - px4::AUTO_EXTERNAL1)],
                ),
                _ => Wanted::UnsupportedAuto,
            },
            px4::ACRO => Wanted::Mode(Nav::Acro),
            px4::STABILIZED => Wanted::Mode(Nav::Stab),
            px4::OFFBOARD => Wanted::NotSimulated("Offboard"),
            _ => Wanted::Nothing,
        }
    } else if base & AUTO != 0 {
        Wanted::Mode(Nav::Mission)
    } else if base & MANUAL_INPUT != 0 {
        if base & GUIDED != 0 {
            Wanted::Mode(Nav::Posctl)
        } else if base & STABILIZE != 0 {
            Wanted::Mode(Nav::Stab)
        } else {
            Wanted::Mode(Nav::Manual)
        }
    } else {
        Wanted::Nothing
    }
}

/// A parameter of a command as a float that may be NaN (C's float).
fn finite(v: f32) -> Option<f64> {
    v.is_finite().then_some(f64::from(v))
}

/// C's lroundf, for the parameters PX4 reads as integers.
fn lround(v: f32) -> i64 {
    if v.is_finite() {
        v.round() as i64
    } else {
        i64::MIN
    }
}

impl Autopilot {
    fn rejected(&self, i: usize, nav: &str) -> Vec<Out> {
        self.say(i, CRITICAL, &format!("Switching to {nav} is currently not available\t"))
    }

    /// Whether mode `nav` can run now, armed (Commander's canRun): the manual modes need
    /// sticks, Mission a mission.
    fn can_run(&self, i: usize, nav: Nav) -> bool {
        !nav.manual() && (nav != Nav::Mission || self.px4(i).mission.valid())
    }

    /// Whether the vehicle can arm in its mode now (canArm): the pre-arm checks pass, the
    /// mode can run and does not prevent arming.
    pub(crate) fn px4_can_arm(&self, i: usize) -> bool {
        let nav = self.px4(i).nav;
        self.ready() && !nav.prevents_arming() && self.can_run(i, nav)
    }

    /// The user's choice of mode (UserModeIntention::change): taken while disarmed or
    /// forced (Land), else only a mode that can run. What the new mode starts to fly
    /// comes with `Some`; `None` is a refusal.
    pub(crate) fn px4_change(&mut self, i: usize, nav: Nav, force: bool) -> Option<Vec<Out>> {
        let armed = self.copters[i].armed;
        if armed && !force && !self.can_run(i, nav) {
            return None;
        }
        let p = self.px4_mut(i);
        if !nav.prevents_arming() {
            p.after_disarm = nav;
        }
        Some(self.px4_enter(i, nav))
    }

    /// Switches to `nav` (the user's choice, or a failsafe's): the navigator starts it when
    /// it changes, armed.
    pub(crate) fn px4_enter(&mut self, i: usize, nav: Nav) -> Vec<Out> {
        let changed = self.px4(i).nav != nav;
        self.px4_mut(i).nav = nav;
        self.copters[i].mode = nav.custom_mode();
        if changed && self.copters[i].armed {
            self.px4_activate(i)
        } else {
            Vec::new()
        }
    }

    /// MAV_CMD_DO_SET_MODE (and SET_MODE, which PX4 turns into it).
    pub(crate) fn px4_set_mode(
        &mut self,
        i: usize,
        base: u8,
        main: u8,
        sub: u8,
        from: (u8, u8),
    ) -> Answer {
        let nav = match wanted(base, main, sub) {
            Wanted::Nothing => return Answer::of(MAV_RESULT_ACCEPTED),
            Wanted::UnsupportedAuto => {
                return self.px4_answer(
                    i,
                    MAV_RESULT_TEMPORARILY_REJECTED,
                    "Unsupported auto mode\t",
                )
            }
            Wanted::NotSimulated(name) => {
                let mut a = Answer::of(MAV_RESULT_TEMPORARILY_REJECTED);
                a.before = self.rejected(i, name).into_iter().map(Reply::all).collect();
                return a;
            }
            Wanted::Mode(nav) => nav,
        };
        // LAND is always taken, to be there in an emergency.
        match self.px4_change(i, nav, nav == Nav::Land) {
            Some(out) => after(Answer::of(MAV_RESULT_ACCEPTED), out),
            None => {
                let mut a = Answer::of(MAV_RESULT_TEMPORARILY_REJECTED);
                if from.1 == MISSION_PLANNER {
                    a.before = self.rejected(i, nav.name()).into_iter().map(Reply::all).collect();
                }
                a
            }
        }
    }

    /// A result with a critical STATUSTEXT before it.
    fn px4_answer(&self, i: usize, result: MavResult, why: &str) -> Answer {
        let mut a = Answer::of(result);
        a.before = self.say(i, CRITICAL, why).into_iter().map(Reply::all).collect();
        a
    }

    /// Commander::arm: refused by the pre-arm checks (before the GPS fix PX4 names the
    /// GPS first) and in a mode that cannot arm. `Err` has PX4's words.
    pub(crate) fn px4_arm(&mut self, i: usize, by: &str) -> Result<Vec<Out>, Vec<Out>> {
        if self.copters[i].armed {
            return Ok(Vec::new());
        }
        if !self.px4_can_arm(i) {
            let mut out = Vec::new();
            if !self.ready() {
                out.extend(self.say(i, CRITICAL, "Preflight Fail: GPS fix too low"));
            }
            out.extend(self.say(
                i,
                CRITICAL,
                "Arming denied: Resolve system health failures first\t",
            ));
            return Err(out);
        }
        if let Err(why) = self.instant(i, &FunctionCall::Arm) {
            return Err(self.say(i, CRITICAL, &why));
        }
        let now = self.fleet.time();
        let c = &mut self.copters[i];
        c.armed = true;
        c.px4.armed_at = now;
        c.px4.taken_off = false;
        c.px4.landed_at = None;
        c.px4.was_airborne = false;
        let mut out = self.say(i, INFO, &format!("Armed by {by}\t"));
        // PX4 sets home where it arms (COM_HOME_EN); the simulator's home does not move,
        // so the same home is sent again.
        if let Some(home) = self.home_position(i) {
            out.push(Out { system: self.copters[i].system, msg: home.into() });
        }
        out.extend(self.px4_activate(i));
        Ok(out)
    }

    /// Commander::disarm: on the ground (a forced disarm, which in the air would stop the
    /// motors, is refused there too: not simulated).
    pub(crate) fn px4_disarm(&mut self, i: usize, by: &str) -> Result<Vec<Out>, Vec<Out>> {
        if !self.copters[i].armed {
            return Ok(Vec::new());
        }
        if self.state(i).airborne() {
            return Err(self.say(i, CRITICAL, "Disarming denied: not landed\t"));
        }
        self.px4_stop(i);
        let _ = self.instant(i, &FunctionCall::Disarm);
        let c = &mut self.copters[i];
        c.armed = false;
        c.failsafe = false;
        c.px4.taken_off = false;
        c.px4.landed_at = None;
        c.px4.reposition = None;
        c.px4.orbit = None;
        // Back to the mode chosen last that allows arming.
        let nav = c.px4.after_disarm;
        c.px4.nav = nav;
        c.mode = nav.custom_mode();
        Ok(self.say(i, INFO, &format!("Disarmed by {by}\t")))
    }

    /// One command to vehicle `i` from `from`, as PX4 answers it.
    pub(crate) fn px4_command(&mut self, i: usize, c: &Command, from: (u8, u8)) -> Answer {
        let system = self.copters[i].system;
        let p = c.p;
        match c.id {
            MavCmd::MAV_CMD_DO_SET_MODE => {
                self.px4_set_mode(i, p[0] as u8, p[1] as u8, p[2] as u8, from)
            }
            MavCmd::MAV_CMD_COMPONENT_ARM_DISARM => match lround(p[0]) {
                1 => match self.px4_arm(i, "external command") {
                    Ok(out) => after(Answer::of(MAV_RESULT_ACCEPTED), out),
                    Err(out) => before(Answer::of(MAV_RESULT_TEMPORARILY_REJECTED), out),
                },
                0 => {
                    let _forced = lround(p[1]) == FORCE;
                    match self.px4_disarm(i, "external command") {
                        Ok(out) => after(Answer::of(MAV_RESULT_ACCEPTED), out),
                        Err(out) => before(Answer::of(MAV_RESULT_TEMPORARILY_REJECTED), out),
                    }
                }
                // PX4 says so and leaves the command unanswered.
                _ => {
                    let why = format!("Unsupported ARM_DISARM param: {:.3}\t", p[0]);
                    before(Answer::none(), self.say(i, CRITICAL, &why))
                }
            },
            MavCmd::MAV_CMD_NAV_TAKEOFF => {
                // The navigator keeps the altitude whatever the commander decides.
                self.px4_mut(i).takeoff_request = Some(p[6]);
                let was = self.px4(i).nav;
                match self.px4_change(i, Nav::Takeoff, false) {
                    Some(mut out) => {
                        if was == Nav::Takeoff && self.copters[i].armed {
                            out.extend(self.px4_activate(i));
                        }
                        after(Answer::of(MAV_RESULT_ACCEPTED), out)
                    }
                    None => self.refused_mode(i, Nav::Takeoff),
                }
            }
            MavCmd::MAV_CMD_NAV_LAND => match self.px4_change(i, Nav::Land, true) {
                Some(out) => {
                    let mut said = self.say(i, INFO, "Landing at current position\t");
                    said.extend(out);
                    after(Answer::of(MAV_RESULT_ACCEPTED), said)
                }
                None => self.refused_mode(i, Nav::Land),
            },
            MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH => match self.px4_change(i, Nav::Rtl, false) {
                Some(out) => {
                    let mut said = self.say(i, INFO, "Returning to launch\t");
                    said.extend(out);
                    after(Answer::of(MAV_RESULT_ACCEPTED), said)
                }
                None => self.refused_mode(i, Nav::Rtl),
            },
            MavCmd::MAV_CMD_DO_REPOSITION => self.px4_reposition(i, c),
            MavCmd::MAV_CMD_DO_CHANGE_ALTITUDE => {
                let r = self.armed_target(i, (None, None), finite(p[0]), None);
                self.px4_mut(i).reposition = r;
                self.hold_with_target(i)
            }
            MavCmd::MAV_CMD_DO_CHANGE_SPEED => {
                // The navigator's cruise speed (a ground speed > 0, else the default), which
                // the flight in progress takes at once (FlightModeManager).
                let speed = finite(p[1]).filter(|s| *s > f64::from(f32::EPSILON));
                self.px4_mut(i).cruise = speed;
                let out = self.px4_new_speed(i);
                after(Answer::of(MAV_RESULT_ACCEPTED), out)
            }
            MavCmd::MAV_CMD_DO_ORBIT => self.px4_orbit(i, c),
            MavCmd::MAV_CMD_MISSION_START => self.px4_mission_start(i, p[0]),
            MavCmd::MAV_CMD_DO_GRIPPER => self.px4_gripper(i, p[1], from),
            MavCmd::MAV_CMD_DO_FLIGHTTERMINATION => Answer::of(MAV_RESULT_DENIED),
            // The simulator's home does not move.
            MavCmd::MAV_CMD_DO_SET_HOME => Answer::of(MAV_RESULT_DENIED),
            MavCmd::MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN if lround(p[0]) == 0 => {
                Answer::of(MAV_RESULT_ACCEPTED)
            }
            MavCmd::MAV_CMD_PREFLIGHT_REBOOT_SHUTDOWN => Answer::of(MAV_RESULT_DENIED),
            MavCmd::MAV_CMD_RUN_PREARM_CHECKS
            | MavCmd::MAV_CMD_DO_SET_ROI
            | MavCmd::MAV_CMD_NAV_ROI
            | MavCmd::MAV_CMD_DO_SET_ROI_LOCATION
            | MavCmd::MAV_CMD_DO_SET_ROI_WPNEXT_OFFSET
            | MavCmd::MAV_CMD_DO_SET_ROI_NONE
            | MavCmd::MAV_CMD_DO_GO_AROUND => Answer::of(MAV_RESULT_ACCEPTED),
            // The mavlink module answers these itself: the message, then the ACK.
            MavCmd::MAV_CMD_GET_HOME_POSITION => self.px4_send(i, self.home_position(i)),
            MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES => {
                self.px4_send(i, Some(self.autopilot_version(i)))
            }
            MavCmd::MAV_CMD_REQUEST_PROTOCOL_VERSION => self.px4_send(i, Some(protocol_version())),
            MavCmd::MAV_CMD_REQUEST_MESSAGE => {
                let id = p[0].round() as u32;
                let msg = if id == 300 { Some(protocol_version()) } else { self.message(i, id) };
                self.px4_send(i, msg)
            }
            // Handled by modules the simulator does not have: nobody answers.
            MavCmd::MAV_CMD_DO_MOUNT_CONTROL
            | MavCmd::MAV_CMD_DO_MOUNT_CONFIGURE
            | MavCmd::MAV_CMD_DO_DIGICAM_CONTROL
            | MavCmd::MAV_CMD_DO_TRIGGER_CONTROL
            | MavCmd::MAV_CMD_DO_SET_CAM_TRIGG_DIST
            | MavCmd::MAV_CMD_DO_SET_CAM_TRIGG_INTERVAL
            | MavCmd::MAV_CMD_SET_CAMERA_MODE
            | MavCmd::MAV_CMD_SET_CAMERA_ZOOM
            | MavCmd::MAV_CMD_SET_CAMERA_FOCUS
            | MavCmd::MAV_CMD_DO_VTOL_TRANSITION
            | MavCmd::MAV_CMD_DO_LAND_START
            | MavCmd::MAV_CMD_LOGGING_START
            | MavCmd::MAV_CMD_LOGGING_STOP
            | MavCmd::MAV_CMD_NAV_DELAY
            | MavCmd::MAV_CMD_DO_WINCH
            | MavCmd::MAV_CMD_DO_GIMBAL_MANAGER_PITCHYAW
            | MavCmd::MAV_CMD_DO_GIMBAL_MANAGER_CONFIGURE
            | MavCmd::MAV_CMD_DO_SET_ACTUATOR
            | MavCmd::MAV_CMD_REQUEST_CAMERA_INFORMATION => Answer::none(),
            _ => {
                let _ = system;
                Answer::of(MAV_RESULT_UNSUPPORTED)
            }
        }
    }

    /// A message the mavlink module sends on request, then ACCEPTED; DENIED for one it
    /// does not have.
    fn px4_send(&self, i: usize, msg: Option<MavMessage>) -> Answer {
        let system = self.copters[i].system;
        match msg {
            Some(m) => {
                Answer { before: vec![Reply::asker(system, m)], ..Answer::of(MAV_RESULT_ACCEPTED) }
            }
            None => Answer::of(MAV_RESULT_DENIED),
        }
    }

    fn refused_mode(&self, i: usize, nav: Nav) -> Answer {
        let mut a = Answer::of(MAV_RESULT_TEMPORARILY_REJECTED);
        a.before = self.rejected(i, nav.name()).into_iter().map(Reply::all).collect();
        a
    }

    /// The switch to Hold of DO_REPOSITION and DO_CHANGE_ALTITUDE, with the target the
    /// navigator kept: a Hold already on flies to it at once.
    fn hold_with_target(&mut self, i: usize) -> Answer {
        let was = self.px4(i).nav;
        match self.px4_change(i, Nav::Loiter, false) {
            Some(mut out) => {
                if was == Nav::Loiter {
                    out.extend(self.px4_hold_target(i));
                }
                self.px4_mut(i).reposition = None;
                after(Answer::of(MAV_RESULT_ACCEPTED), out)
            }
            None => {
                self.px4_mut(i).reposition = None;
                self.refused_mode(i, Nav::Loiter)
            }
        }
    }

    /// The target the navigator takes from DO_REPOSITION's latitude, longitude and
    /// altitude above sea level (each NaN: where the vehicle is; all three: stop), only
    /// armed ("it otherwise won't get executed", navigator_main.cpp).
    fn armed_target(
        &self,
        i: usize,
        (lat, lon): (Option<f64>, Option<f64>),
        alt: Option<f64>,
        speed: Option<f64>,
    ) -> Option<Reposition> {
        if !self.copters[i].armed {
            return None;
        }
        let here = self.here(i);
        let p = self.px4(i);
        let z = alt.map_or(here[2], |a| a - self.origin.alt);
        // A latitude or longitude off the Earth (a COMMAND_LONG's float can be anything)
        // is no place: the vehicle holds where it is.
        let on_earth = |lat: f64, lon: f64| lat.abs() <= 90.0 && lon.abs() <= 180.0;
        let (lat, lon) = match (lat, lon) {
            (Some(a), Some(o)) if !on_earth(a, o) => (None, None),
            other => other,
        };
        let to = match (lat, lon) {
            (Some(lat), Some(lon)) => {
                let [x, y] = self.origin.to_local(lat, lon);
                [x, y, z]
            }
            // Only the altitude: the current setpoint's place, or here.
            _ => {
                let xy = p.reposition.map_or([here[0], here[1]], |r| [r.to[0], r.to[1]]);
                [xy[0], xy[1], z]
            }
        };
        let pause = lat.is_none() && lon.is_none() && alt.is_none();
        Some(Reposition { to: if pause { here } else { to }, speed, pause })
    }

    /// MAV_CMD_DO_REPOSITION, as COMMAND_INT or COMMAND_LONG: PX4 takes both alike, and
    /// COMMAND_INT's frame is not read (mavlink_receiver.cpp copies z into param7, and the
    /// navigator takes param7 as the altitude above sea level): an altitude above home
    /// in MAV_FRAME_GLOBAL_RELATIVE_ALT is flown as one above sea level.
    fn px4_reposition(&mut self, i: usize, c: &Command) -> Answer {
        let p = c.p;
        let (lat, lon, alt) = match c.int {
            Some((_, x, y, z)) if x == i32::MAX && y == i32::MAX => (None, None, finite(z)),
            Some((_, x, y, z)) => (Some(f64::from(x) / 1e7), Some(f64::from(y) / 1e7), finite(z)),
            None => (finite(p[4]), finite(p[5]), finite(p[6])),
        };
        let speed = finite(p[0]).filter(|s| *s > 0.0);
        let r = self.armed_target(i, (lat, lon), alt, speed);
        self.px4_mut(i).reposition = r;
        let flags = if p[1].is_finite() && p[1] >= 0.0 { p[1] as u32 } else { 0 };
        if flags & 1 == 0 || flags & !1 != 0 {
            // No mode change asked: UNSUPPORTED, but a Hold on (and armed) flies to it.
            let mut out = Vec::new();
            if self.px4(i).nav == Nav::Loiter {
                out = self.px4_hold_target(i);
            }
            self.px4_mut(i).reposition = None;
            return after(Answer::of(MAV_RESULT_UNSUPPORTED), out);
        }
        self.hold_with_target(i)
    }

    /// MAV_CMD_DO_ORBIT: Orbit mode (POSCTL ORBIT), which FlightTaskOrbit flies armed:
    /// param1 the radius (1 to MC_ORBIT_RAD_MAX; its sign the direction, positive
    /// clockwise), param2 the speed, param3 the yaw behaviour, lat/lon the centre (NaN:
    /// where it is when the orbit starts), param7 the centre's altitude above sea level.
    fn px4_orbit(&mut self, i: usize, c: &Command) -> Answer {
        let was = self.px4(i).nav;
        let Some(mut out) = self.px4_change(i, Nav::Orbit, false) else {
            return self.px4_answer(i, MAV_RESULT_TEMPORARILY_REJECTED, "Orbit command rejected");
        };
        if self.copters[i].armed && self.px4(i).nav == Nav::Orbit {
            let p = c.p;
            let here = self.here(i);
            let mut orbit = match (was, self.px4(i).orbit) {
                (Nav::Orbit, Some(o)) => o,
                _ => Orbit { center: [here[0], here[1]], z: here[2], radius: 1.0 },
            };
            let mut ok = true;
            if let Some(r) = finite(p[0]) {
                if (1.0..=1000.0).contains(&r.abs()) {
                    orbit.radius = r.abs();
                } else {
                    ok = false;
                }
            }
            let center = match c.int {
                Some((_, x, y, _)) if x == i32::MAX && y == i32::MAX => None,
                Some((_, x, y, _)) => Some((f64::from(x) / 1e7, f64::from(y) / 1e7)),
                None => finite(p[4]).zip(finite(p[5])),
            };
            if let Some((lat, lon)) = center.filter(|(a, o)| a.abs() <= 90.0 && o.abs() <= 180.0) {
                orbit.center = self.origin.to_local(lat, lon);
            }
            let alt = match c.int {
                Some((_, _, _, z)) => finite(z),
                None => finite(p[6]),
            };
            if let Some(alt) = alt {
                orbit.z = alt - self.origin.alt;
            }
            self.px4_mut(i).orbit = Some(orbit);
            if ok {
                out.extend(self.px4_fly_orbit(i));
            } else {
                // FlightModeManager's failsafe task: it stops where it is.
                self.px4_stop(i);
                out.extend(self.say(i, CRITICAL, "Orbit radius limit exceeded\t"));
            }
        }
        after(Answer::of(MAV_RESULT_ACCEPTED), out)
    }

    /// MAV_CMD_MISSION_START: DENIED without a mission or for a first item out of it;
    /// else Mission mode, armed (PX4 arms for it).
    fn px4_mission_start(&mut self, i: usize, first: f32) -> Answer {
        if !self.px4(i).mission.valid() {
            return self.px4_answer(
                i,
                MAV_RESULT_DENIED,
                "Mission start denied! No valid mission\t",
            );
        }
        let count = self.px4(i).mission.items.len();
        if !(first.is_finite() && first >= -1.0 && (first as f64) < count as f64) {
            return Answer::of(MAV_RESULT_DENIED);
        }
        let mut out = Vec::new();
        if first >= 0.0 {
            out = self.px4_set_current(i, first as u16);
        }
        let Some(more) = self.px4_change(i, Nav::Mission, false) else {
            return self.refused_mode(i, Nav::Mission);
        };
        out.extend(more);
        match self.px4_arm(i, "mission start") {
            Ok(more) => {
                out.extend(more);
                after(Answer::of(MAV_RESULT_ACCEPTED), out)
            }
            Err(more) => {
                out.extend(more);
                out.extend(self.rejected(i, Nav::Mission.name()));
                before(Answer::of(MAV_RESULT_TEMPORARILY_REJECTED), out)
            }
        }
    }

    /// MAV_CMD_DO_GRIPPER as PX4's payload_deliverer answers it (PD_GRIPPER_EN, on when
    /// the world gives the drone a payload; off, PX4 does not start it and nobody
    /// answers): IN_PROGRESS, then ACCEPTED after PD_GRIPPER_TO; ACCEPTED at once when the
    /// gripper is there already; the same action again while it moves
    /// TEMPORARILY_REJECTED; another cancels it. Grabbing loads the world's payload,
    /// releasing drops it; where the simulator cannot (loading above 5 m, nothing to
    /// drop), FAILED with its reason.
    fn px4_gripper(&mut self, i: usize, action: f32, from: (u8, u8)) -> Answer {
        if !self.px4(i).has_gripper {
            return Answer::none();
        }
        let system = self.copters[i].system;
        let grab = match lround(action) {
            1 => true,
            0 => false,
            _ => return Answer::of(MAV_RESULT_DENIED),
        };
        let mut a = Answer::of(MAV_RESULT_IN_PROGRESS);
        if let Some(g) = self.px4(i).gripper {
            if g.grab == grab {
                return Answer::of(MAV_RESULT_TEMPORARILY_REJECTED);
            }
            a.before.push(Reply::all(gripper_ack(system, MAV_RESULT_CANCELLED, g.asker)));
            self.px4_mut(i).gripper = None;
        }
        if self.px4(i).grabbed == Some(grab) {
            a.result = MAV_RESULT_ACCEPTED;
            return a;
        }
        let done = if grab {
            let kind = self.copters[i].payload.clone().unwrap_or_default();
            self.instant(i, &FunctionCall::LoadPayload { kind })
        } else {
            self.instant(i, &FunctionCall::ReleasePayload)
        };
        if let Err(why) = done {
            a.result = MAV_RESULT_FAILED;
            a.before.extend(
                self.say(i, MavSeverity::MAV_SEVERITY_WARNING, &why).into_iter().map(Reply::all),
            );
            return a;
        }
        let until = self.fleet.time() + super::GRIPPER_TIME;
        self.px4_mut(i).gripper = Some(Gripper { grab, asker: from, until });
        a.progress = u8::MAX;
        a
    }

    /// PX4's battery failsafe at a critical battery (COM_LOW_BAT_ACT 3): "Failsafe
    /// activated", Return, HEARTBEAT CRITICAL.
    pub(crate) fn px4_battery_failsafe(&mut self, i: usize) -> Vec<Out> {
        self.copters[i].failsafe = true;
        let mut out = self.say(i, CRITICAL, "Failsafe activated\t");
        if self.state(i).airborne() {
            out.extend(self.px4_enter(i, Nav::Rtl));
        }
        out
    }

    /// What the commander and the navigator do as time passes: the gripper's end, the
    /// landing detector and the auto-disarm, the plans flown, the mission protocol's
    /// timeout.
    pub(crate) fn px4_step(&mut self) -> Vec<Out> {
        let now = self.fleet.time();
        let mut out = Vec::new();
        for i in 0..self.copters.len() {
            let system = self.copters[i].system;
            if let Some(g) = self.px4(i).gripper.filter(|g| now >= g.until) {
                self.px4_mut(i).gripper = None;
                self.px4_mut(i).grabbed = Some(g.grab);
                out.push(gripper_ack(system, MAV_RESULT_ACCEPTED, g.asker));
            }
            let state = self.state(i);
            let airborne = state.airborne();
            if self.copters[i].armed {
                let was = self.px4(i).was_airborne;
                if airborne && !was {
                    out.extend(self.say(i, INFO, "Takeoff detected\t"));
                    let p = self.px4_mut(i);
                    p.taken_off = true;
                    p.landed_at = None;
                } else if !airborne && was && state == FlightState::Landed {
                    out.extend(self.say(i, INFO, "Landing detected\t"));
                    self.px4_mut(i).landed_at = Some(now);
                }
                let p = self.px4(i);
                let amid_mission = p.nav == Nav::Mission && !p.mission.finished;
                let disarm = if airborne {
                    None
                } else if p.taken_off {
                    p.landed_at
                        .filter(|t| now - t >= super::DISARM_LAND && !amid_mission)
                        .map(|_| "landing")
                } else {
                    (now - p.armed_at >= super::DISARM_PREFLIGHT)
                        .then_some("auto preflight disarming")
                };
                if let Some(by) = disarm {
                    match self.px4_disarm(i, by) {
                        Ok(said) | Err(said) => out.extend(said),
                    }
                }
            }
            self.px4_mut(i).was_airborne = airborne;
            if self.px4(i).nav == Nav::Rtl
                && state == FlightState::Landing
                && !self.px4(i).rtl_landing_said
            {
                self.px4_mut(i).rtl_landing_said = true;
                out.extend(self.say(i, INFO, "RTL: land at destination\t"));
            }
            if self.copters[i].call.is_none() && !self.px4(i).plan.is_empty() {
                out.extend(self.px4_run(i));
            }
            out.extend(self.px4_mission_timeout(i, now));
        }
        out
    }

    /// A simulator call that failed: the plan stops (the vehicle holds where it is), said
    /// in PX4's words where PX4 has them, else in the simulator's.
    pub(crate) fn px4_failed(&mut self, i: usize, f: &Failure) -> Vec<Out> {
        let doing = self.px4(i).doing;
        self.px4_stop(i);
        let fence = f.exception == aviary_api::BuiltinException::GeofenceViolation;
        match doing {
            super::For::Reposition if fence => {
                self.say(i, CRITICAL, "Reposition is outside geofence\t")
            }
            super::For::Orbit if fence => self.say(i, CRITICAL, "Orbit is outside geofence"),
            super::For::Waypoint(seq) if fence => {
                self.say(i, CRITICAL, &format!("Geofence violation for waypoint {}\t", seq + 1))
            }
            _ => self.say(i, MavSeverity::MAV_SEVERITY_WARNING, &f.reason),
        }
    }
}

fn after(mut a: Answer, out: Vec<Out>) -> Answer {
    a.after.extend(out.into_iter().map(Reply::all));
    a
}

fn before(mut a: Answer, out: Vec<Out>) -> Answer {
    a.before.extend(out.into_iter().map(Reply::all));
    a
}

/// The payload deliverer's COMMAND_ACK for DO_GRIPPER, to whoever asked.
fn gripper_ack(system: u8, result: MavResult, to: (u8, u8)) -> Out {
    Out {
        system,
        msg: MavMessage::COMMAND_ACK(COMMAND_ACK_DATA {
            command: MavCmd::MAV_CMD_DO_GRIPPER,
            result,
            progress: 0,
            result_param2: 0,
            target_system: to.0,
            target_component: to.1,
        })
        .into(),
    }
}

/// PROTOCOL_VERSION: MAVLink 2.
fn protocol_version() -> MavMessage {
    MavMessage::PROTOCOL_VERSION(PROTOCOL_VERSION_DATA {
        version: 200,
        min_version: 100,
        max_version: 200,
        ..PROTOCOL_VERSION_DATA::default()
    })
}
