//! The autopilots over the simulator's [`Fleet`], ArduCopter-like or PX4 (`crate::px4`):
//! modes, arming with pre-arm checks, the command protocol with ACKs and STATUSTEXT
//! reasons, GUIDED position targets, and the telemetry messages. No IO and no clock: the
//! server feeds it messages and simulated seconds, and sends what it returns.

use aviary_api::{
    BuiltinException, CallEnd, CallId, DroneEvent, DroneId, FlightState, FunctionCall,
};
use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavMessage, MavSeverity, STATUSTEXT_DATA};
use aviary_mavlink::mode::{Flavour, COPTER_RTL};
use aviary_mavlink::Origin;
use aviary_sim::{Fleet, Report};
use aviary_world::World;

use crate::px4::Px4;
use crate::wire::Wire;

/// How the simulated autopilots behave.
#[derive(Clone, Copy, Debug)]
pub struct Behaviour {
    /// Simulated seconds in MAV_STATE_BOOT, when mode changes are refused (ArduCopter;
    /// PX4 shows UNINIT until the pre-arm checks pass, and takes modes at once).
    pub boot_time: f64,
    /// Simulated seconds from power-on until the pre-arm checks pass (GPS and EKF).
    pub prearm_time: f64,
    /// Which autopilot the vehicles answer as: ArduCopter (the default) or PX4.
    pub autopilot: Flavour,
}

impl Default for Behaviour {
    fn default() -> Behaviour {
        Behaviour { boot_time: 1.0, prearm_time: 3.0, autopilot: Flavour::ArduPilot }
    }
}

pub struct Copter {
    pub system: u8,
    pub mode: u32,
    pub armed: bool,
    /// A failsafe has triggered (HEARTBEAT says CRITICAL from then on).
    pub failsafe: bool,
    /// The motion call in progress (a new command replaces it).
    pub(crate) call: Option<CallId>,
    /// The speed of GUIDED flights now (DO_CHANGE_SPEED), m/s.
    pub(crate) speed: f64,
    /// WPNAV_SPEED, m/s: the speed GUIDED flights start with.
    pub(crate) wpnav_speed: f64,
    pub(crate) max_speed: f64,
    pub(crate) climb_rate: f64,
    /// The world's `takeoff_speed` (PX4's MPC_TKO_SPEED).
    pub(crate) takeoff_speed: f64,
    /// How it comes down, and how it returns: the world's figures, which its simulated
    /// drone flies and its parameters report.
    pub(crate) descent: aviary_api::flight::Descent,
    pub(crate) return_altitude: f64,
    pub(crate) return_loiter: f64,
    /// mAh, when the world gives it.
    pub(crate) battery_capacity: Option<f64>,
    pub(crate) acceleration: f64,
    pub(crate) target: Option<[f64; 3]>,
    /// Home is set (the GPS has its fix): HOME_POSITION can be sent.
    pub(crate) home_set: bool,
    /// The world's home, local metres.
    pub(crate) home: [f64; 2],
    pub(crate) payload: Option<String>,
    was_airborne: bool,
    /// PX4's state (`--autopilot px4`; unused for ArduCopter).
    pub(crate) px4: Px4,
}

/// A message for the ground stations, from one vehicle.
#[derive(Clone, Debug)]
pub struct Out {
    pub system: u8,
    pub msg: Wire,
}

/// Who gets an answer: the client that asked (ACKs, reads, requested messages) or every
/// client (what ArduPilot sends on all links: STATUSTEXT, a changed parameter, a new home).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum To {
    Asker,
    All,
}

#[derive(Clone, Debug)]
pub struct Reply {
    pub to: To,
    pub out: Out,
}

impl Reply {
    pub fn asker(system: u8, msg: impl Into<Wire>) -> Reply {
        Reply { to: To::Asker, out: Out { system, msg: msg.into() } }
    }

    pub fn all(out: Out) -> Reply {
        Reply { to: To::All, out }
    }
}

pub struct Autopilot {
    pub fleet: Fleet,
    pub origin: Origin,
    pub copters: Vec<Copter>,
    pub(crate) behaviour: Behaviour,
    /// The site's geofence and altitude limit, which the simulator enforces.
    pub(crate) fence: (bool, Option<f64>),
    /// PX4's STATUSTEXT id, one more for every message.
    pub(crate) text_id: std::cell::Cell<u16>,
}

