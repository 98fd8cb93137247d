//! MAV_CMD_DO_REPOSITION in every frame ArduCopter takes for it (as MAVSDK's
//! goto_location and MAVProxy's `guided` send it), refused as ArduCopter refuses it.
// These tests talk to `aviary vehicles` in real time (its own clock is the wall's).
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

mod common;

use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavCmd, MavFrame, MavMessage, MavResult, COMMAND_INT_DATA,
};
use aviary_mavlink::Origin;
use common::{fleet, quick, serve, Gcs, ORIGIN};

const ORIGIN_GEO: Origin = Origin { lat: ORIGIN.0, lon: ORIGIN.1, alt: ORIGIN.2 };

async fn reposition(gcs: &mut Gcs, frame: u8, p2: f32, at: (i32, i32, f32)) -> MavResult {
    let frame = frame_of(frame);
    gcs.send(&MavMessage::COMMAND_INT(COMMAND_INT_DATA {
        param1: -1.0,
        param2: p2,
        x: at.0,
        y: at.1,
        z: at.2,
        command: MavCmd::MAV_CMD_DO_REPOSITION,
        target_system: 1,
        target_component: 1,
        frame,
        ..Default::default()
    }))
    .await;
    gcs.ack(1, MavCmd::MAV_CMD_DO_REPOSITION).await.result
}

/// The dialect's frame of a number (the `_INT` names are deprecated, not their numbers:
/// MAVSDK and ArduPilot use them).
#[allow(deprecated)]
fn frame_of(n: u8) -> MavFrame {
    match n {
        0 => MavFrame::MAV_FRAME_GLOBAL,
        1 => MavFrame::MAV_FRAME_LOCAL_NED,
        3 => MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
        5 => MavFrame::MAV_FRAME_GLOBAL_INT,
        6 => MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
        11 => MavFrame::MAV_FRAME_GLOBAL_TERRAIN_ALT_INT,
        _ => unreachable!("frame {n}"),
    }
}

