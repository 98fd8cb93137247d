//! One message from a ground station: which vehicles it is for, and what they answer.
//! SET_MODE and REQUEST_DATA_STREAM are deprecated, but pymavlink's `set_mode`, MAVProxy
//! and older ground stations still send them, and ArduPilot still takes them. PX4 takes
//! SET_MODE, ignores REQUEST_DATA_STREAM, and speaks the mission protocol (`px4`).

use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavCmd, MavMessage, MavResult, COMMAND_ACK_DATA, FILE_TRANSFER_PROTOCOL_DATA,
};
use aviary_mavlink::mode::px4;

use crate::autopilot::{Autopilot, Out, Reply, To};
use crate::client::Client;
use crate::commands::{Answer, Command};
use crate::px4::{for_me, Incoming};
use crate::telemetry::stream_group;
use crate::wire::{known_command, Unparsed, Wire};

/// The fastest stream rate a client may ask for, Hz.
const MAX_HZ: f64 = 50.0;

/// The vehicles a message is for: its target system (0: every vehicle, as every
/// ArduPilot takes a broadcast), component 0 (any) or 1 (the autopilot). A vehicle whose
/// radio is down (a world `link_loss` fault) hears nothing.
fn targets(ap: &Autopilot, system: u8, component: Option<u8>) -> Vec<usize> {
    if component.is_some_and(|c| c > 1) {
        return Vec::new();
    }
    (0..ap.copters.len())
        .filter(|i| system == 0 || ap.copters[*i].system == system)
        .filter(|i| ap.link(*i))
        .collect()
}

fn answered(system: u8, command: MavCmd, a: Answer, from: (u8, u8)) -> Vec<Reply> {
    let mut out = a.before;
    if !a.silent {
        let msg = MavMessage::COMMAND_ACK(COMMAND_ACK_DATA {
            command,
            result: a.result,
            progress: a.progress,
            result_param2: 0,
            target_system: from.0,
            target_component: from.1,
        });
        out.push(Reply { to: To::Asker, out: Out { system, msg: msg.into() } });
    }
    out.extend(a.after);
    out
}

/// Whether PX4 takes a command for `system` (mavlink_receiver.cpp, evaluate_target_ok):
/// addressed to it exactly, to the autopilot or any component; the two old requests for
/// its version and capabilities also broadcast.
fn px4_target(ap: &Autopilot, i: usize, command: MavCmd, target: (u8, u8)) -> bool {
    let me = ap.copters[i].system;
    #[allow(deprecated)]
    let broadcast = matches!(
        command,
        MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES | MavCmd::MAV_CMD_REQUEST_PROTOCOL_VERSION
    );
    if broadcast {
        target.0 == 0 || target.0 == me
    } else {
        target.0 == me && matches!(target.1, 0 | 1)
    }
}

/// A COMMAND_INT with x and y NaN's bits (a NaN sent as an int), or a COMMAND_LONG whose
/// param5 and param6 are INT32_MAX (COMMAND_INT's "not given" sent in a COMMAND_LONG):
/// PX4 DENIES both at once.
fn px4_malformed(c: &Command) -> bool {
    match c.int {
        Some((_, x, y, _)) => x == 0x7ff8_0000 && y == 0x7ff8_0000,
        None => {
            let near = |v: f32| (v - i32::MAX as f32).abs() <= 128.0;
            near(c.p[4]) && near(c.p[5])
        }
    }
}

