//! ArduCopter-like autopilots over the simulator's [`Fleet`]: modes, arming with pre-arm
//! checks, the command protocol with ACKs and STATUSTEXT reasons, GUIDED position
//! targets, and the telemetry messages. No IO and no clock: the server feeds it
//! messages and simulated seconds, and sends what it returns.

use aviary_api::{CallEnd, CallId, DroneEvent, FlightState, Point, Value};
use aviary_mavlink::geo::Origin;
use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavCmd, MavMessage, MavResult, MavSeverity, COMMAND_ACK_DATA, STATUSTEXT_DATA,
};
use aviary_mavlink::mode::{COPTER_BRAKE, COPTER_GUIDED, COPTER_LAND, COPTER_LOITER, COPTER_RTL};
use aviary_sim::{Fleet, Report};
use aviary_world::World;

/// How the simulated autopilots behave.
#[derive(Clone, Copy, Debug)]
pub struct Behaviour {
    /// Simulated seconds in MAV_STATE_BOOT, when mode changes are refused.
    pub boot_time: f64,
    /// Simulated seconds from power-on until the pre-arm checks pass (GPS and EKF).
    pub prearm_time: f64,
}

impl Default for Behaviour {
    fn default() -> Behaviour {
        Behaviour {
            boot_time: 1.0,
            prearm_time: 3.0,
        }
    }
}

pub struct Copter {
    pub system: u8,
    pub mode: u32,
    pub armed: bool,
    /// A failsafe has triggered (HEARTBEAT says CRITICAL from then on).
    pub failsafe: bool,
    /// The motion call in progress (a new command replaces it).
    call: Option<CallId>,
    pub(crate) speed: f64,
    pub(crate) max_speed: f64,
    target: Option<[f64; 3]>,
    pub(crate) payload: Option<String>,
    was_airborne: bool,
}

/// A message for the ground stations, from one vehicle.
#[derive(Clone)]
pub struct Out {
    pub system: u8,
    pub msg: MavMessage,
}

pub struct Autopilot {
    pub fleet: Fleet,
    pub origin: Origin,
    pub copters: Vec<Copter>,
    pub(crate) behaviour: Behaviour,
    /// GLOBAL_POSITION_INT per second, as the ground station last asked.
    pub position_hz: f64,
}

const STABILIZE: u32 = 0;

impl Autopilot {
    /// Every drone of the world, with its `system_id` when it has one, else its place
    /// in the world (1, 2, ...).
    pub fn new(world: &World, behaviour: Behaviour) -> Autopilot {
        let copters = world
            .drones
            .iter()
            .enumerate()
            .map(|(i, d)| {
                let system = match &d.backend {
                    aviary_world::Backend::Mavlink(link) => link.system_id,
                    aviary_world::Backend::Sim => None,
                }
                .unwrap_or_else(|| u8::try_from(i + 1).unwrap_or(u8::MAX));
                Copter {
                    system,
                    mode: STABILIZE,
                    armed: false,
                    failsafe: false,
                    call: None,
                    speed: d.max_speed,
                    max_speed: d.max_speed,
                    target: None,
                    payload: d.payload.first().cloned(),
                    was_airborne: false,
                }
            })
            .collect();
        let origin = world
            .site
            .origin
            .as_ref()
            .map_or(Origin::default(), |g| Origin {
                lat: g.lat,
                lon: g.lon,
                alt: g.alt,
            });
        Autopilot {
            fleet: Fleet::new(world),
            origin,
            copters,
            behaviour,
            position_hz: 4.0,
        }
    }

    pub fn booting(&self) -> bool {
        self.fleet.time() < self.behaviour.boot_time
    }

    pub fn index(&self, system: u8) -> Option<usize> {
        self.copters.iter().position(|c| c.system == system)
    }

    /// Whether the drone's radio works (a world `link_loss` fault silences it).
    pub fn link(&self, i: usize) -> bool {
        self.fleet.telemetry(i).is_some_and(|t| t.link)
    }

