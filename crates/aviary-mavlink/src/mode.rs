//! Flight modes of the two autopilot families, as HEARTBEAT's `custom_mode` carries them.
//!
//! ArduCopter numbers its modes (GUIDED 4, RTL 6, LAND 9, ...). PX4 packs a main mode in
//! bits 16–23 and an AUTO sub-mode in bits 24–31. Aviary flies ArduPilot in GUIDED and
//! PX4 in HOLD (AUTO.LOITER) with DO_REPOSITION, so it only needs these few.

use mavlink::dialects::ardupilotmega::MavAutopilot;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flavour {
    ArduPilot,
    Px4,
}

impl Flavour {
    pub fn of(autopilot: MavAutopilot) -> Flavour {
        match autopilot {
            MavAutopilot::MAV_AUTOPILOT_PX4 => Flavour::Px4,
            // Everything else that flies guided with ArduPilot's numbers (ArduPilot
            // itself, and the `aviary vehicles` simulator, which says it is ArduPilot).
            _ => Flavour::ArduPilot,
        }
    }
}

/// What a mode means to the backend.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// Takes position targets from the ground station (GUIDED, or PX4's HOLD).
    Guided,
    Land,
    Rtl,
    Other,
}

pub const COPTER_GUIDED: u32 = 4;
pub const COPTER_LOITER: u32 = 5;
pub const COPTER_RTL: u32 = 6;
pub const COPTER_LAND: u32 = 9;
pub const COPTER_BRAKE: u32 = 17;
pub const COPTER_SMART_RTL: u32 = 21;
pub const COPTER_AUTO_RTL: u32 = 27;

const PX4_AUTO: u32 = 4;
const PX4_OFFBOARD: u32 = 6;
const PX4_LOITER: u32 = 3;
const PX4_RTL: u32 = 5;
const PX4_LAND: u32 = 6;

/// The meaning of a HEARTBEAT's `custom_mode`.
pub fn classify(flavour: Flavour, custom_mode: u32) -> Mode {
    match flavour {
        Flavour::ArduPilot => match custom_mode {
            COPTER_GUIDED => Mode::Guided,
            COPTER_RTL | COPTER_SMART_RTL | COPTER_AUTO_RTL => Mode::Rtl,
            COPTER_LAND => Mode::Land,
            _ => Mode::Other,
        },
        Flavour::Px4 => {
            let main = (custom_mode >> 16) & 0xff;
            let sub = (custom_mode >> 24) & 0xff;
            match (main, sub) {
                (PX4_OFFBOARD, _) | (PX4_AUTO, PX4_LOITER) => Mode::Guided,
                (PX4_AUTO, PX4_RTL) => Mode::Rtl,
                (PX4_AUTO, PX4_LAND) => Mode::Land,
                _ => Mode::Other,
            }
        }
    }
}

/// Parameters 2 and 3 of MAV_CMD_DO_SET_MODE (parameter 1 is "custom mode enabled").
pub fn set_mode_params(flavour: Flavour, mode: Mode) -> Option<(f32, f32)> {
    let (main, sub) = match (flavour, mode) {
        (Flavour::ArduPilot, Mode::Guided) => (COPTER_GUIDED, 0),
        (Flavour::ArduPilot, Mode::Land) => (COPTER_LAND, 0),
        (Flavour::ArduPilot, Mode::Rtl) => (COPTER_RTL, 0),
        (Flavour::Px4, Mode::Guided) => (PX4_AUTO, PX4_LOITER),
        (Flavour::Px4, Mode::Land) => (PX4_AUTO, PX4_LAND),
        (Flavour::Px4, Mode::Rtl) => (PX4_AUTO, PX4_RTL),
        (_, Mode::Other) => return None,
    };
    Some((main as f32, sub as f32))
}

/// A copter mode by its ArduCopter name, for messages.
pub fn name(flavour: Flavour, custom_mode: u32) -> String {
    match (flavour, classify(flavour, custom_mode)) {
        (Flavour::ArduPilot, _) => match custom_mode {
            0 => "STABILIZE".into(),
            3 => "AUTO".into(),
            COPTER_GUIDED => "GUIDED".into(),
            COPTER_LOITER => "LOITER".into(),
            COPTER_RTL => "RTL".into(),
            COPTER_LAND => "LAND".into(),
            COPTER_BRAKE => "BRAKE".into(),
            COPTER_SMART_RTL => "SMART_RTL".into(),
            n => format!("mode {n}"),
        },
        (Flavour::Px4, Mode::Guided) => "HOLD".into(),
        (Flavour::Px4, Mode::Rtl) => "RTL".into(),
        (Flavour::Px4, Mode::Land) => "LAND".into(),
        (Flavour::Px4, Mode::Other) => format!("mode {custom_mode:#x}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn px4_modes_round_trip_through_set_mode() {
        for mode in [Mode::Guided, Mode::Land, Mode::Rtl] {
            let (main, sub) = set_mode_params(Flavour::Px4, mode).unwrap();
            let custom = ((main as u32) << 16) | ((sub as u32) << 24);
            assert_eq!(classify(Flavour::Px4, custom), mode);
        }
    }

    #[test]
    fn copter_failsafe_modes_count_as_rtl() {
        assert_eq!(classify(Flavour::ArduPilot, COPTER_SMART_RTL), Mode::Rtl);
        assert_eq!(classify(Flavour::ArduPilot, 0), Mode::Other);
    }
}