pub(crate) const STABILIZE: u32 = 0;

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
                let px4 = Px4::new(d.return_speed, !d.payload.is_empty());
                let mode = match behaviour.autopilot {
                    Flavour::ArduPilot => STABILIZE,
                    Flavour::Px4 => px4.nav.custom_mode(),
                };
                Copter {
                    system,
                    mode,
                    armed: false,
                    failsafe: false,
                    call: None,
                    speed: d.max_speed,
                    wpnav_speed: d.max_speed,
                    max_speed: d.max_speed,
                    climb_rate: d.climb_rate,
                    takeoff_speed: d.takeoff_speed,
                    descent: d.descent(),
                    return_altitude: d.return_altitude,
                    return_loiter: d.return_loiter,
                    battery_capacity: d.battery_capacity,
                    acceleration: d.acceleration,
                    target: None,
                    home_set: false,
                    home: [d.home[0], d.home[1]],
                    payload: d.payload.first().cloned(),
                    was_airborne: false,
                    px4,
                }
            })
            .collect();
        let origin =
            world.site.origin.as_ref().map_or(Origin::default(), aviary_world::Geo::origin);
        // An autopilot knows its geofence, not Aviary's no-fly zones: a real ArduCopter
        // flies a GUIDED target and its own RTL straight, so the detour must be the
        // backend's (aviary-mavlink sends it as waypoints), and the test of it means
        // something only if these vehicles do not go around by themselves.
        let unzoned;
        let world = if world.no_fly.is_empty() {
            world
        } else {
            unzoned = World { no_fly: Vec::new(), ..world.clone() };
            &unzoned
        };
        Autopilot {
            fleet: Fleet::new(world),
            origin,
            copters,
            behaviour,
            fence: (world.site.geofence.is_some(), world.site.max_altitude),
            text_id: std::cell::Cell::new(0),
        }
    }

    pub fn px4_flavour(&self) -> bool {
        self.behaviour.autopilot == Flavour::Px4
    }

    pub fn booting(&self) -> bool {
        self.fleet.time() < self.behaviour.boot_time
    }

    /// The pre-arm checks pass (GPS fix and position estimate) from this time on.
    pub fn ready(&self) -> bool {
        self.fleet.time() >= self.behaviour.prearm_time
    }

    /// The drone's flight state (Lost when the simulator has no such drone).
    pub(crate) fn state(&self, i: usize) -> FlightState {
        self.fleet.telemetry(DroneId(i)).map_or(FlightState::Lost, |t| t.state)
    }

    /// Whether the drone's radio works (a world `link_loss` fault silences it).
    pub fn link(&self, i: usize) -> bool {
        self.fleet.telemetry(DroneId(i)).is_some_and(|t| t.link)
    }

    /// Advances the simulation; returns what every client is told: the STATUSTEXTs that
    /// say what happened, and HOME_POSITION once home is set.
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
                        if self.px4_flavour() {
                            out.extend(self.px4_failed(i, &f));
                        } else {
                            out.push(text(
                                self.copters[i].system,
                                MavSeverity::MAV_SEVERITY_WARNING,
                                &f.reason,
                            ));
                        }
                    }
                }
                Report::Event(DroneEvent::Fault { drone, failure })
                    if failure.exception == BuiltinException::BatteryCritical
                        && self.px4_flavour() =>
                {
                    out.extend(self.px4_battery_failsafe(drone.0));
                }
                Report::Event(DroneEvent::Fault { drone, failure })
                    if failure.exception == BuiltinException::BatteryCritical =>
                {
                    // ArduCopter's battery failsafe: say so, then return to launch.
                    let system = self.copters[drone.0].system;
                    out.push(text(
                        system,
                        MavSeverity::MAV_SEVERITY_CRITICAL,
                        "Battery 1 is critical: failsafe RTL",
                    ));
                    self.copters[drone.0].mode = COPTER_RTL;
                    self.copters[drone.0].failsafe = true;
                    if let Err(why) = self.motion(drone.0, &FunctionCall::ReturnToLaunch) {
                        out.push(text(system, MavSeverity::MAV_SEVERITY_CRITICAL, &why));
                    }
                }
                Report::Event(DroneEvent::Fault { drone, failure })
                    if failure.exception == BuiltinException::DroneLost =>
                {
                    // Down for good: HEARTBEAT says EMERGENCY from now on; say why first.
                    let system = self.copters[drone.0].system;
                    let why = format!("Crash: {}", failure.reason);
                    if self.px4_flavour() {
                        out.extend(self.px4_text(
                            system,
                            MavSeverity::MAV_SEVERITY_EMERGENCY,
                            &why,
                        ));
                    } else {
                        out.push(text(system, MavSeverity::MAV_SEVERITY_EMERGENCY, &why));
                    }
                }
                Report::Event(_) => {}
            }
        }
        if self.ready() {
            // The GPS has its fix: home is set, and said, as ArduCopter and PX4 do.
            for i in 0..self.copters.len() {
                if !self.copters[i].home_set {
                    self.copters[i].home_set = true;
                    if let Some(home) = self.home_position(i) {
                        out.push(Out { system: self.copters[i].system, msg: home.into() });
                    }
                }
            }
        }
        if self.px4_flavour() {
            out.extend(self.px4_step());
            return out;
        }
        for (i, c) in self.copters.iter_mut().enumerate() {
            let state = self.fleet.telemetry(DroneId(i)).map_or(FlightState::Lost, |t| t.state);
            if c.was_airborne && !state.airborne() {
                // Down (landed, or fallen): the motors stop, as ArduCopter's auto-disarm.
                c.armed = false;
            }
            c.was_airborne = state.airborne();
        }
        out
    }

    /// Starts a motion call, replacing the one in progress. `Err` has the reason.
    pub(crate) fn motion(&mut self, i: usize, function: &FunctionCall) -> Result<(), String> {
        if let Some(call) = self.copters[i].call.take() {
            self.fleet.interrupt(call, aviary_api::Interrupt::Abort);
        }
        let (call, end) = self.fleet.call(DroneId(i), function);
        match end {
            None => {
                self.copters[i].call = Some(call);
                Ok(())
            }
            Some(CallEnd::Failed(f)) => Err(f.reason),
            Some(_) => Ok(()),
        }
    }
}

pub fn text(system: u8, severity: MavSeverity, s: &str) -> Out {
    Out {
        system,
        msg: MavMessage::STATUSTEXT(STATUSTEXT_DATA {
            severity,
            text: s.into(),
            ..STATUSTEXT_DATA::default()
        })
        .into(),
    }
}
