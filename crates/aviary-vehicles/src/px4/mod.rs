//! PX4 (`aviary vehicles --autopilot px4`): the same simulated drones answering as PX4
//! answers, as its source says (PX4-Autopilot main of 2024-12, docs/REAL_DRONES.md):
//! - `commander`: modes (main and sub mode in `custom_mode`, [`aviary_mavlink::mode::px4`]),
//!   arming with PX4's refusals, the commands PX4's commander, navigator and mavlink
//!   modules answer, landing detection and auto-disarm;
//! - `navigator`: what each mode flies on the simulator (take-off, Hold with
//!   DO_REPOSITION, land, return, orbit, the mission through its items);
//! - `mission`: the mission protocol (upload, download, clear, set current) and the
//!   progress messages (MISSION_CURRENT, MISSION_ITEM_REACHED);
//! - `params`: the parameters under PX4's names and types, integers sent bytewise.
//!
//! PX4's STATUSTEXTs are its own words, sent as PX4 sends them: with the tab that ends
//! most of them in its source, split into chunks of 50 characters, each message with its
//! own id.

mod commander;
mod mission;
mod navigator;
mod params;

use std::collections::VecDeque;

use aviary_api::{DroneId, FunctionCall};
use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavMessage, MavSeverity, STATUSTEXT_DATA};
use aviary_mavlink::mode::px4;

use crate::autopilot::{Autopilot, Out};

pub(crate) use mission::{for_me, Incoming, Mission};

/// PX4's navigation states (its vehicle_status nav_state) that a vehicle can be in, with
/// the `custom_mode` each is shown as (px4_custom_mode.h's get_px4_custom_mode).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Nav {
    Manual,
    Altctl,
    Posctl,
    PositionSlow,
    Acro,
    Stab,
    Mission,
    Loiter,
    Rtl,
    Takeoff,
    Land,
    Orbit,
}

impl Nav {
    pub fn custom_mode(self) -> u32 {
        let (main, sub) = match self {
            Nav::Manual => (px4::MANUAL, 0),
            Nav::Altctl => (px4::ALTCTL, 0),
            Nav::Posctl => (px4::POSCTL, px4::POSCTL_POSCTL),
            Nav::PositionSlow => (px4::POSCTL, px4::POSCTL_SLOW),
            Nav::Acro => (px4::ACRO, 0),
            Nav::Stab => (px4::STABILIZED, 0),
            Nav::Mission => (px4::AUTO, px4::AUTO_MISSION),
            Nav::Loiter => (px4::AUTO, px4::AUTO_LOITER),
            Nav::Rtl => (px4::AUTO, px4::AUTO_RTL),
            Nav::Takeoff => (px4::AUTO, px4::AUTO_TAKEOFF),
            Nav::Land => (px4::AUTO, px4::AUTO_LAND),
            Nav::Orbit => (px4::POSCTL, px4::POSCTL_ORBIT),
        };
        px4::encode(main, sub)
    }

    /// The mode's name in PX4's messages (src/lib/modes/ui.hpp, nav_state_names).
    pub fn name(self) -> &'static str {
        match self {
            Nav::Manual => "Manual",
            Nav::Altctl => "Altitude",
            Nav::Posctl => "Position",
            Nav::PositionSlow => "Position Slow",
            Nav::Acro => "Acro",
            Nav::Stab => "Stabilized",
            Nav::Mission => "Mission",
            Nav::Loiter => "Hold",
            Nav::Rtl => "Return",
            Nav::Takeoff => "Takeoff",
            Nav::Land => "Land",
            Nav::Orbit => "Orbit",
        }
    }

    /// PX4 does not arm in these (mode_requirements.cpp, mode_req_prevent_arming).
    pub fn prevents_arming(self) -> bool {
        matches!(self, Nav::Rtl | Nav::Land | Nav::Orbit)
    }

    /// The manual modes need a pilot's sticks (mode_req_manual_control), which the
    /// simulator has none of.
    pub fn manual(self) -> bool {
        matches!(
            self,
            Nav::Manual | Nav::Altctl | Nav::Posctl | Nav::PositionSlow | Nav::Acro | Nav::Stab
        )
    }

    /// flag_control_auto_enabled (control_mode.cpp): HEARTBEAT's AUTO, GUIDED and STABILIZE.
    pub fn auto(self) -> bool {
        matches!(self, Nav::Mission | Nav::Loiter | Nav::Rtl | Nav::Takeoff | Nav::Land)
    }
}

/// What a step of a vehicle's plan is for, to say a refusal in PX4's words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum For {
    Reposition,
    Orbit,
    Waypoint(u16),
    Other,
}

/// One step of what the navigator flies next.
#[derive(Clone, Debug)]
pub(crate) enum Step {
    /// A call to the simulator; the next step waits for its end.
    Call(FunctionCall, For),
    /// Mission item `seq` is reached: say so, go on with the mission.
    Reached(u16),
    /// The take-off is done: Takeoff hands over to Hold (PX4's COM_TAKEOFF_ACT 0).
    TakeoffDone,
}

/// DO_REPOSITION's target, kept for Hold (local metres; speed None: the cruise speed).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Reposition {
    pub to: [f64; 3],
    pub speed: Option<f64>,
    /// Latitude, longitude and altitude all NaN: stop where it is.
    pub pause: bool,
}

/// The orbit FlightTaskOrbit flies (local metres; the radius within 1 to 1000 m).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Orbit {
    pub center: [f64; 2],
    pub z: f64,
    pub radius: f64,
}

