//! The command protocol of the simulated autopilots: each COMMAND_LONG or COMMAND_INT
//! answered with the result ArduCopter would give, the reason it says first, and what a
//! request asks for (AUTOPILOT_VERSION, HOME_POSITION, a telemetry message).

use aviary_api::{CallEnd, DroneId, FlightState, FunctionCall};
use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavCmd, MavResult, MavSeverity};
use aviary_mavlink::mode::{COPTER_GUIDED, COPTER_LAND, COPTER_RTL};

use crate::autopilot::{text, Autopilot, Out, Reply};

/// A command's answer: the result for the COMMAND_ACK, what goes before it (a reason,
/// HOME_POSITION for MAV_CMD_GET_HOME_POSITION) and after it (what a request asked for).
pub struct Answer {
    pub result: MavResult,
    pub before: Vec<Reply>,
    pub after: Vec<Reply>,
    /// COMMAND_ACK's `progress` (PX4 sends 255 with IN_PROGRESS, "unknown").
    pub progress: u8,
    /// No COMMAND_ACK at all (a command PX4 leaves unanswered).
    pub silent: bool,
}

impl Answer {
    pub fn of(result: MavResult) -> Answer {
        Answer { result, before: Vec::new(), after: Vec::new(), progress: 0, silent: false }
    }

    /// No COMMAND_ACK, only what comes with it.
    pub fn none() -> Answer {
        Answer { silent: true, ..Answer::of(MavResult::MAV_RESULT_ACCEPTED) }
    }

    /// A refusal with the autopilot's reason, a STATUSTEXT every ground station sees (as
    /// ArduPilot's, sent on all links) just before the ACK.
    pub fn failed(system: u8, result: MavResult, why: Option<String>) -> Answer {
        let mut a = Answer::of(result);
        if let Some(why) = why {
            a.before.push(Reply::all(text(system, MavSeverity::MAV_SEVERITY_WARNING, &why)));
        }
        a
    }
}

/// A command as it came: COMMAND_LONG's seven parameters, or COMMAND_INT's four with its
/// frame and position (`x`, `y` as degrees × 10⁷, `z`).
pub struct Command {
    pub id: MavCmd,
    pub p: [f32; 7],
    pub int: Option<(u32, i32, i32, f32)>,
}

impl Autopilot {
    /// One command to vehicle `i`. GET_HOME_POSITION and REQUEST_AUTOPILOT_CAPABILITIES are
    /// superseded by REQUEST_MESSAGE, but MAVSDK, MAVProxy and ArduPilot still use them.
    #[allow(deprecated)]
    pub fn command(&mut self, i: usize, c: &Command) -> Answer {
        use MavResult::*;
        let system = self.copters[i].system;
        let p = c.p;
        match c.id {
            MavCmd::MAV_CMD_DO_SET_MODE => with_reason(system, self.set_mode(i, p[1] as u32)),
            MavCmd::MAV_CMD_COMPONENT_ARM_DISARM if p[0] >= 0.5 => self.arm(i),
            MavCmd::MAV_CMD_COMPONENT_ARM_DISARM => self.disarm(i),
            MavCmd::MAV_CMD_NAV_TAKEOFF => self.take_off(i, c),
            MavCmd::MAV_CMD_NAV_LAND => with_reason(system, self.set_mode(i, COPTER_LAND)),
            MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH => {
                with_reason(system, self.set_mode(i, COPTER_RTL))
            }
            MavCmd::MAV_CMD_DO_CHANGE_SPEED if p[1] > 0.0 => {
                let c = &mut self.copters[i];
                c.speed = f64::from(p[1]).min(c.max_speed);
                Answer::of(MAV_RESULT_ACCEPTED)
            }
            MavCmd::MAV_CMD_DO_CHANGE_SPEED => Answer::of(MAV_RESULT_DENIED),
            // ArduCopter takes DO_REPOSITION only as COMMAND_INT (a COMMAND_LONG is
            // answered UNSUPPORTED, as below).
            MavCmd::MAV_CMD_DO_REPOSITION => match c.int {
                Some((frame, x, y, z)) => self.reposition(i, p[1], frame, (x, y, z)),
                None => Answer::of(MAV_RESULT_UNSUPPORTED),
            },
            MavCmd::MAV_CMD_DO_GRIPPER => {
                if p[1] >= 0.5 {
                    let kind = self.copters[i].payload.clone().unwrap_or_default();
                    done(system, self.instant(i, &FunctionCall::LoadPayload { kind }))
                } else {
                    done(system, self.instant(i, &FunctionCall::ReleasePayload))
                }
            }
            MavCmd::MAV_CMD_GET_HOME_POSITION => match self.home_position(i) {
                Some(home) => Answer {
                    before: vec![Reply::asker(system, home)],
                    ..Answer::of(MAV_RESULT_ACCEPTED)
                },
                None => Answer::of(MAV_RESULT_FAILED),
            },
            MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES if p[0] >= 0.5 => Answer {
                after: vec![Reply::asker(system, self.autopilot_version(i))],
                ..Answer::of(MAV_RESULT_ACCEPTED)
            },
            MavCmd::MAV_CMD_REQUEST_MESSAGE => match self.message(i, p[0] as u32) {
                Some(msg) => Answer {
                    after: vec![Reply::asker(system, msg)],
                    ..Answer::of(MAV_RESULT_ACCEPTED)
                },
                // ArduPilot's answer for a message it cannot send.
                None => Answer::of(MAV_RESULT_FAILED),
            },
            _ => Answer::of(MAV_RESULT_UNSUPPORTED),
        }
    }