/// The replies to `msg`, which came from system and component `from` on `client`'s link.
#[allow(deprecated)]
pub fn dispatch(
    ap: &mut Autopilot,
    client: &Client,
    from: (u8, u8),
    msg: &MavMessage,
) -> Vec<Reply> {
    if ap.px4_flavour() {
        return dispatch_px4(ap, client, from, msg);
    }
    let (system, component, command) = match msg {
        MavMessage::COMMAND_LONG(c) => (
            c.target_system,
            Some(c.target_component),
            Some(Command {
                id: c.command,
                p: [c.param1, c.param2, c.param3, c.param4, c.param5, c.param6, c.param7],
                int: None,
            }),
        ),
        MavMessage::COMMAND_INT(c) => (
            c.target_system,
            Some(c.target_component),
            Some(Command {
                id: c.command,
                p: [c.param1, c.param2, c.param3, c.param4, 0.0, 0.0, 0.0],
                int: Some((c.frame as u32, c.x, c.y, c.z)),
            }),
        ),
        MavMessage::SET_MODE(m) => (m.target_system, None, None),
        MavMessage::SET_POSITION_TARGET_GLOBAL_INT(t) => {
            (t.target_system, Some(t.target_component), None)
        }
        MavMessage::REQUEST_DATA_STREAM(r) => (r.target_system, Some(r.target_component), None),
        MavMessage::PARAM_REQUEST_LIST(r) => (r.target_system, Some(r.target_component), None),
        MavMessage::PARAM_REQUEST_READ(r) => (r.target_system, Some(r.target_component), None),
        MavMessage::PARAM_SET(r) => (r.target_system, Some(r.target_component), None),
        MavMessage::FILE_TRANSFER_PROTOCOL(f) => (f.target_system, Some(f.target_component), None),
        _ => return Vec::new(),
    };
    let mut out = Vec::new();
    for i in targets(ap, system, component) {
        let me = ap.copters[i].system;
        match (msg, &command) {
            (_, Some(c)) if c.id == MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL => {
                let result = set_interval(ap, client, me, c.p[0], c.p[1]);
                out.extend(answered(me, c.id, Answer::of(result), from));
            }
            (_, Some(c)) => out.extend(answered(me, c.id, ap.command(i, c), from)),
            (MavMessage::SET_MODE(m), _) => {
                let (result, why) = ap.set_mode(i, m.custom_mode);
                let a = Answer::failed(me, result, why);
                out.extend(answered(me, MavCmd::MAV_CMD_DO_SET_MODE, a, from));
            }
            (MavMessage::SET_POSITION_TARGET_GLOBAL_INT(t), _) => {
                // Ignored outside GUIDED, on the ground, or in a frame that is not global,
                // silently, as ArduCopter does.
                let z = ap.frame_z(t.coordinate_frame as u32, t.alt);
                if let Some(z) = z.filter(|z| z.is_finite()) {
                    let _ = ap.goto(i, t.lat_int, t.lon_int, z);
                }
            }
            (MavMessage::REQUEST_DATA_STREAM(r), _) => {
                let hz =
                    if r.start_stop == 1 { f64::from(r.req_message_rate).min(MAX_HZ) } else { 0.0 };
                let mut s = client.schedule.lock();
                for id in stream_group(r.req_stream_id as u8) {
                    s.set(me, *id, Some(hz));
                }
            }
            (MavMessage::PARAM_REQUEST_LIST(_), _) => out.extend(ap.param_list(i)),
            (MavMessage::PARAM_REQUEST_READ(r), _) => {
                out.extend(ap.param_read(i, r.param_id.to_str().unwrap_or(""), r.param_index));
            }
            (MavMessage::FILE_TRANSFER_PROTOCOL(f), _) => {
                out.push(Reply::asker(me, ftp_refusal(&f.payload, from)));
            }
            (MavMessage::PARAM_SET(r), _) => {
                out.extend(ap.param_set(i, r.param_id.to_str().unwrap_or(""), r.param_value));
            }
            _ => {}
        }
    }
    out
}