/// A DO_GRIPPER in progress: its action, who asked, when it is done.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Gripper {
    pub grab: bool,
    pub asker: (u8, u8),
    pub until: f64,
}

/// PX4's state of one vehicle.
pub(crate) struct Px4 {
    pub nav: Nav,
    /// The mode PX4 returns to when it disarms: the last one chosen that allows arming.
    pub after_disarm: Nav,
    /// Airborne since arming (PX4's _have_taken_off_since_arming).
    pub taken_off: bool,
    pub armed_at: f64,
    /// When the landing was detected, armed.
    pub landed_at: Option<f64>,
    pub was_airborne: bool,
    /// DO_CHANGE_SPEED's ground speed, until a mode resets it (None: MPC_XY_CRUISE).
    pub cruise: Option<f64>,
    /// MPC_XY_CRUISE, MIS_TAKEOFF_ALT, NAV_ACC_RAD.
    pub xy_cruise: f64,
    pub takeoff_alt: f64,
    pub nav_acc_rad: f64,
    /// NAV_TAKEOFF's altitude above sea level for the take-off to come (NaN: the default).
    pub takeoff_request: Option<f32>,
    pub reposition: Option<Reposition>,
    pub orbit: Option<Orbit>,
    pub plan: VecDeque<Step>,
    /// What the call in progress is for.
    pub doing: For,
    /// The place the call in progress flies to, for a new DO_CHANGE_SPEED.
    pub flying: Option<([f64; 3], For)>,
    /// "RTL: land at destination" said for this return.
    pub rtl_landing_said: bool,
    pub mission: Mission,
    pub gripper: Option<Gripper>,
    /// The gripper's last action done: grabbed (Some(true)) or released.
    pub grabbed: Option<bool>,
    /// Whether a world payload makes the gripper (PD_GRIPPER_EN) present.
    pub has_gripper: bool,
}

impl Px4 {
    /// `xy_cruise`: MPC_XY_CRUISE, the world's `return_speed` (PX4 returns at it).
    pub fn new(xy_cruise: f64, has_gripper: bool) -> Px4 {
        Px4 {
            // PX4 boots in Hold (UserModeIntention.hpp).
            nav: Nav::Loiter,
            after_disarm: Nav::Loiter,
            taken_off: false,
            armed_at: 0.0,
            landed_at: None,
            was_airborne: false,
            cruise: None,
            xy_cruise,
            takeoff_alt: 2.5,
            nav_acc_rad: 2.0,
            takeoff_request: None,
            reposition: None,
            orbit: None,
            plan: VecDeque::new(),
            doing: For::Other,
            flying: None,
            rtl_landing_said: false,
            mission: Mission::default(),
            gripper: None,
            grabbed: None,
            has_gripper,
        }
    }
}

/// PD_GRIPPER_TO: the time a gripper without a sensor takes, s.
pub(crate) const GRIPPER_TIME: f64 = 3.0;
/// COM_DISARM_LAND and COM_DISARM_PRFLT, s.
pub(crate) const DISARM_LAND: f64 = 2.0;
pub(crate) const DISARM_PREFLIGHT: f64 = 10.0;
/// NAV_MC_ALT_RAD, m: a height within this of the target counts as reached.
pub(crate) const ALT_RADIUS: f64 = 0.8;

impl Autopilot {
    pub(crate) fn px4(&self, i: usize) -> &Px4 {
        &self.copters[i].px4
    }

    pub(crate) fn px4_mut(&mut self, i: usize) -> &mut Px4 {
        &mut self.copters[i].px4
    }

    /// A STATUSTEXT as PX4's STATUSTEXT stream sends its mavlink_log messages: every
    /// message with the next id, its text in chunks of 50 characters, the last chunk
    /// the one that is 50 or shorter (a text of exactly 50 has no terminator).
    pub(crate) fn px4_text(&self, system: u8, severity: MavSeverity, text: &str) -> Vec<Out> {
        let id = self.text_id.get();
        self.text_id.set(id.wrapping_add(1));
        let bytes = text.as_bytes();
        let mut out = Vec::new();
        let mut at = 0;
        let mut chunk = 0u8;
        loop {
            let left = &bytes[at..];
            let n = left.len().min(50);
            let mut buf = [0u8; 50];
            buf[..n].copy_from_slice(&left[..n]);
            out.push(Out {
                system,
                msg: MavMessage::STATUSTEXT(STATUSTEXT_DATA {
                    severity,
                    text: buf.into(),
                    id,
                    chunk_seq: chunk,
                })
                .into(),
            });
            if left.len() <= 50 {
                return out;
            }
            at += 50;
            chunk = chunk.wrapping_add(1);
        }
    }

    /// The PX4 texts of vehicle `i`, for every client.
    pub(crate) fn say(&self, i: usize, severity: MavSeverity, text: &str) -> Vec<Out> {
        self.px4_text(self.copters[i].system, severity, text)
    }

    /// The ground speed a Hold reposition or a mission flies at: DO_CHANGE_SPEED's, or
    /// MPC_XY_CRUISE, within what the airframe can fly.
    pub(crate) fn cruise(&self, i: usize) -> f64 {
        let c = &self.copters[i];
        c.px4.cruise.unwrap_or(c.px4.xy_cruise).min(c.max_speed)
    }

    /// Where the drone is, local metres.
    pub(crate) fn here(&self, i: usize) -> [f64; 3] {
        self.fleet.telemetry(DroneId(i)).map_or([0.0; 3], |t| t.position)
    }
}