    /// MAV_CMD_COMPONENT_ARM_DISARM, arm: refused while booting, before the pre-arm
    /// checks pass, and in RTL or LAND.
    fn arm(&mut self, i: usize) -> Answer {
        use MavResult::*;
        let system = self.copters[i].system;
        if self.booting() {
            return with_reason(
                system,
                (MAV_RESULT_TEMPORARILY_REJECTED, Some("Arm: still booting".into())),
            );
        }
        if !self.ready() {
            return refused(system, "PreArm: GPS: waiting for 3D fix");
        }
        if matches!(self.copters[i].mode, COPTER_RTL | COPTER_LAND) {
            return refused(system, "Arm: Mode not armable");
        }
        if self.copters[i].armed {
            return Answer::of(MAV_RESULT_ACCEPTED);
        }
        let mut a = done(system, self.instant(i, &FunctionCall::Arm));
        self.copters[i].armed = a.result == MAV_RESULT_ACCEPTED;
        // ArduCopter sets home where it arms, and says so on every link; the
        // simulator's home does not move, so the same home is said again.
        if let Some(home) = self.home_position(i).filter(|_| self.copters[i].armed) {
            a.after.push(Reply::all(Out { system, msg: home.into() }));
        }
        a
    }

    /// MAV_CMD_COMPONENT_ARM_DISARM, disarm: on the ground only.
    fn disarm(&mut self, i: usize) -> Answer {
        let system = self.copters[i].system;
        if self.state(i).airborne() {
            return refused(system, "Disarm: vehicle is flying");
        }
        let a = done(system, self.instant(i, &FunctionCall::Disarm));
        self.copters[i].armed &= a.result != MavResult::MAV_RESULT_ACCEPTED;
        a
    }

    /// MAV_CMD_NAV_TAKEOFF: in GUIDED, armed, from the ground.
    fn take_off(&mut self, i: usize, c: &Command) -> Answer {
        use MavResult::*;
        let system = self.copters[i].system;
        let state = self.state(i);
        // COMMAND_INT carries the altitude in z, and only above home (as ArduCopter).
        let alt = match c.int {
            None => c.p[6],
            Some((3 | 6, _, _, z)) => z,
            Some(_) => return Answer::of(MAV_RESULT_DENIED),
        };
        if !alt.is_finite() {
            return Answer::of(MAV_RESULT_DENIED);
        }
        if self.copters[i].mode != COPTER_GUIDED {
            return refused(system, "Takeoff: not in GUIDED mode");
        }
        if !self.copters[i].armed {
            return refused(system, "Takeoff: arm motors first");
        }
        if state != FlightState::Landed {
            return refused(system, "Takeoff: already flying");
        }
        done(system, self.motion(i, &FunctionCall::TakeOff { alt: f64::from(alt) }))
    }

    /// A call that does not move the drone (arming, the gripper): left to finish alone.
    pub(crate) fn instant(&mut self, i: usize, call: &FunctionCall) -> Result<(), String> {
        match self.fleet.call(DroneId(i), call).1 {
            Some(CallEnd::Failed(f)) => Err(f.reason),
            _ => Ok(()),
        }
    }
}

/// The result the autopilot gives, with its reason when it says one.
fn with_reason(system: u8, (result, why): (MavResult, Option<String>)) -> Answer {
    Answer::failed(system, result, why)
}

/// A refusal (`MAV_RESULT_FAILED`) with the autopilot's reason.
fn refused(system: u8, why: &str) -> Answer {
    Answer::failed(system, MavResult::MAV_RESULT_FAILED, Some(why.to_owned()))
}

/// Accepted when the simulator's call went through, else refused with its reason.
fn done(system: u8, r: Result<(), String>) -> Answer {
    match r {
        Ok(()) => Answer::of(MavResult::MAV_RESULT_ACCEPTED),
        Err(why) => Answer::failed(system, MavResult::MAV_RESULT_FAILED, Some(why)),
    }
}