/// The replies of PX4 vehicles to `msg` from `from` on `client`'s link.
#[allow(deprecated)]
fn dispatch_px4(
    ap: &mut Autopilot,
    client: &Client,
    from: (u8, u8),
    msg: &MavMessage,
) -> Vec<Reply> {
    let command = match msg {
        MavMessage::COMMAND_LONG(c) => Some((
            (c.target_system, c.target_component),
            Command {
                id: c.command,
                p: [c.param1, c.param2, c.param3, c.param4, c.param5, c.param6, c.param7],
                int: None,
            },
        )),
        MavMessage::COMMAND_INT(c) => Some((
            (c.target_system, c.target_component),
            Command {
                id: c.command,
                p: [c.param1, c.param2, c.param3, c.param4, 0.0, 0.0, 0.0],
                int: Some((c.frame as u32, c.x, c.y, c.z)),
            },
        )),
        _ => None,
    };
    let mut out = Vec::new();
    let up: Vec<usize> = (0..ap.copters.len()).filter(|i| ap.link(*i)).collect();
    for i in up {
        let me = ap.copters[i].system;
        if let Some((target, c)) = &command {
            if !px4_target(ap, i, c.id, *target) {
                continue;
            }
            let a = if px4_malformed(c) {
                Answer::of(MavResult::MAV_RESULT_DENIED)
            } else if c.id == MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL {
                Answer::of(set_interval(ap, client, me, c.p[0], c.p[1]))
            } else {
                ap.px4_command(i, c, from)
            };
            out.extend(answered(me, c.id, a, from));
            continue;
        }
        let mine = |target: (u8, u8)| target.0 == me && matches!(target.1, 0 | 1);
        let mission = |target: (u8, u8)| for_me(me, target);
        match msg {
            // PX4 turns SET_MODE into DO_SET_MODE for the commander, which takes a
            // broadcast (target system 0) too.
            MavMessage::SET_MODE(m) if m.target_system == 0 || m.target_system == me => {
                let (main, sub) = px4::decode(m.custom_mode);
                let a = ap.px4_set_mode(i, m.base_mode.bits(), main, sub, from);
                out.extend(answered(me, MavCmd::MAV_CMD_DO_SET_MODE, a, from));
            }
            MavMessage::PARAM_REQUEST_LIST(r) if mine((r.target_system, r.target_component)) => {
                out.extend(ap.px4_param_list(i));
            }
            MavMessage::PARAM_REQUEST_READ(r) if mine((r.target_system, r.target_component)) => {
                let name = r.param_id.to_str().unwrap_or("");
                out.extend(ap.px4_param_read(i, name, r.param_index));
            }
            MavMessage::PARAM_SET(r) if mine((r.target_system, r.target_component)) => {
                let name = r.param_id.to_str().unwrap_or("");
                out.extend(ap.px4_param_set(i, name, r.param_value, r.param_type));
            }
            MavMessage::FILE_TRANSFER_PROTOCOL(f) if f.target_system == me => {
                out.push(Reply::asker(me, ftp_refusal(&f.payload, from)));
            }
            MavMessage::MISSION_COUNT(m) if mission((m.target_system, m.target_component)) => {
                out.extend(ap.px4_mission_count(i, from, m.count, m.mission_type));
            }
            MavMessage::MISSION_ITEM_INT(m) if mission((m.target_system, m.target_component)) => {
                out.extend(ap.px4_mission_item(i, from, Incoming::of_int(m)));
            }
            MavMessage::MISSION_ITEM(m) if mission((m.target_system, m.target_component)) => {
                out.extend(ap.px4_mission_item(i, from, Incoming::of_float(m)));
            }
            MavMessage::MISSION_REQUEST_LIST(m)
                if mission((m.target_system, m.target_component)) =>
            {
                out.extend(ap.px4_mission_list(i, from, m.mission_type));
            }
            MavMessage::MISSION_REQUEST_INT(m)
                if mission((m.target_system, m.target_component)) =>
            {
                out.extend(ap.px4_mission_request(i, from, m.seq, m.mission_type, true));
            }
            MavMessage::MISSION_REQUEST(m) if mission((m.target_system, m.target_component)) => {
                out.extend(ap.px4_mission_request(i, from, m.seq, m.mission_type, false));
            }
            MavMessage::MISSION_ACK(m) if mission((m.target_system, m.target_component)) => {
                out.extend(ap.px4_mission_ack(i, from, m.mavtype, m.mission_type));
            }
            MavMessage::MISSION_CLEAR_ALL(m) if mission((m.target_system, m.target_component)) => {
                out.extend(ap.px4_mission_clear(i, from, m.mission_type));
            }
            MavMessage::MISSION_SET_CURRENT(m)
                if mission((m.target_system, m.target_component)) =>
            {
                out.extend(ap.px4_mission_set_current(i, m.seq));
            }
            // SET_POSITION_TARGET_GLOBAL_INT is for Offboard, which is not simulated; PX4
            // has no REQUEST_DATA_STREAM.
            _ => {}
        }
    }
    out
}

