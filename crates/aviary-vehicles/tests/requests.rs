//! Commands and requests answered as ArduCopter answers them: ACKs addressed to the
//! asker, UNSUPPORTED for unknown commands, AUTOPILOT_VERSION, HOME_POSITION and the
//! health a ground station arms by, FTP refused at once.
// These tests talk to `aviary vehicles` in real time (its own clock is the wall's).
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

mod common;

use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    GpsFixType, MavCmd, MavMessage, MavProtocolCapability as Cap, MavResult,
    MavSysStatusSensor as S, COMMAND_INT_DATA, COMMAND_LONG_DATA, FILE_TRANSFER_PROTOCOL_DATA,
};
use aviary_mavlink::mavlink::{calculate_crc, MAVLinkV2MessageRaw, MavHeader, Message};
use aviary_mavlink::Origin;
use aviary_vehicles::Behaviour;
use common::{fleet, quick, serve, Gcs, ORIGIN};

const SECOND: Duration = Duration::from_secs(1);

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn acks_are_addressed_to_the_asker_and_sent_to_it_alone() {
    let vehicles = serve(&fleet(1, ""), 5.0, quick()).await;
    let mut asker = Gcs::connect_as(vehicles.address, 200, 42).await;
    let mut other = Gcs::connect(vehicles.address).await;
    let ack =
        asker.command(1, MavCmd::MAV_CMD_DO_SET_MODE, [1.0, 5.0, 0.0, 0.0, 0.0, 0.0, 0.0]).await;
    assert_eq!((ack.target_system, ack.target_component), (200, 42), "{ack:?}");
    // A broadcast (target system 0) is taken by every vehicle, and answered likewise.
    asker.system = 7;
    asker
        .send(&MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
            param1: 1.0,
            param2: 5.0,
            command: MavCmd::MAV_CMD_DO_SET_MODE,
            target_system: 0,
            target_component: 0,
            ..Default::default()
        }))
        .await;
    let ack = asker.ack(1, MavCmd::MAV_CMD_DO_SET_MODE).await;
    assert_eq!((ack.target_system, ack.target_component), (7, 42), "{ack:?}");
    let seen =
        other.wait(1, 2 * SECOND, |m| matches!(m, MavMessage::COMMAND_ACK(_)).then_some(())).await;
    assert!(seen.is_none(), "another client was sent the ACK");
    vehicles.stop();
}

