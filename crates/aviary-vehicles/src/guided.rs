//! Modes and GUIDED targets: SET_MODE / DO_SET_MODE, SET_POSITION_TARGET_GLOBAL_INT and
//! DO_REPOSITION, with their altitude frames converted as ArduCopter does.

use aviary_api::{DroneId, FlightState, FunctionCall, Place, Point};
use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavResult, MavSeverity};
use aviary_mavlink::mode::{COPTER_BRAKE, COPTER_GUIDED, COPTER_LAND, COPTER_LOITER, COPTER_RTL};

use crate::autopilot::{text, Autopilot, Reply, STABILIZE};
use crate::commands::Answer;

/// DO_REPOSITION's param2 bit: switch to GUIDED first (MAV_DO_REPOSITION_FLAGS_CHANGE_MODE).
const CHANGE_MODE: i32 = 1;

impl Autopilot {
    /// A position's height in the local frame (metres above the origin, where the vehicle's
    /// home and the ground are) from an altitude in a MAVLink frame; `None` for a frame
    /// ArduCopter does not take for a global position.
    pub fn frame_z(&self, frame: u32, z: f32) -> Option<f64> {
        let z = f64::from(z);
        match frame {
            // MAV_FRAME_GLOBAL and _INT: above mean sea level.
            0 | 5 => Some(z - self.origin.alt),
            // MAV_FRAME_GLOBAL_RELATIVE_ALT and _INT: above home.
            3 | 6 => Some(z),
            // MAV_FRAME_GLOBAL_TERRAIN_ALT and _INT: above the ground, which the simulator
            // has flat at home's height.
            10 | 11 => Some(z),
            _ => None,
        }
    }

    /// Flies to a GUIDED target (`z` in the local frame). The same target again, while it
    /// is being flown to, changes nothing.
    pub fn goto(&mut self, i: usize, lat: i32, lon: i32, z: f64) -> Result<(), String> {
        let xy = self.origin.from_e7(lat, lon);
        let to = [xy[0], xy[1], z];
        let c = &self.copters[i];
        if c.mode != COPTER_GUIDED {
            return Err("position target ignored: not in GUIDED".into());
        }
        // As ArduCopter: a target during the take-off replaces the climb.
        if !matches!(self.state(i), FlightState::Flying | FlightState::TakingOff) {
            return Err("position target ignored: not flying".into());
        }
        // The simulator flies to a place only from the air: a take-off still on the ground
        // (commanded in this very tick) would be cancelled by the flight that then fails,
        // so the target is refused and the take-off goes on.
        if self.state(i) == FlightState::TakingOff
            && self.fleet.telemetry(DroneId(i)).is_some_and(|t| t.position[2] <= 0.0)
        {
            return Err("position target ignored: still taking off".into());
        }
        let same = c.target.is_some_and(|t| (0..3).all(|k| (t[k] - to[k]).abs() < 0.01));
        if same && c.call.is_some() {
            return Ok(());
        }
        self.copters[i].target = Some(to);
        let speed = self.copters[i].speed;
        let pos = Place::Point(Point { x: to[0], y: to[1], z: Some(to[2]) });
        self.motion(i, &FunctionCall::FlyToPosition { pos, speed: Some(speed) })
    }

    /// MAV_CMD_DO_REPOSITION (COMMAND_INT), as ArduCopter's
    /// `handle_command_int_do_reposition`: DENIED outside GUIDED unless asked to change
    /// mode, for a latitude or longitude out of range, or a frame that is not global
    /// (with ArduPilot's "Unknown mavlink coordinate frame"); on the ground in GUIDED the
    /// target is taken and nothing flies until a take-off.
    pub fn reposition(&mut self, i: usize, p2: f32, frame: u32, at: (i32, i32, f32)) -> Answer {
        use MavResult::*;
        let system = self.copters[i].system;
        let change = (p2 as i32) & CHANGE_MODE != 0;
        if self.copters[i].mode != COPTER_GUIDED && !change {
            return Answer::of(MAV_RESULT_DENIED);
        }
        let (lat, lon, z) = at;
        // A height that is not a number is no place to fly to.
        if lat.unsigned_abs() > 900_000_000 || lon.unsigned_abs() > 1_800_000_000 || !z.is_finite()
        {
            return Answer::of(MAV_RESULT_DENIED);
        }
        let Some(z) = self.frame_z(frame, z) else {
            let why = format!("Unknown mavlink coordinate frame {frame}");
            let mut a = Answer::of(MAV_RESULT_DENIED);
            a.before.push(Reply::all(text(system, MavSeverity::MAV_SEVERITY_INFO, &why)));
            return a;
        };
        if self.copters[i].mode != COPTER_GUIDED {
            let (result, why) = self.set_mode(i, COPTER_GUIDED);
            if result != MAV_RESULT_ACCEPTED {
                return Answer::failed(system, MAV_RESULT_FAILED, why);
            }
        }
        if !self.state(i).airborne() {
            return Answer::of(MAV_RESULT_ACCEPTED);
        }
        match self.goto(i, lat, lon, z) {
            Ok(()) => Answer::of(MAV_RESULT_ACCEPTED),
            Err(why) => Answer::failed(system, MAV_RESULT_FAILED, Some(why)),
        }
    }

    /// Stops where it is (GUIDED, LOITER or BRAKE entered in the air).
    fn hold(&mut self, i: usize) {
        if let Some(call) = self.copters[i].call.take() {
            self.fleet.interrupt(call, aviary_api::Interrupt::Abort);
        }
        self.copters[i].target = None;
    }

    /// A mode change (DO_SET_MODE or SET_MODE).
    pub fn set_mode(&mut self, i: usize, mode: u32) -> (MavResult, Option<String>) {
        if self.booting() {
            return (
                MavResult::MAV_RESULT_TEMPORARILY_REJECTED,
                Some("Mode change refused: still booting".into()),
            );
        }
        let airborne = self.state(i).airborne();
        let outcome = match mode {
            STABILIZE | COPTER_GUIDED | COPTER_LOITER | COPTER_BRAKE => {
                if airborne {
                    self.hold(i);
                }
                Ok(())
            }
            COPTER_RTL if airborne => self.motion(i, &FunctionCall::ReturnToLaunch),
            COPTER_LAND if airborne => self.motion(i, &FunctionCall::Land),
            COPTER_RTL | COPTER_LAND => Ok(()),
            other => {
                return (
                    MavResult::MAV_RESULT_DENIED,
                    Some(format!("Mode {other} is not simulated")),
                )
            }
        };
        match outcome {
            Ok(()) => {
                let c = &mut self.copters[i];
                if c.mode != mode {
                    // As ArduCopter, whose waypoint controller starts each mode at WPNAV_SPEED.
                    c.speed = c.wpnav_speed;
                }
                c.mode = mode;
                (MavResult::MAV_RESULT_ACCEPTED, None)
            }
            Err(why) => (MavResult::MAV_RESULT_FAILED, Some(why)),
        }
    }
}