/// The vehicle has no files (AUTOPILOT_VERSION does not claim MAVLink FTP): every FTP
/// request is answered, as the FTP protocol asks of a server without an operation, by a
/// NAK with ERR_UnknownCommand, so that a ground station that tries FTP first (MAVProxy,
/// for the parameters) falls back at once instead of waiting for its timeouts.
fn ftp_refusal(request: &[u8; 251], from: (u8, u8)) -> MavMessage {
    const NAK: u8 = 129;
    const ERR_UNKNOWN_COMMAND: u8 = 7;
    let seq = u16::from_le_bytes([request[0], request[1]]).wrapping_add(1);
    let mut payload = [0u8; 251];
    payload[..2].copy_from_slice(&seq.to_le_bytes());
    payload[2] = request[2]; // session
    payload[3] = NAK;
    payload[4] = 1; // size of the data: the error code
    payload[5] = request[3]; // the opcode refused
    payload[12] = ERR_UNKNOWN_COMMAND;
    MavMessage::FILE_TRANSFER_PROTOCOL(FILE_TRANSFER_PROTOCOL_DATA {
        target_network: 0,
        target_system: from.0,
        target_component: from.1,
        payload,
    })
}

/// MAV_CMD_SET_MESSAGE_INTERVAL for this client's link (as ArduPilot's, per link): an
/// interval in µs, 0 for the default rate, -1 for none. DENIED for a message the vehicle
/// does not send.
fn set_interval(
    ap: &Autopilot,
    client: &Client,
    system: u8,
    id: f32,
    interval_us: f32,
) -> MavResult {
    let id = id as u32;
    if !ap.streams().iter().any(|(s, _)| *s == id) || !interval_us.is_finite() {
        // PX4 answers FAILED for a message it cannot configure.
        return if ap.px4_flavour() {
            MavResult::MAV_RESULT_FAILED
        } else {
            MavResult::MAV_RESULT_DENIED
        };
    }
    let hz = if interval_us < 0.0 {
        Some(0.0)
    } else if interval_us == 0.0 {
        None
    } else {
        Some((1e6 / f64::from(interval_us)).min(MAX_HZ))
    };
    let mut s = client.schedule.lock();
    s.set(system, id, hz);
    MavResult::MAV_RESULT_ACCEPTED
}

/// A COMMAND_LONG or COMMAND_INT that did not parse: ArduPilot's UNSUPPORTED for a
/// command number it does not know, DENIED for a known command with a field out of range
/// (such as an unknown frame).
pub fn dispatch_unparsed(ap: &Autopilot, from: (u8, u8), u: Unparsed) -> Vec<Reply> {
    let result = if known_command(u.command) {
        MavResult::MAV_RESULT_DENIED
    } else {
        MavResult::MAV_RESULT_UNSUPPORTED
    };
    targets(ap, u.target_system, Some(u.target_component))
        .into_iter()
        .map(|i| {
            Reply::asker(
                ap.copters[i].system,
                Wire::UnknownAck {
                    command: u.command,
                    result,
                    target_system: from.0,
                    target_component: from.1,
                },
            )
        })
        .collect()
}
