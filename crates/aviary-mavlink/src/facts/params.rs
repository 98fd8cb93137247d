//! The parameters a vehicle is asked for, per autopilot, and what each sets.

use mavlink::dialects::ardupilotmega::MavParamType;

use crate::mode::Flavour;

/// A figure of a drone that a vehicle parameter gives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Figure {
    Climb,
    Descent,
    Acceleration,
    LandSpeed,
    LandSpeedBelow,
    /// ArduCopter's LAND_SPEED_HIGH: the landing's upper part, when not 0. The world has
    /// no key for it (its landing starts at `descent_rate`).
    LandSpeedHigh,
    ReturnAltitude,
    ReturnLoiter,
    /// `TakeOff`'s climb from the ground (PX4's MPC_TKO_SPEED).
    TakeoffSpeed,
    /// `ReturnToLaunch`'s speed over the ground (PX4's MPC_XY_CRUISE).
    ReturnSpeed,
    Capacity,
}

impl Figure {
    /// The world key it sets, and its unit there.
    pub fn key(self) -> (&'static str, &'static str) {
        match self {
            Figure::Climb => ("climb_rate", "m/s"),
            Figure::Descent => ("descent_rate", "m/s"),
            Figure::Acceleration => ("acceleration", "m/s²"),
            Figure::LandSpeed => ("land_speed", "m/s"),
            Figure::LandSpeedBelow => ("land_speed_below", "m"),
            Figure::LandSpeedHigh => ("landing from high", "m/s"),
            Figure::ReturnAltitude => ("return_altitude", "m"),
            Figure::ReturnLoiter => ("return_loiter", "s"),
            Figure::TakeoffSpeed => ("takeoff_speed", "m/s"),
            Figure::ReturnSpeed => ("return_speed", "m/s"),
            Figure::Capacity => ("battery_capacity", "mAh"),
        }
    }

    /// Whether `value` (in the world's unit) is one the world could hold: speeds and the
    /// capacity above 0, heights and times not below it. (LAND_SPEED_HIGH 0 means "not
    /// set": usable, it changes nothing.)
    pub fn usable(self, value: f64) -> bool {
        value.is_finite()
            && match self {
                Figure::Climb
                | Figure::Descent
                | Figure::Acceleration
                | Figure::LandSpeed
                | Figure::TakeoffSpeed
                | Figure::ReturnSpeed
                | Figure::Capacity => value > 0.0,
                Figure::LandSpeedBelow
                | Figure::ReturnAltitude
                | Figure::ReturnLoiter
                | Figure::LandSpeedHigh => value >= 0.0,
            }
    }
}

/// One vehicle parameter: its name, the figure it gives, and the factor from the
/// vehicle's unit to the world's.
#[derive(Debug, PartialEq)]
pub struct Param {
    pub name: &'static str,
    pub figure: Figure,
    pub scale: f64,
    /// The vehicle's unit, for the documentation and messages.
    pub unit: &'static str,
    /// How the figure comes from the parameter, in messages ("the vehicle's X", or "half
    /// the vehicle's X" where the figure is not the parameter in other units).
    pub of: &'static str,
}

const fn p(name: &'static str, figure: Figure, scale: f64, unit: &'static str) -> Param {
    Param { name, figure, scale, unit, of: "the vehicle's" }
}

/// What PX4's horizontal acceleration in its auto modes averages, as a share of its
/// limit MPC_ACC_HOR: its trajectories are jerk-limited (MPC_JERK_AUTO) and slow down
/// early for the next waypoint. Measured on PX4 SITL (defaults: MPC_ACC_HOR 3 m/s²,
/// MPC_JERK_AUTO 4 m/s³): a path of two 60 m legs and a 45° bend took 37.8 s, the
/// simulator 37.6 s at 1.5 m/s² and 27.7 s at 3; a sweep of three 60 m lanes 53.0 s, the
/// simulator 49.4 s at 1.5 m/s² and 37.3 s at 3 (docs/REAL_DRONES.md).
pub const PX4_ACCELERATION_SHARE: f64 = 0.5;