/// A COMMAND_LONG or COMMAND_INT with a command number the dialect has no name for,
/// written byte by byte.
fn unknown_command(msgid: u32, number: u16) -> Vec<u8> {
    let msg = if msgid == 76 {
        MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
            command: MavCmd::MAV_CMD_NAV_WAYPOINT,
            target_system: 1,
            target_component: 1,
            ..Default::default()
        })
    } else {
        MavMessage::COMMAND_INT(COMMAND_INT_DATA {
            command: MavCmd::MAV_CMD_NAV_WAYPOINT,
            target_system: 1,
            target_component: 1,
            ..Default::default()
        })
    };
    let header = MavHeader { system_id: 255, component_id: 190, sequence: 0 };
    let mut raw = MAVLinkV2MessageRaw::new();
    raw.serialize_message(header, &msg);
    let len = usize::from(raw.payload_length());
    let bytes = raw.as_mut_slice();
    // STX and a 9-byte header, then the payload: the command is at 28..30 in both.
    bytes[10 + 28..10 + 30].copy_from_slice(&number.to_le_bytes());
    let crc = calculate_crc(&bytes[1..10 + len], MavMessage::extra_crc(msgid));
    bytes[10 + len..12 + len].copy_from_slice(&crc.to_le_bytes());
    bytes[..12 + len].to_vec()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn unknown_and_unhandled_commands_are_answered_unsupported() {
    let vehicles = serve(&fleet(1, ""), 5.0, quick()).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    for msgid in [76, 75] {
        gcs.send_bytes(&unknown_command(msgid, 31_999)).await;
        let mut answer = None;
        for _ in 0..100 {
            let f = gcs.frame(3 * SECOND).await.expect("an answer");
            if f.raw.message_id() == 77 {
                answer = Some(f.raw.payload().to_vec());
                break;
            }
        }
        let p = answer.expect("a COMMAND_ACK");
        let mut full = [0u8; 10];
        full[..p.len()].copy_from_slice(&p);
        assert_eq!(u16::from_le_bytes([full[0], full[1]]), 31_999, "msg {msgid}");
        assert_eq!(full[2], MavResult::MAV_RESULT_UNSUPPORTED as u8);
        assert_eq!(&full[8..10], &[255, 190]);
    }
    // A command the dialect knows that the vehicle does not handle.
    let ack =
        gcs.command(1, MavCmd::MAV_CMD_DO_SET_SERVO, [8.0, 1500.0, 0.0, 0.0, 0.0, 0.0, 0.0]).await;
    assert_eq!(ack.result, MavResult::MAV_RESULT_UNSUPPORTED);
    vehicles.stop();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn autopilot_version_is_sent_on_request_to_the_asker() {
    let vehicles = serve(&fleet(2, ""), 5.0, quick()).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    let mut other = Gcs::connect(vehicles.address).await;
    let version = |m: &MavMessage| match m {
        MavMessage::AUTOPILOT_VERSION(v) => Some(v.clone()),
        _ => None,
    };
    #[allow(deprecated)]
    let asks = [
        (MavCmd::MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES, 1.0),
        (MavCmd::MAV_CMD_REQUEST_MESSAGE, 148.0),
    ];
    for (command, p1) in asks {
        let ack = gcs.command(2, command, [p1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]).await;
        assert_eq!(ack.result, MavResult::MAV_RESULT_ACCEPTED, "{command:?}");
        // After the ACK, as ArduPilot sends it.
        let v = gcs.wait(2, SECOND, version).await.expect("AUTOPILOT_VERSION");
        #[allow(deprecated)]
        let served = Cap::MAV_PROTOCOL_CAPABILITY_MAVLINK2
            | Cap::MAV_PROTOCOL_CAPABILITY_COMMAND_INT
            | Cap::MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_GLOBAL_INT
            | Cap::MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT;
        assert_eq!(v.capabilities, served, "only what is served");
        assert_eq!(v.uid, 2);
    }
    assert!(other.wait(2, SECOND, version).await.is_none(), "sent to a client that did not ask");
    vehicles.stop();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn home_gps_and_health_turn_ready_at_the_pre_arm_time() {
    // Ready after 8 simulated seconds, 4 s of wall time.
    let behaviour = Behaviour { boot_time: 1.0, prearm_time: 8.0, ..Behaviour::default() };
    let fence = "geofence = [[-100, -100], [100, -100], [100, 100], [-100, 100]]";
    let vehicles = serve(&fleet(2, fence), 2.0, behaviour).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    let sys_status = |m: &MavMessage| match m {
        MavMessage::SYS_STATUS(s) => Some(s.clone()),
        _ => None,
    };
    let gps = |m: &MavMessage| match m {
        MavMessage::GPS_RAW_INT(g) => Some(g.fix_type),
        _ => None,
    };
    let home = |m: &MavMessage| match m {
        MavMessage::HOME_POSITION(h) => Some(h.clone()),
        _ => None,
    };
    let needed = S::MAV_SYS_STATUS_SENSOR_GPS
        | S::MAV_SYS_STATUS_SENSOR_3D_GYRO
        | S::MAV_SYS_STATUS_SENSOR_3D_ACCEL
        | S::MAV_SYS_STATUS_SENSOR_3D_MAG
        | S::MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
        | S::MAV_SYS_STATUS_PREARM_CHECK
        | S::MAV_SYS_STATUS_GEOFENCE;

    // Before: no fix, no home, the GPS and the pre-arm checks unhealthy.
    let s = gcs.wait(2, 2 * SECOND, sys_status).await.expect("SYS_STATUS");
    assert!(s.onboard_control_sensors_present.contains(needed));
    assert!(s.onboard_control_sensors_enabled.contains(needed), "the world has a geofence");
    assert!(!s.onboard_control_sensors_health.contains(S::MAV_SYS_STATUS_SENSOR_GPS));
    assert!(!s.onboard_control_sensors_health.contains(S::MAV_SYS_STATUS_PREARM_CHECK));
    assert_eq!(gcs.wait(2, 2 * SECOND, gps).await, Some(GpsFixType::GPS_FIX_TYPE_NO_FIX));
    #[allow(deprecated)]
    let get_home = MavCmd::MAV_CMD_GET_HOME_POSITION;
    let ack = gcs.command(2, get_home, [0.0; 7]).await;
    assert_eq!(ack.result, MavResult::MAV_RESULT_FAILED, "no home before the fix");

    // Home is set once, unasked, when the fix comes.
    let h = gcs.wait(2, 6 * SECOND, home).await.expect("HOME_POSITION when home is set");
    let origin = Origin { lat: ORIGIN.0, lon: ORIGIN.1, alt: ORIGIN.2 };
    assert_eq!((h.latitude, h.longitude), origin.to_e7(10.0, 0.0), "drone d1 stands at (10, 0)");
    assert_eq!(h.altitude, 400_000, "at the origin's altitude, in mm");
    let s = gcs.wait(2, 2 * SECOND, sys_status).await.expect("SYS_STATUS");
    assert!(s.onboard_control_sensors_health.contains(needed), "{s:?}");
    assert_eq!(gcs.wait(2, 2 * SECOND, gps).await, Some(GpsFixType::GPS_FIX_TYPE_3D_FIX));

    // On request: HOME_POSITION then the ACK for GET_HOME_POSITION; the ACK first for
    // REQUEST_MESSAGE (both as ArduCopter SITL).
    gcs.send(&MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        command: get_home,
        target_system: 2,
        target_component: 1,
        ..Default::default()
    }))
    .await;
    let mut order = Vec::new();
    while order.len() < 2 {
        let f = gcs.frame(2 * SECOND).await.expect("the answers");
        match f.msg {
            Some(MavMessage::HOME_POSITION(_)) if f.system() == 2 => order.push("HOME_POSITION"),
            Some(MavMessage::COMMAND_ACK(a)) if a.command == get_home => order.push("ACK"),
            _ => {}
        }
    }
    assert_eq!(order, ["HOME_POSITION", "ACK"]);
    let ack = gcs
        .command(2, MavCmd::MAV_CMD_REQUEST_MESSAGE, [242.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        .await;
    assert_eq!(ack.result, MavResult::MAV_RESULT_ACCEPTED);
    assert!(gcs.wait(2, SECOND, home).await.is_some());

    // At an asked rate: 5 Hz.
    let ack = gcs
        .command(
            2,
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            [242.0, 200_000.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        )
        .await;
    assert_eq!(ack.result, MavResult::MAV_RESULT_ACCEPTED);
    let start = tokio::time::Instant::now();
    let mut n = 0;
    while start.elapsed() < Duration::from_millis(1500) {
        if gcs.wait(2, SECOND, home).await.is_some() {
            n += 1;
        }
    }
    // 5 Hz of the vehicles' own time, which runs at twice the wall's: 15 or 16 on an
    // idle machine; a loaded one may pace a tick late.
    assert!((12..=18).contains(&n), "{n} HOME_POSITION in 1.5 s at 5 Hz of a 2x clock");
    // A message the vehicle does not send has no rate.
    let ack = gcs
        .command(
            2,
            MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
            [30.0, 100_000.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        )
        .await;
    assert_eq!(ack.result, MavResult::MAV_RESULT_DENIED);
    vehicles.stop();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn ftp_requests_are_refused_at_once() {
    let vehicles = serve(&fleet(1, ""), 5.0, quick()).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    // OpenFileRO of MAVProxy's parameter file, sequence 41, session 3.
    let mut payload = [0u8; 251];
    payload[..2].copy_from_slice(&41u16.to_le_bytes());
    payload[2] = 3;
    payload[3] = 4;
    let path = b"@PARAM/param.pck";
    payload[4] = path.len() as u8;
    payload[12..12 + path.len()].copy_from_slice(path);
    gcs.send(&MavMessage::FILE_TRANSFER_PROTOCOL(FILE_TRANSFER_PROTOCOL_DATA {
        target_network: 0,
        target_system: 1,
        target_component: 1,
        payload,
    }))
    .await;
    let nak = gcs
        .wait(1, SECOND, |m| match m {
            MavMessage::FILE_TRANSFER_PROTOCOL(f) => Some(f.clone()),
            _ => None,
        })
        .await
        .expect("an FTP answer");
    assert_eq!((nak.target_system, nak.target_component), (255, 190));
    let p = nak.payload;
    // Sequence 42, session 3, NAK (129) of OpenFileRO (4), one byte: ERR_UnknownCommand.
    assert_eq!(
        (u16::from_le_bytes([p[0], p[1]]), p[2], p[3], p[4], p[5], p[12]),
        (42, 3, 129, 1, 4, 7)
    );
    vehicles.stop();
}
