//! The command protocol of the simulated autopilots: each COMMAND_LONG or COMMAND_INT
//! answered with the result ArduCopter would give, and the reason it says first.

use aviary_api::{CallEnd, FlightState, Value};
use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavCmd, MavResult};
use aviary_mavlink::mode::{COPTER_GUIDED, COPTER_LAND, COPTER_RTL};

use crate::autopilot::Autopilot;

impl Autopilot {
    /// One COMMAND_LONG or COMMAND_INT (positions already in `at`): the ACK and any
    /// reason (sent first, as ArduPilot does).
    pub fn command(
        &mut self,
        i: usize,
        cmd: MavCmd,
        p: [f32; 7],
        at: Option<(i32, i32, f32)>,
    ) -> (MavResult, Option<String>) {
        use MavResult::*;
        let state = self
            .fleet
            .telemetry(i)
            .map_or(FlightState::Lost, |t| t.state);
        let refused = |why: &str| (MAV_RESULT_FAILED, Some(why.to_owned()));
        let done = |r: Result<(), String>| match r {
            Ok(()) => (MAV_RESULT_ACCEPTED, None),
            Err(why) => (MAV_RESULT_FAILED, Some(why)),
        };
        match cmd {
            MavCmd::MAV_CMD_DO_SET_MODE => self.set_mode(i, p[1] as u32),
            MavCmd::MAV_CMD_COMPONENT_ARM_DISARM if p[0] >= 0.5 => {
                if self.booting() {
                    return (
                        MAV_RESULT_TEMPORARILY_REJECTED,
                        Some("Arm: still booting".into()),
                    );
                }
                if self.fleet.time() < self.behaviour.prearm_time {
                    return refused("PreArm: GPS: waiting for 3D fix");
                }
                if matches!(self.copters[i].mode, COPTER_RTL | COPTER_LAND) {
                    return refused("Arm: Mode not armable");
                }
                if self.copters[i].armed {
                    return (MAV_RESULT_ACCEPTED, None);
                }
                let r = done(self.instant(i, "Arm", &[]));
                self.copters[i].armed = r.0 == MAV_RESULT_ACCEPTED;
                r
            }
            MavCmd::MAV_CMD_COMPONENT_ARM_DISARM => {
                if state.airborne() {
                    return refused("Disarm: vehicle is flying");
                }
                let r = done(self.instant(i, "Disarm", &[]));
                self.copters[i].armed &= r.0 != MAV_RESULT_ACCEPTED;
                r
            }
            MavCmd::MAV_CMD_NAV_TAKEOFF => {
                if self.copters[i].mode != COPTER_GUIDED {
                    return refused("Takeoff: not in GUIDED mode");
                }
                if !self.copters[i].armed {
                    return refused("Takeoff: arm motors first");
                }
                if state != FlightState::Landed {
                    return refused("Takeoff: already flying");
                }
                done(self.motion(i, "TakeOff", &[Value::Number(f64::from(p[6]))]))
            }
            MavCmd::MAV_CMD_NAV_LAND => self.set_mode(i, COPTER_LAND),
            MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH => self.set_mode(i, COPTER_RTL),
            MavCmd::MAV_CMD_DO_CHANGE_SPEED if p[1] > 0.0 => {
                let c = &mut self.copters[i];
                c.speed = f64::from(p[1]).min(c.max_speed);
                (MAV_RESULT_ACCEPTED, None)
            }
            MavCmd::MAV_CMD_DO_REPOSITION => match at {
                Some((lat, lon, z)) => done(self.goto(i, lat, lon, f64::from(z))),
                None => (MAV_RESULT_COMMAND_INT_ONLY, None),
            },
            MavCmd::MAV_CMD_DO_GRIPPER => {
                if p[1] >= 0.5 {
                    let kind = self.copters[i].payload.clone().unwrap_or_default();
                    done(self.instant(i, "LoadPayload", &[Value::Symbol(kind)]))
                } else {
                    done(self.instant(i, "ReleasePayload", &[]))
                }
            }
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL => {
                // Only GLOBAL_POSITION_INT's rate changes; the rest go at 1 Hz.
                if p[0] as u32 == 33 && p[1] > 0.0 {
                    self.position_hz = (1e6 / f64::from(p[1])).clamp(0.2, 50.0);
                }
                (MAV_RESULT_ACCEPTED, None)
            }
            _ => (MAV_RESULT_UNSUPPORTED, None),
        }
    }

    /// A call that does not move the drone (arming, the gripper): left to finish alone.
    pub(crate) fn instant(
        &mut self,
        i: usize,
        function: &str,
        args: &[Value],
    ) -> Result<(), String> {
        match self.fleet.call(i, function, args).1 {
            Some(CallEnd::Failed(f)) => Err(f.reason),
            _ => Ok(()),
        }
    }
}