    /// Advances the simulation; returns the STATUSTEXTs that tell what happened.
    pub fn step(&mut self, dt: f64) -> Vec<Out> {
        let mut out = Vec::new();
        for report in self.fleet.step(dt) {
            match report {
                Report::Ended { call, end } => {
                    let Some(i) = self.copters.iter().position(|c| c.call == Some(call)) else {
                        continue;
                    };
                    self.copters[i].call = None;
                    if let CallEnd::Failed(f) = end {
                        out.push(text(
                            self.copters[i].system,
                            MavSeverity::MAV_SEVERITY_WARNING,
                            &f.reason,
                        ));
                    }
                }
                Report::Event(DroneEvent::Fault { drone, failure })
                    if failure.exception == "BatteryCritical" =>
                {
                    // ArduCopter's battery failsafe: say so, then return to launch.
                    let system = self.copters[drone].system;
                    out.push(text(
                        system,
                        MavSeverity::MAV_SEVERITY_CRITICAL,
                        "Battery 1 is critical: failsafe RTL",
                    ));
                    self.copters[drone].mode = COPTER_RTL;
                    self.copters[drone].failsafe = true;
                    if let Err(why) = self.motion(drone, "ReturnToLaunch", &[]) {
                        out.push(text(system, MavSeverity::MAV_SEVERITY_CRITICAL, &why));
                    }
                }
                Report::Event(DroneEvent::Fault { drone, failure })
                    if failure.exception == "DroneLost" =>
                {
                    // Down for good: HEARTBEAT says EMERGENCY from now on; say why first.
                    let system = self.copters[drone].system;
                    out.push(text(
                        system,
                        MavSeverity::MAV_SEVERITY_EMERGENCY,
                        &format!("Crash: {}", failure.reason),
                    ));
                }
                Report::Event(_) => {}
            }
        }
        for (i, c) in self.copters.iter_mut().enumerate() {
            let state = self
                .fleet
                .telemetry(i)
                .map_or(FlightState::Lost, |t| t.state);
            if c.was_airborne && !state.airborne() {
                // Down (landed, or fallen): the motors stop, as ArduCopter's auto-disarm.
                c.armed = false;
            }
            c.was_airborne = state.airborne();
        }
        out
    }

    /// Starts a motion call, replacing the one in progress. `Err` has the reason.
    pub(crate) fn motion(
        &mut self,
        i: usize,
        function: &str,
        args: &[Value],
    ) -> Result<(), String> {
        if let Some(call) = self.copters[i].call.take() {
            self.fleet.interrupt(call, aviary_api::Interrupt::Abort);
        }
        let (call, end) = self.fleet.call(i, function, args);
        match end {
            None => {
                self.copters[i].call = Some(call);
                Ok(())
            }
            Some(CallEnd::Failed(f)) => Err(f.reason),
            Some(_) => Ok(()),
        }
    }

    /// Flies to a GUIDED target (SET_POSITION_TARGET_GLOBAL_INT, DO_REPOSITION). The same
    /// target again, while it is being flown to, changes nothing.
    pub fn goto(&mut self, i: usize, lat: i32, lon: i32, z: f64) -> Result<(), String> {
        let xy = self.origin.from_e7(lat, lon);
        let to = [xy[0], xy[1], z];
        let c = &self.copters[i];
        if c.mode != COPTER_GUIDED {
            return Err("position target ignored: not in GUIDED".into());
        }
        let state = self
            .fleet
            .telemetry(i)
            .map_or(FlightState::Lost, |t| t.state);
        // As ArduCopter: a target during the take-off replaces the climb.
        if !matches!(state, FlightState::Flying | FlightState::TakingOff) {
            return Err("position target ignored: not flying".into());
        }
        let same = c
            .target
            .is_some_and(|t| (0..3).all(|k| (t[k] - to[k]).abs() < 0.01));
        if same && c.call.is_some() {
            return Ok(());
        }
        self.copters[i].target = Some(to);
        let speed = self.copters[i].speed;
        self.motion(
            i,
            "FlyToPosition",
            &[
                Value::Position(Point {
                    x: to[0],
                    y: to[1],
                    z: Some(to[2]),
                }),
                Value::Number(speed),
            ],
        )
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
        let airborne = self.fleet.telemetry(i).is_some_and(|t| t.state.airborne());
        let outcome = match mode {
            STABILIZE | COPTER_GUIDED | COPTER_LOITER | COPTER_BRAKE => {
                if airborne {
                    self.hold(i);
                }
                Ok(())
            }
            COPTER_RTL if airborne => self.motion(i, "ReturnToLaunch", &[]),
            COPTER_LAND if airborne => self.motion(i, "Land", &[]),
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
                self.copters[i].mode = mode;
                (MavResult::MAV_RESULT_ACCEPTED, None)
            }
            Err(why) => (MavResult::MAV_RESULT_FAILED, Some(why)),
        }
    }
}

pub fn text(system: u8, severity: MavSeverity, s: &str) -> Out {
    Out {
        system,
        msg: MavMessage::STATUSTEXT(STATUSTEXT_DATA {
            severity,
            text: s.into(),
        }),
    }
}

pub fn ack(system: u8, command: MavCmd, result: MavResult) -> Out {
    Out {
        system,
        msg: MavMessage::COMMAND_ACK(COMMAND_ACK_DATA { command, result }),
    }
}