/// Waits until the vehicle is within 1 m of `(x, y)` at `z` ± 0.5 m (local metres).
async fn arrives(gcs: &mut Gcs, x: f64, y: f64, z: f64) {
    let there = gcs
        .wait(1, Duration::from_secs(20), |m| match m {
            MavMessage::GLOBAL_POSITION_INT(p) => {
                let at = ORIGIN_GEO.from_e7(p.lat, p.lon);
                let h = f64::from(p.relative_alt) / 1000.0;
                ((at[0] - x).hypot(at[1] - y) < 1.0 && (h - z).abs() < 0.5).then_some(())
            }
            _ => None,
        })
        .await;
    assert!(there.is_some(), "did not arrive at ({x}, {y}, {z})");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn do_reposition_flies_in_every_global_frame_and_is_refused_as_arducopter_refuses_it() {
    let vehicles = serve(&fleet(1, ""), 5.0, quick()).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    use MavResult::*;
    let north = ORIGIN_GEO.to_e7(0.0, 30.0);
    // In GUIDED on the ground: taken, and nothing flies before a take-off (as ArduCopter).
    let until = tokio::time::Instant::now() + Duration::from_secs(10);
    while gcs
        .command(1, MavCmd::MAV_CMD_DO_SET_MODE, [1.0, 4.0, 0.0, 0.0, 0.0, 0.0, 0.0])
        .await
        .result
        != MAV_RESULT_ACCEPTED
    {
        assert!(tokio::time::Instant::now() < until, "GUIDED refused");
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
    assert_eq!(reposition(&mut gcs, 6, 0.0, (north.0, north.1, 10.0)).await, MAV_RESULT_ACCEPTED);
    let rose = gcs
        .wait(1, Duration::from_secs(1), |m| match m {
            MavMessage::GLOBAL_POSITION_INT(p) if p.relative_alt > 100 => Some(()),
            _ => None,
        })
        .await;
    assert!(rose.is_none(), "a target on the ground took off");
    gcs.take_off(1, 10.0).await;

    // As COMMAND_LONG: ArduCopter answers UNSUPPORTED.
    let ack = gcs
        .command(1, MavCmd::MAV_CMD_DO_REPOSITION, [-1.0, 0.0, 0.0, 0.0, 46.6, 14.2, 20.0])
        .await;
    assert_eq!(ack.result, MAV_RESULT_UNSUPPORTED);
    // Above sea level (MAV_FRAME_GLOBAL_INT, MAVSDK's goto_location): 15 m above home.
    let amsl = ORIGIN.2 as f32 + 15.0;
    assert_eq!(reposition(&mut gcs, 5, 0.0, (north.0, north.1, amsl)).await, MAV_RESULT_ACCEPTED);
    arrives(&mut gcs, 0.0, 30.0, 15.0).await;
    // Above home (MAVProxy's `guided LAT LON ALT`).
    let east = ORIGIN_GEO.to_e7(30.0, 30.0);
    assert_eq!(reposition(&mut gcs, 3, 0.0, (east.0, east.1, 12.0)).await, MAV_RESULT_ACCEPTED);
    arrives(&mut gcs, 30.0, 30.0, 12.0).await;
    // Above the terrain, which is flat at home's height; and MAV_FRAME_GLOBAL.
    assert_eq!(reposition(&mut gcs, 11, 0.0, (north.0, north.1, 8.0)).await, MAV_RESULT_ACCEPTED);
    arrives(&mut gcs, 0.0, 30.0, 8.0).await;
    let back = ORIGIN_GEO.to_e7(0.0, 0.0);
    assert_eq!(reposition(&mut gcs, 0, 0.0, (back.0, back.1, amsl)).await, MAV_RESULT_ACCEPTED);
    arrives(&mut gcs, 0.0, 0.0, 15.0).await;

    // Refused: a local frame (with ArduPilot's words), a latitude out of range, a height
    // that is not a number.
    assert_eq!(reposition(&mut gcs, 1, 0.0, (north.0, north.1, 10.0)).await, MAV_RESULT_DENIED);
    assert_eq!(reposition(&mut gcs, 6, 0.0, (950_000_000, north.1, 10.0)).await, MAV_RESULT_DENIED);
    assert_eq!(reposition(&mut gcs, 6, 0.0, (north.0, north.1, f32::NAN)).await, MAV_RESULT_DENIED);
    // Outside GUIDED: refused, unless asked to change mode (MAVSDK and MAVProxy ask).
    let ack =
        gcs.command(1, MavCmd::MAV_CMD_DO_SET_MODE, [1.0, 5.0, 0.0, 0.0, 0.0, 0.0, 0.0]).await;
    assert_eq!(ack.result, MAV_RESULT_ACCEPTED, "LOITER");
    assert_eq!(reposition(&mut gcs, 6, 0.0, (north.0, north.1, 10.0)).await, MAV_RESULT_DENIED);
    assert_eq!(reposition(&mut gcs, 6, 1.0, (north.0, north.1, 10.0)).await, MAV_RESULT_ACCEPTED);
    let mode = gcs
        .wait(1, Duration::from_secs(3), |m| match m {
            MavMessage::HEARTBEAT(h) => Some(h.custom_mode),
            _ => None,
        })
        .await;
    assert_eq!(mode, Some(4), "switched to GUIDED");
    arrives(&mut gcs, 0.0, 30.0, 10.0).await;
    vehicles.stop();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_unknown_frame_is_denied_with_arducopters_words() {
    let vehicles = serve(&fleet(1, ""), 5.0, quick()).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    gcs.take_off(1, 5.0).await;
    let at = ORIGIN_GEO.to_e7(0.0, 10.0);
    gcs.send(&MavMessage::COMMAND_INT(COMMAND_INT_DATA {
        x: at.0,
        y: at.1,
        z: 5.0,
        command: MavCmd::MAV_CMD_DO_REPOSITION,
        target_system: 1,
        target_component: 1,
        frame: frame_of(1),
        ..Default::default()
    }))
    .await;
    let said = gcs
        .wait(1, Duration::from_secs(3), |m| match m {
            MavMessage::STATUSTEXT(t) => Some(t.text.to_str().unwrap_or("").to_owned()),
            _ => None,
        })
        .await;
    assert_eq!(said.as_deref(), Some("Unknown mavlink coordinate frame 1"));
    assert_eq!(
        gcs.ack(1, MavCmd::MAV_CMD_DO_REPOSITION).await.result,
        MavResult::MAV_RESULT_DENIED
    );
    vehicles.stop();
}

/// A take-off and a reposition in one read, before the simulation steps (a fast client,
/// or one packet holding both): the reposition is refused and the take-off goes on. It
/// used to cancel the take-off, whose flight to the place then failed on the ground.
#[tokio::test]
async fn a_reposition_in_the_take_offs_own_tick_leaves_the_take_off_flying() {
    use aviary_mavlink::mavlink::dialects::ardupilotmega::MavModeFlag;
    use aviary_mavlink::mavlink::{self, MavHeader};
    let behaviour =
        aviary_vehicles::Behaviour { boot_time: 0.0, prearm_time: 0.0, ..Default::default() };
    let long = |command, p| common::command_long(1, command, p);
    let (lat, lon) = ORIGIN_GEO.to_e7(0.0, 30.0);
    let asked = [
        long(MavCmd::MAV_CMD_DO_SET_MODE, [1.0, 4.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        long(MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        long(MavCmd::MAV_CMD_NAV_TAKEOFF, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 10.0]),
        MavMessage::COMMAND_INT(COMMAND_INT_DATA {
            param1: -1.0,
            x: lat,
            y: lon,
            z: 15.0,
            command: MavCmd::MAV_CMD_DO_REPOSITION,
            target_system: 1,
            target_component: 1,
            frame: frame_of(6),
            ..Default::default()
        }),
    ];
    let mut bytes = Vec::new();
    for (k, m) in asked.iter().enumerate() {
        let header = MavHeader { system_id: 255, component_id: 190, sequence: k as u8 };
        mavlink::write_v2_msg(&mut bytes, header, m).expect("into a Vec");
    }
    let answers = aviary_vehicles::answer(&fleet(1, ""), behaviour, &bytes, 10.0).await;
    let heard: Vec<MavMessage> = answers
        .iter()
        .map(|f| {
            mavlink::MavlinkReader::new(f.as_slice())
                .read_any_message::<MavMessage>()
                .expect("a frame")
                .1
        })
        .collect();
    let result = |command| {
        heard.iter().find_map(|m| match m {
            MavMessage::COMMAND_ACK(a) if a.command == command => Some(a.result),
            _ => None,
        })
    };
    assert_eq!(result(MavCmd::MAV_CMD_NAV_TAKEOFF), Some(MavResult::MAV_RESULT_ACCEPTED));
    assert_eq!(result(MavCmd::MAV_CMD_DO_REPOSITION), Some(MavResult::MAV_RESULT_FAILED));
    let armed = heard.iter().any(|m| {
        matches!(m, MavMessage::HEARTBEAT(h) if h.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED))
    });
    let height = heard.iter().rev().find_map(|m| match m {
        MavMessage::GLOBAL_POSITION_INT(p) => Some(f64::from(p.relative_alt) / 1000.0),
        _ => None,
    });
    assert!(armed, "never armed");
    assert!(height.is_some_and(|h| (h - 10.0).abs() < 0.5), "took off to {height:?} m, not 10 m");
}
