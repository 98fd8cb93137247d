//! Writes the seeds of `fuzz_link` and `fuzz_vehicles` (`in/link`, `in/vehicles`): a
//! vehicle's telemetry over the example world, and a ground station's session with
//! `aviary vehicles`, as MAVLink 2 frames. Run from `fuzz/`:
//! `cargo run --example mavlink_seeds`.

// Ground stations in the field still send REQUEST_DATA_STREAM, MAV_CMD_GET_HOME_POSITION
// and the _INT frames, so the seeds do too: the fuzzers must start from what really arrives.
#![allow(deprecated)]

use aviary_mavlink::mavlink::dialects::ardupilotmega::*;
use aviary_mavlink::mavlink::{self, MavHeader};
use aviary_mavlink::Origin;

const ORIGIN: Origin = Origin { lat: 46.6167, lon: 14.265, alt: 440.0 };

fn frames(system: u8, component: u8, messages: &[MavMessage]) -> Vec<u8> {
    let mut out = Vec::new();
    for (k, m) in messages.iter().enumerate() {
        let header =
            MavHeader { system_id: u32::from(system), component_id: component, sequence: k as u8 };
        mavlink::write_v2_msg(&mut out, header, m).expect("into a Vec");
    }
    out
}

fn heartbeat(armed: bool) -> MavMessage {
    MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 4,
        mavtype: MavType::MAV_TYPE_QUADROTOR,
        autopilot: MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA,
        base_mode: if armed {
            MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED | MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        } else {
            MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
        },
        system_status: if armed { MavState::MAV_STATE_ACTIVE } else { MavState::MAV_STATE_STANDBY },
        mavlink_version: 3,
    })
}

fn position(x: f64, y: f64, z: f64, ms: u32) -> MavMessage {
    let (lat, lon) = ORIGIN.to_e7(x, y);
    MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
        time_boot_ms: ms,
        lat,
        lon,
        alt: ((ORIGIN.alt + z) * 1000.0) as i32,
        relative_alt: (z * 1000.0) as i32,
        vx: 1000,
        vy: 0,
        vz: 0,
        hdg: 9000,
    })
}

fn sys_status(remaining: i8) -> MavMessage {
    MavMessage::SYS_STATUS(SYS_STATUS_DATA {
        battery_remaining: remaining,
        voltage_battery: 12_600,
        current_battery: 2_500,
        ..Default::default()
    })
}

fn text(s: &str) -> MavMessage {
    let mut t =
        STATUSTEXT_DATA { severity: MavSeverity::MAV_SEVERITY_CRITICAL, ..Default::default() };
    t.text = s.into();
    MavMessage::STATUSTEXT(t)
}

/// A flight from home to the first Body target (230, 330), with the battery
/// running down, then a battery failsafe (RTL).
fn telemetry() -> Vec<MavMessage> {
    let mut m = vec![heartbeat(false), sys_status(100)];
    for k in 0..=40u32 {
        let f = f64::from(k) / 40.0;
        m.push(position(230.0 * f, 330.0 * f, 20.0, 1_000 + k * 1_000));
        if k % 10 == 0 {
            m.push(heartbeat(true));
            m.push(sys_status(100 - (k / 2) as i8));
            m.push(MavMessage::EXTENDED_SYS_STATE(EXTENDED_SYS_STATE_DATA {
                landed_state: MavLandedState::MAV_LANDED_STATE_IN_AIR,
                ..Default::default()
            }));
        }
    }
    m.push(text("Battery 1 is critical"));
    m.push(MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 6,
        ..match heartbeat(true) {
            MavMessage::HEARTBEAT(h) => h,
            _ => unreachable!(),
        }
    }));
    m
}

/// A position that jumps 300 km and stays there, and a charge of 127 %.
fn implausible() -> Vec<MavMessage> {
    let mut m = vec![heartbeat(true), position(0.0, 0.0, 10.0, 1_000), sys_status(127)];
    for k in 0..30 {
        m.push(position(300_000.0, 0.0, 10.0, 1_100 + k * 100));
    }
    m
}

