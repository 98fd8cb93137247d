//! Flight modes of the two autopilot families, as HEARTBEAT's `custom_mode` carries them.
//!
//! ArduCopter numbers its modes (GUIDED 4, RTL 6, LAND 9, ...). PX4 packs a main mode in
//! bits 16–23 and a sub mode in bits 24–31 ([`px4`], the one encoding of PX4's modes, which
//! `aviary vehicles --autopilot px4` serves too). Aviary flies ArduPilot in GUIDED and PX4
//! in HOLD (AUTO.LOITER) with DO_REPOSITION, and a PX4 path as a mission (AUTO.MISSION),
//! so it only needs these few.

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
    /// Flies the uploaded mission (PX4's AUTO.MISSION): paths on PX4.
    Mission,
    Other,
}

pub const COPTER_GUIDED: u32 = 4;
pub const COPTER_LOITER: u32 = 5;
pub const COPTER_RTL: u32 = 6;
pub const COPTER_LAND: u32 = 9;
pub const COPTER_BRAKE: u32 = 17;
pub const COPTER_SMART_RTL: u32 = 21;
pub const COPTER_AUTO_RTL: u32 = 27;

/// PX4's modes as HEARTBEAT's `custom_mode` carries them and MAV_CMD_DO_SET_MODE takes
/// them (param2 the main mode, param3 the sub mode), as PX4 defines them in
/// src/modules/commander/px4_custom_mode.h: the main mode in bits 16–23, the sub mode (of
/// AUTO, or of POSCTL) in bits 24–31.
pub mod px4 {
    pub const MANUAL: u8 = 1;
    pub const ALTCTL: u8 = 2;
    pub const POSCTL: u8 = 3;
    pub const AUTO: u8 = 4;
    pub const ACRO: u8 = 5;
    pub const OFFBOARD: u8 = 6;
    pub const STABILIZED: u8 = 7;
    pub const RATTITUDE_LEGACY: u8 = 8;
    pub const SIMPLE: u8 = 9;
    pub const TERMINATION: u8 = 10;

    /// AUTO's sub modes.
    pub const AUTO_READY: u8 = 1;
    pub const AUTO_TAKEOFF: u8 = 2;
    pub const AUTO_LOITER: u8 = 3;
    pub const AUTO_MISSION: u8 = 4;
    pub const AUTO_RTL: u8 = 5;
    pub const AUTO_LAND: u8 = 6;
    pub const AUTO_FOLLOW_TARGET: u8 = 8;
    pub const AUTO_PRECLAND: u8 = 9;
    pub const AUTO_VTOL_TAKEOFF: u8 = 10;
    /// The first of the eight external modes (ROS 2 modes), 11 to 18.
    pub const AUTO_EXTERNAL1: u8 = 11;
    pub const AUTO_EXTERNAL8: u8 = 18;

    /// POSCTL's sub modes.
    pub const POSCTL_POSCTL: u8 = 0;
    pub const POSCTL_ORBIT: u8 = 1;
    pub const POSCTL_SLOW: u8 = 2;

    /// `custom_mode` of a main and a sub mode.
    pub const fn encode(main: u8, sub: u8) -> u32 {
        ((main as u32) << 16) | ((sub as u32) << 24)
    }

    /// The main and the sub mode of a `custom_mode`.
    pub const fn decode(custom_mode: u32) -> (u8, u8) {
        (((custom_mode >> 16) & 0xff) as u8, (custom_mode >> 24) as u8)
    }
}

/// The meaning of a HEARTBEAT's `custom_mode`.
pub fn classify(flavour: Flavour, custom_mode: u32) -> Mode {
    match flavour {
        Flavour::ArduPilot => match custom_mode {
            COPTER_GUIDED => Mode::Guided,
            COPTER_RTL | COPTER_SMART_RTL | COPTER_AUTO_RTL => Mode::Rtl,
            COPTER_LAND => Mode::Land,
            _ => Mode::Other,
        },
        Flavour::Px4 => match px4::decode(custom_mode) {
            (px4::OFFBOARD, _) | (px4::AUTO, px4::AUTO_LOITER) => Mode::Guided,
            (px4::AUTO, px4::AUTO_RTL) => Mode::Rtl,
            (px4::AUTO, px4::AUTO_LAND) => Mode::Land,
            (px4::AUTO, px4::AUTO_MISSION) => Mode::Mission,
            _ => Mode::Other,
        },
    }
}

/// Parameters 2 and 3 of MAV_CMD_DO_SET_MODE (parameter 1 is "custom mode enabled").
pub fn set_mode_params(flavour: Flavour, mode: Mode) -> Option<(f32, f32)> {
    let (main, sub) = match (flavour, mode) {
        (Flavour::ArduPilot, Mode::Guided) => (COPTER_GUIDED, 0),
        (Flavour::ArduPilot, Mode::Land) => (COPTER_LAND, 0),
        (Flavour::ArduPilot, Mode::Rtl) => (COPTER_RTL, 0),
        (Flavour::Px4, Mode::Guided) => (px4::AUTO.into(), px4::AUTO_LOITER.into()),
        (Flavour::Px4, Mode::Land) => (px4::AUTO.into(), px4::AUTO_LAND.into()),
        (Flavour::Px4, Mode::Rtl) => (px4::AUTO.into(), px4::AUTO_RTL.into()),
        (Flavour::Px4, Mode::Mission) => (px4::AUTO.into(), px4::AUTO_MISSION.into()),
        // ArduPilot's paths are flown in GUIDED, point by point.
        (Flavour::ArduPilot, Mode::Mission) | (_, Mode::Other) => return None,
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
        (Flavour::Px4, Mode::Mission) => "MISSION".into(),
        (Flavour::Px4, Mode::Other) => format!("mode {custom_mode:#x}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn px4_modes_round_trip_through_set_mode() {
        for mode in [Mode::Guided, Mode::Land, Mode::Rtl, Mode::Mission] {
            let (main, sub) = set_mode_params(Flavour::Px4, mode).unwrap();
            let custom = px4::encode(main as u8, sub as u8);
            assert_eq!(classify(Flavour::Px4, custom), mode);
        }
    }

    #[test]
    fn px4_modes_encode_as_px4_custom_mode_h_packs_them() {
        // AUTO.LOITER, AUTO.TAKEOFF and POSCTL.ORBIT as PX4 SITL's HEARTBEAT carries them.
        assert_eq!(px4::encode(px4::AUTO, px4::AUTO_LOITER), 0x0304_0000);
        assert_eq!(px4::encode(px4::AUTO, px4::AUTO_TAKEOFF), 0x0204_0000);
        assert_eq!(px4::encode(px4::POSCTL, px4::POSCTL_ORBIT), 0x0103_0000);
        for main in 0..=u8::MAX {
            for sub in [0, 1, 7, 255] {
                assert_eq!(px4::decode(px4::encode(main, sub)), (main, sub));
            }
        }
    }

    #[test]
    fn copter_failsafe_modes_count_as_rtl() {
        assert_eq!(classify(Flavour::ArduPilot, COPTER_SMART_RTL), Mode::Rtl);
        assert_eq!(classify(Flavour::ArduPilot, 0), Mode::Other);
    }
}
