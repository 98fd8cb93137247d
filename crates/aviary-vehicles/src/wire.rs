//! What goes on the wire: the dialect's messages, plus the one answer the dialect cannot
//! express. A COMMAND_LONG or COMMAND_INT whose command number the `mavlink` crate does
//! not know fails to parse (its `command` is an enum), so nothing would answer it;
//! ArduPilot answers every command it does not handle with MAV_RESULT_UNSUPPORTED and the
//! number it was sent. [`Wire::UnknownAck`] is that COMMAND_ACK, and [`unparsed_command`]
//! reads such a command from the raw frame.

use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavCmd, MavMessage, MavResult, COMMAND_ACK_DATA, COMMAND_INT_DATA, COMMAND_LONG_DATA,
};
use aviary_mavlink::mavlink::error::ParserError;
use aviary_mavlink::mavlink::{MavlinkVersion, Message, MessageData};

// Nearly every message is `Mav`: boxing it would allocate for each one sent.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq)]
pub enum Wire {
    Mav(MavMessage),
    /// COMMAND_ACK for a command number outside the dialect.
    UnknownAck {
        command: u16,
        result: MavResult,
        target_system: u8,
        target_component: u8,
    },
}

impl From<MavMessage> for Wire {
    fn from(m: MavMessage) -> Wire {
        Wire::Mav(m)
    }
}

impl Message for Wire {
    fn message_id(&self) -> u32 {
        match self {
            Wire::Mav(m) => m.message_id(),
            Wire::UnknownAck { .. } => COMMAND_ACK_DATA::ID,
        }
    }

    fn message_name(&self) -> &'static str {
        match self {
            Wire::Mav(m) => m.message_name(),
            Wire::UnknownAck { .. } => COMMAND_ACK_DATA::NAME,
        }
    }

    fn target_system_id(&self) -> Option<u8> {
        match self {
            Wire::Mav(m) => m.target_system_id(),
            Wire::UnknownAck { .. } => None,
        }
    }

    fn target_component_id(&self) -> Option<u8> {
        match self {
            Wire::Mav(m) => m.target_component_id(),
            Wire::UnknownAck { .. } => None,
        }
    }

    fn target_system_id_mut(&mut self) -> Option<&mut u8> {
        match self {
            Wire::Mav(m) => m.target_system_id_mut(),
            Wire::UnknownAck { .. } => None,
        }
    }

    fn target_component_id_mut(&mut self) -> Option<&mut u8> {
        match self {
            Wire::Mav(m) => m.target_component_id_mut(),
            Wire::UnknownAck { .. } => None,
        }
    }

    fn ser(&self, version: MavlinkVersion, bytes: &mut [u8]) -> usize {
        match self {
            Wire::Mav(m) => m.ser(version, bytes),
            Wire::UnknownAck { command, result, target_system, target_component } => {
                // An ACK of any known command, then its first two payload bytes (the
                // command, a little-endian u16 on the wire) replaced by the real number.
                let known = COMMAND_ACK_DATA {
                    command: MavCmd::MAV_CMD_NAV_WAYPOINT,
                    result: *result,
                    target_system: *target_system,
                    target_component: *target_component,
                    ..COMMAND_ACK_DATA::default()
                };
                let n = known.ser(version, bytes);
                bytes[..2].copy_from_slice(&command.to_le_bytes());
                match version {
                    MavlinkVersion::V1 => n,
                    // MAVLink 2 drops trailing zero bytes, and keeps at least one.
                    MavlinkVersion::V2 => {
                        let full = &bytes[..COMMAND_ACK_DATA::ENCODED_LEN];
                        full.iter().rposition(|b| *b != 0).map_or(1, |last| last + 1)
                    }
                }
            }
        }
    }

    fn parse(version: MavlinkVersion, msgid: u32, payload: &[u8]) -> Result<Wire, ParserError> {
        MavMessage::parse(version, msgid, payload).map(Wire::Mav)
    }

    fn message_id_from_name(name: &str) -> Option<u32> {
        MavMessage::message_id_from_name(name)
    }

    fn default_message_from_id(id: u32) -> Option<Wire> {
        MavMessage::default_message_from_id(id).map(Wire::Mav)
    }

    fn extra_crc(id: u32) -> u8 {
        MavMessage::extra_crc(id)
    }
}

/// A COMMAND_LONG or COMMAND_INT that did not parse: its command number and target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unparsed {
    pub command: u16,
    pub target_system: u8,
    pub target_component: u8,
}

/// Reads the command number and target of a COMMAND_LONG or COMMAND_INT from its payload
/// (the two share these offsets); `None` for any other message.
pub fn unparsed_command(msgid: u32, payload: &[u8]) -> Option<Unparsed> {
    let len = match msgid {
        COMMAND_LONG_DATA::ID => COMMAND_LONG_DATA::ENCODED_LEN,
        COMMAND_INT_DATA::ID => COMMAND_INT_DATA::ENCODED_LEN,
        _ => return None,
    };
    // MAVLink 2 truncates trailing zeros: put them back.
    let mut full = vec![0u8; len];
    let n = payload.len().min(len);
    full[..n].copy_from_slice(&payload[..n]);
    Some(Unparsed {
        command: u16::from_le_bytes([full[28], full[29]]),
        target_system: full[30],
        target_component: full[31],
    })
}

/// Whether the dialect knows a command number: a COMMAND_ACK of it parses.
pub fn known_command(n: u16) -> bool {
    MavMessage::parse(MavlinkVersion::V2, COMMAND_ACK_DATA::ID, &n.to_le_bytes()).is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unknown_ack_carries_the_number_it_was_sent() {
        let ack = Wire::UnknownAck {
            command: 31_999,
            result: MavResult::MAV_RESULT_UNSUPPORTED,
            target_system: 255,
            target_component: 190,
        };
        let mut buf = [0u8; 255];
        let n = ack.ser(MavlinkVersion::V2, &mut buf);
        assert_eq!(n, COMMAND_ACK_DATA::ENCODED_LEN);
        assert_eq!(u16::from_le_bytes([buf[0], buf[1]]), 31_999);
        assert_eq!(buf[2], MavResult::MAV_RESULT_UNSUPPORTED as u8);
        assert_eq!(&buf[8..10], &[255, 190]);
    }

    #[test]
    fn short_payloads_are_read_as_zero_filled() {
        let mut p = vec![0u8; 30];
        p[28..30].copy_from_slice(&42_000u16.to_le_bytes());
        let u = unparsed_command(COMMAND_LONG_DATA::ID, &p).unwrap();
        assert_eq!((u.command, u.target_system, u.target_component), (42_000, 0, 0));
        assert_eq!(unparsed_command(0, &p), None);
        assert!(unparsed_command(COMMAND_INT_DATA::ID, &[]).is_some());
        assert!(known_command(MavCmd::MAV_CMD_NAV_TAKEOFF as u16));
        assert!(!known_command(31_999));
    }
}