fn command(system: u8, command: MavCmd, p: [f32; 7]) -> MavMessage {
    MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        target_system: system,
        target_component: 1,
        command,
        confirmation: 0,
        param1: p[0],
        param2: p[1],
        param3: p[2],
        param4: p[3],
        param5: p[4],
        param6: p[5],
        param7: p[6],
    })
}

/// What a ground station asks of drone 1: parameters, streams, GUIDED, arm, take-off,
/// a reposition (COMMAND_INT, above home) and a position target in the take-off's own
/// tick, a speed.
fn session() -> Vec<MavMessage> {
    let (lat, lon) = ORIGIN.to_e7(100.0, 50.0);
    let mut param = PARAM_SET_DATA {
        target_system: 1,
        target_component: 1,
        param_value: 12.0,
        param_type: MavParamType::MAV_PARAM_TYPE_REAL32,
        ..Default::default()
    };
    param.param_id = "WPNAV_SPEED".into();
    vec![
        MavMessage::HEARTBEAT(HEARTBEAT_DATA {
            mavtype: MavType::MAV_TYPE_GCS,
            autopilot: MavAutopilot::MAV_AUTOPILOT_INVALID,
            mavlink_version: 3,
            ..Default::default()
        }),
        MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
            target_system: 1,
            target_component: 1,
        }),
        MavMessage::PARAM_SET(param),
        MavMessage::REQUEST_DATA_STREAM(REQUEST_DATA_STREAM_DATA {
            req_message_rate: 4,
            target_system: 0,
            target_component: 0,
            req_stream_id: MavDataStream::MAV_DATA_STREAM_ALL,
            start_stop: 1,
        }),
        command(1, MavCmd::MAV_CMD_REQUEST_MESSAGE, [148.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        command(1, MavCmd::MAV_CMD_GET_HOME_POSITION, [0.0; 7]),
        command(1, MavCmd::MAV_CMD_DO_SET_MODE, [1.0, 4.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        command(1, MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        command(1, MavCmd::MAV_CMD_NAV_TAKEOFF, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 10.0]),
        MavMessage::COMMAND_INT(COMMAND_INT_DATA {
            target_system: 1,
            target_component: 1,
            frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
            command: MavCmd::MAV_CMD_DO_REPOSITION,
            param1: -1.0,
            x: lat,
            y: lon,
            z: 15.0,
            ..Default::default()
        }),
        MavMessage::SET_POSITION_TARGET_GLOBAL_INT(SET_POSITION_TARGET_GLOBAL_INT_DATA {
            target_system: 1,
            target_component: 1,
            coordinate_frame: MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
            type_mask: PositionTargetTypemask::from_bits_truncate(0b0000_1111_1111_1000),
            lat_int: lat,
            lon_int: lon,
            alt: 20.0,
            ..Default::default()
        }),
        command(1, MavCmd::MAV_CMD_DO_CHANGE_SPEED, [1.0, 8.0, -1.0, 0.0, 0.0, 0.0, 0.0]),
    ]
}

/// The session, then RTL for drone 1 and LAND for every drone (system 0), at once.
fn session_then_land() -> Vec<MavMessage> {
    let mut m = session();
    m.push(command(1, MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH, [0.0; 7]));
    m.push(command(0, MavCmd::MAV_CMD_NAV_LAND, [0.0; 7]));
    m
}

fn main() {
    let write = |dir: &str, name: &str, bytes: Vec<u8>| {
        std::fs::create_dir_all(dir).expect("a directory");
        std::fs::write(format!("{dir}/{name}"), bytes).expect("a seed written");
    };
    write("in/link", "flight_over_a_target.bin", frames(1, 1, &telemetry()));
    write("in/link", "implausible.bin", frames(1, 1, &implausible()));
    write("in/vehicles", "session.bin", frames(255, 190, &session()));
    write("in/vehicles", "session_then_land.bin", frames(255, 190, &session_then_land()));
    let mut noisy = b"garbage before \xfd\x09 a cut frame".to_vec();
    noisy.extend(frames(255, 190, &session()[..8]));
    write("in/vehicles", "noise_then_arm.bin", noisy);
}