/// ArduCopter. GUIDED flies position targets at the WPNAV speeds; RTL climbs to RTL_ALT,
/// waits RTL_LOIT_TIME above home and lands like LAND: LAND_SPEED_HIGH (or WPNAV_SPEED_DN
/// when it is 0) down to LAND_ALT_LOW, then LAND_SPEED.
pub const ARDUPILOT: &[Param] = &[
    p("WPNAV_SPEED_UP", Figure::Climb, 0.01, "cm/s"),
    p("WPNAV_SPEED_DN", Figure::Descent, 0.01, "cm/s"),
    p("WPNAV_ACCEL", Figure::Acceleration, 0.01, "cm/s²"),
    p("LAND_SPEED", Figure::LandSpeed, 0.01, "cm/s"),
    p("LAND_ALT_LOW", Figure::LandSpeedBelow, 0.01, "cm"),
    p("LAND_SPEED_HIGH", Figure::LandSpeedHigh, 0.01, "cm/s"),
    p("RTL_ALT", Figure::ReturnAltitude, 0.01, "cm"),
    p("RTL_LOIT_TIME", Figure::ReturnLoiter, 0.001, "ms"),
    p("BATT_CAPACITY", Figure::Capacity, 1.0, "mAh"),
];

/// PX4 (read from PX4 SITL, and from `aviary vehicles --autopilot px4`). Aviary flies PX4 in HOLD
/// with DO_REPOSITION, an auto mode, whose vertical limits are MPC_Z_V_AUTO_UP/DN (the
/// MPC_Z_VEL_MAX_* are the manual modes'). PX4 lands at MPC_LAND_SPEED below
/// MPC_LAND_ALT2 after slowing from MPC_LAND_ALT1; the slow part is taken from ALT1, the
/// longer landing, so that the battery rule errs towards home. RTL_LAND_DELAY is -1 for
/// "hover, never land", which is no usable wait and keeps the world's. PX4 takes off at
/// MPC_TKO_SPEED (half its climb rate by default) and returns at MPC_XY_CRUISE. Its
/// paths are missions, whose acceleration averages [`PX4_ACCELERATION_SHARE`] of
/// MPC_ACC_HOR.
pub const PX4: &[Param] = &[
    p("MPC_Z_V_AUTO_UP", Figure::Climb, 1.0, "m/s"),
    p("MPC_TKO_SPEED", Figure::TakeoffSpeed, 1.0, "m/s"),
    p("MPC_XY_CRUISE", Figure::ReturnSpeed, 1.0, "m/s"),
    p("MPC_Z_V_AUTO_DN", Figure::Descent, 1.0, "m/s"),
    Param {
        of: "half the vehicle's",
        ..p("MPC_ACC_HOR", Figure::Acceleration, PX4_ACCELERATION_SHARE, "m/s²")
    },
    p("MPC_LAND_SPEED", Figure::LandSpeed, 1.0, "m/s"),
    p("MPC_LAND_ALT1", Figure::LandSpeedBelow, 1.0, "m"),
    p("RTL_RETURN_ALT", Figure::ReturnAltitude, 1.0, "m"),
    p("RTL_LAND_DELAY", Figure::ReturnLoiter, 1.0, "s"),
    p("BAT1_CAPACITY", Figure::Capacity, 1.0, "mAh"),
];

pub fn table(flavour: Flavour) -> &'static [Param] {
    match flavour {
        Flavour::ArduPilot => ARDUPILOT,
        Flavour::Px4 => PX4,
    }
}

/// Whether a PARAM_VALUE of this name is one the facts wait for (others, which ArduPilot
/// also sends by itself after a calibration, are not kept).
pub fn wanted(name: &str) -> bool {
    ARDUPILOT.iter().chain(PX4).any(|p| p.name == name)
}

/// The number a PARAM_VALUE carries. Floats are sent as they are. Integers differ:
/// ArduPilot converts them to a float ("cast"), PX4 sends their bytes in the float's place
/// ("bytewise", MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE).
pub fn decode(flavour: Flavour, value: f32, ty: MavParamType) -> f64 {
    use MavParamType::*;
    let bits = value.to_bits();
    match (flavour, ty) {
        (_, MAV_PARAM_TYPE_REAL32 | MAV_PARAM_TYPE_REAL64) | (Flavour::ArduPilot, _) => {
            f64::from(value)
        }
        (Flavour::Px4, MAV_PARAM_TYPE_UINT8) => f64::from(bits as u8),
        (Flavour::Px4, MAV_PARAM_TYPE_INT8) => f64::from(bits as u8 as i8),
        (Flavour::Px4, MAV_PARAM_TYPE_UINT16) => f64::from(bits as u16),
        (Flavour::Px4, MAV_PARAM_TYPE_INT16) => f64::from(bits as u16 as i16),
        (Flavour::Px4, MAV_PARAM_TYPE_UINT32) => f64::from(bits),
        (Flavour::Px4, MAV_PARAM_TYPE_INT32 | MAV_PARAM_TYPE_UINT64 | MAV_PARAM_TYPE_INT64) => {
            f64::from(bits as i32)
        }
    }
}
