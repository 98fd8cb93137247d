//! `aviary vehicles --autopilot px4`, with the `mavlink` crate as the ground station over
//! TCP: PX4's modes in `custom_mode`, arming and its refusals in PX4's words (chunked as
//! PX4 sends them), Takeoff handing over to Hold, DO_REPOSITION's altitude read above sea
//! level whatever the frame (as PX4's mavlink receiver and navigator read it), Orbit, the
//! mission protocol and a mission flown, the parameters bytewise, and the backend reading
//! the vehicle's figures under PX4's names.
// These tests talk to `aviary vehicles` in real time (its own clock is the wall's).
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

mod common;

use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavCmd, MavFrame, MavMessage, MavMissionResult, MavMissionType, MavModeFlag,
    MavParamType, MavResult, MavState, COMMAND_INT_DATA, HEARTBEAT_DATA, MISSION_ACK_DATA,
    MISSION_COUNT_DATA, MISSION_ITEM_INT_DATA, MISSION_REQUEST_INT_DATA, MISSION_REQUEST_LIST_DATA,
    PARAM_REQUEST_LIST_DATA, PARAM_REQUEST_READ_DATA, PARAM_SET_DATA, PARAM_VALUE_DATA,
};
use aviary_mavlink::mode::{px4, Flavour};
use aviary_mavlink::Origin;
use aviary_vehicles::Behaviour;
use common::{command_long, fleet, serve, world, Gcs, ORIGIN};
use tokio::time::Instant;

use MavResult::*;

const ORIGIN_GEO: Origin = Origin { lat: ORIGIN.0, lon: ORIGIN.1, alt: ORIGIN.2 };
const SECOND: Duration = Duration::from_secs(1);
const NAN: f32 = f32::NAN;

const HOLD: u32 = px4::encode(px4::AUTO, px4::AUTO_LOITER);
const TAKEOFF: u32 = px4::encode(px4::AUTO, px4::AUTO_TAKEOFF);
const LAND: u32 = px4::encode(px4::AUTO, px4::AUTO_LAND);
const RTL: u32 = px4::encode(px4::AUTO, px4::AUTO_RTL);
const MISSION: u32 = px4::encode(px4::AUTO, px4::AUTO_MISSION);
const ORBIT: u32 = px4::encode(px4::POSCTL, px4::POSCTL_ORBIT);

fn px4_behaviour(prearm_time: f64) -> Behaviour {
    Behaviour { prearm_time, autopilot: Flavour::Px4, ..Behaviour::default() }
}

/// What came from system 1 until `stop` took a message (or `limit` passed), in order,
/// with the STATUSTEXTs put together from their chunks.
struct Heard {
    messages: Vec<MavMessage>,
    texts: Vec<String>,
}

async fn hear(
    gcs: &mut Gcs,
    limit: Duration,
    mut stop: impl FnMut(&MavMessage) -> bool,
) -> (Heard, bool) {
    let until = Instant::now() + limit;
    let mut heard = Heard { messages: Vec::new(), texts: Vec::new() };
    let mut chunks: Vec<(u16, Vec<u8>)> = Vec::new();
    loop {
        let left = until.saturating_duration_since(Instant::now());
        let Some(f) = gcs.frame(left).await else { return (heard, false) };
        if f.system() != 1 {
            continue;
        }
        let Some(m) = f.msg else { continue };
        if let MavMessage::STATUSTEXT(t) = &m {
            let bytes: [u8; 50] = t.text.into();
            let end = bytes.iter().position(|b| *b == 0).unwrap_or(50);
            match chunks.iter_mut().find(|(id, _)| *id == t.id) {
                Some((_, text)) => text.extend_from_slice(&bytes[..end]),
                None => chunks.push((t.id, bytes[..end].to_vec())),
            }
            if end < 50 {
                let at = chunks.iter().position(|(id, _)| *id == t.id).unwrap();
                let (_, text) = chunks.remove(at);
                heard.texts.push(String::from_utf8(text).unwrap());
            }
        }
        let done = stop(&m);
        heard.messages.push(m);
        if done {
            return (heard, true);
        }
    }
}

fn is_ack(command: MavCmd) -> impl FnMut(&MavMessage) -> bool {
    move |m| matches!(m, MavMessage::COMMAND_ACK(a) if a.command == command)
}

fn ack_of(heard: &Heard, command: MavCmd) -> MavResult {
    heard
        .messages
        .iter()
        .find_map(|m| match m {
            MavMessage::COMMAND_ACK(a) if a.command == command => Some(a.result),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no ACK for {command:?}"))
}

/// What came until the ACK of `command`, and for 0.2 s after it (what PX4 says of a
/// command comes before its ACK when it refuses, after it when it does what it was told).
async fn answer(gcs: &mut Gcs, command: MavCmd) -> Heard {
    let (mut heard, acked) = hear(gcs, 3 * SECOND, is_ack(command)).await;
    assert!(acked, "no ACK for {command:?}: {:?}", heard.texts);
    let (more, _) = hear(gcs, SECOND / 5, |_| false).await;
    heard.messages.extend(more.messages);
    heard.texts.extend(more.texts);
    heard
}

/// Sends a COMMAND_LONG; what came with its ACK.
async fn command(gcs: &mut Gcs, command: MavCmd, p: [f32; 7]) -> Heard {
    gcs.send(&command_long(1, command, p)).await;
    answer(gcs, command).await
}

async fn command_int(gcs: &mut Gcs, c: COMMAND_INT_DATA) -> Heard {
    let command = c.command;
    gcs.send(&MavMessage::COMMAND_INT(c)).await;
    answer(gcs, command).await
}

async fn set_mode(gcs: &mut Gcs, main: u8, sub: u8) -> Heard {
    command(gcs, MavCmd::MAV_CMD_DO_SET_MODE, [1.0, main.into(), sub.into(), 0.0, 0.0, 0.0, 0.0])
        .await
}

async fn heartbeat(gcs: &mut Gcs) -> HEARTBEAT_DATA {
    gcs.wait(1, 3 * SECOND, |m| match m {
        MavMessage::HEARTBEAT(h) => Some(h.clone()),
        _ => None,
    })
    .await
    .expect("a HEARTBEAT")
}

/// Waits for a HEARTBEAT that `pick` takes.
async fn heartbeat_until(
    gcs: &mut Gcs,
    limit: Duration,
    mut pick: impl FnMut(&HEARTBEAT_DATA) -> bool,
) -> HEARTBEAT_DATA {
    gcs.wait(1, limit, |m| match m {
        MavMessage::HEARTBEAT(h) if pick(h) => Some(h.clone()),
        _ => None,
    })
    .await
    .expect("no such HEARTBEAT")
}

/// HEARTBEAT at 20 Hz on this link (PX4 streams it at 1 Hz): the tests' vehicles fly
/// 5 or 10 times faster than real time.
async fn fast_heartbeat(gcs: &mut Gcs) {
    let h = command(
        gcs,
        MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
        [0.0, 50_000.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    )
    .await;
    assert_eq!(ack_of(&h, MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL), MAV_RESULT_ACCEPTED);
}

/// Arms (asking again until the pre-arm checks pass).
async fn arm(gcs: &mut Gcs) {
    let until = Instant::now() + 10 * SECOND;
    loop {
        let h =
            command(gcs, MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
                .await;
        if ack_of(&h, MavCmd::MAV_CMD_COMPONENT_ARM_DISARM) == MAV_RESULT_ACCEPTED {
            assert!(h.texts.iter().any(|t| t == "Armed by external command\t"), "{:?}", h.texts);
            return;
        }
        assert!(Instant::now() < until, "not armed: {:?}", h.texts);
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

/// Arms and takes off to `alt` m above home with NAV_TAKEOFF (param7 above sea level).
async fn take_off(gcs: &mut Gcs, alt: f32) {
    arm(gcs).await;
    let amsl = ORIGIN.2 as f32 + alt;
    let h = command(gcs, MavCmd::MAV_CMD_NAV_TAKEOFF, [NAN, NAN, NAN, NAN, NAN, NAN, amsl]).await;
    assert_eq!(ack_of(&h, MavCmd::MAV_CMD_NAV_TAKEOFF), MAV_RESULT_ACCEPTED, "{:?}", h.texts);
    at(gcs, None, f64::from(alt), 30 * SECOND).await;
}

/// Waits until the vehicle is within 1 m of `(x, y)` (when given) and 0.5 m of `z`.
async fn at(gcs: &mut Gcs, xy: Option<(f64, f64)>, z: f64, limit: Duration) {
    let there = gcs
        .wait(1, limit, |m| match m {
            MavMessage::GLOBAL_POSITION_INT(p) => {
                let here = ORIGIN_GEO.from_e7(p.lat, p.lon);
                let h = f64::from(p.relative_alt) / 1000.0;
                let near = xy.is_none_or(|(x, y)| (here[0] - x).hypot(here[1] - y) < 1.0);
                (near && (h - z).abs() < 0.5).then_some(())
            }
            _ => None,
        })
        .await;
    assert!(there.is_some(), "did not get to {xy:?} at {z} m");
}

fn reposition(frame: MavFrame, p2: f32, (x, y): (f64, f64), z: f32) -> COMMAND_INT_DATA {
    let (lat, lon) = ORIGIN_GEO.to_e7(x, y);
    COMMAND_INT_DATA {
        param1: -1.0,
        param2: p2,
        param3: 0.0,
        param4: NAN,
        x: lat,
        y: lon,
        z,
        command: MavCmd::MAV_CMD_DO_REPOSITION,
        target_system: 1,
        target_component: 1,
        frame,
        ..Default::default()
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn heartbeat_modes_and_arming_answer_as_px4() {
    // The pre-arm checks pass after 20 s of simulated time, 4 s here.
    let vehicles = serve(&fleet(1, ""), 5.0, px4_behaviour(20.0)).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    let h = heartbeat(&mut gcs).await;
    assert_eq!(h.autopilot, MavAutopilot::MAV_AUTOPILOT_PX4);
    assert_eq!(h.custom_mode, HOLD, "PX4 boots in Hold: {:#x}", h.custom_mode);
    for flag in [
        MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED,
        MavModeFlag::MAV_MODE_FLAG_AUTO_ENABLED,
        MavModeFlag::MAV_MODE_FLAG_GUIDED_ENABLED,
        MavModeFlag::MAV_MODE_FLAG_STABILIZE_ENABLED,
    ] {
        assert!(h.base_mode.contains(flag), "{:?}", h.base_mode);
    }
    assert!(!h.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED));
    assert_eq!(h.system_status, MavState::MAV_STATE_UNINIT, "not ready to arm yet");

    // Before the GPS fix: PX4's health failures, then its refusal, 52 characters sent
    // as two chunks of one STATUSTEXT id.
    let refused = command(
        &mut gcs,
        MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    )
    .await;
    assert_eq!(
        ack_of(&refused, MavCmd::MAV_CMD_COMPONENT_ARM_DISARM),
        MAV_RESULT_TEMPORARILY_REJECTED
    );
    assert_eq!(
        refused.texts,
        [
            "Preflight Fail: GPS fix too low",
            "Arming denied: Resolve system health failures first\t"
        ]
    );
    let chunks: Vec<(u16, u8)> = refused
        .messages
        .iter()
        .filter_map(|m| match m {
            MavMessage::STATUSTEXT(t) => Some((t.id, t.chunk_seq)),
            _ => None,
        })
        .collect();
    assert_eq!(chunks.len(), 3, "{chunks:?}");
    assert_eq!(
        (chunks[1].0, chunks[1].1, chunks[2].0, chunks[2].1),
        (chunks[1].0, 0, chunks[1].0, 1)
    );

    // Disarmed, any mode is taken: Return, shown at once; an AUTO sub mode PX4 does not
    // have is refused, a main mode it does not map changes nothing.
    let rtl = set_mode(&mut gcs, px4::AUTO, px4::AUTO_RTL).await;
    assert_eq!(ack_of(&rtl, MavCmd::MAV_CMD_DO_SET_MODE), MAV_RESULT_ACCEPTED);
    assert_eq!(heartbeat(&mut gcs).await.custom_mode, RTL);
    let odd = set_mode(&mut gcs, px4::AUTO, 7).await;
    assert_eq!(ack_of(&odd, MavCmd::MAV_CMD_DO_SET_MODE), MAV_RESULT_TEMPORARILY_REJECTED);
    assert_eq!(odd.texts, ["Unsupported auto mode\t"]);
    let simple = set_mode(&mut gcs, px4::SIMPLE, 0).await;
    assert_eq!(ack_of(&simple, MavCmd::MAV_CMD_DO_SET_MODE), MAV_RESULT_ACCEPTED);
    assert_eq!(heartbeat(&mut gcs).await.custom_mode, RTL);
    fast_heartbeat(&mut gcs).await;

    // Ready: Return does not arm (UNINIT, "Arming denied" alone); Hold does (STANDBY).
    tokio::time::sleep(4 * SECOND).await;
    let h = heartbeat(&mut gcs).await;
    assert_eq!((h.custom_mode, h.system_status), (RTL, MavState::MAV_STATE_UNINIT));
    let refused = command(
        &mut gcs,
        MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
        [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    )
    .await;
    assert_eq!(refused.texts, ["Arming denied: Resolve system health failures first\t"]);
    set_mode(&mut gcs, px4::AUTO, px4::AUTO_LOITER).await;
    heartbeat_until(&mut gcs, 3 * SECOND, |h| h.system_status == MavState::MAV_STATE_STANDBY).await;
    arm(&mut gcs).await;
    let h = heartbeat_until(&mut gcs, 3 * SECOND, |h| {
        h.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED)
    })
    .await;
    assert_eq!((h.custom_mode, h.system_status), (HOLD, MavState::MAV_STATE_ACTIVE));

    // Armed, a manual mode cannot run without sticks: refused, said to a mission planner.
    let pos = set_mode(&mut gcs, px4::POSCTL, 0).await;
    assert_eq!(ack_of(&pos, MavCmd::MAV_CMD_DO_SET_MODE), MAV_RESULT_TEMPORARILY_REJECTED);
    assert_eq!(pos.texts, ["Switching to Position is currently not available\t"]);

    // Not a 0 or 1 to ARM_DISARM: said, and no ACK.
    gcs.send(&command_long(
        1,
        MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
        [2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    ))
    .await;
    let (odd, acked) =
        hear(&mut gcs, SECOND / 2, is_ack(MavCmd::MAV_CMD_COMPONENT_ARM_DISARM)).await;
    assert!(!acked, "PX4 does not answer ARM_DISARM 2");
    assert!(
        odd.texts.iter().any(|t| t == "Unsupported ARM_DISARM param: 2.000\t"),
        "{:?}",
        odd.texts
    );

    // Armed without a take-off: PX4 disarms by itself after COM_DISARM_PRFLT (10 s).
    let (rest, disarmed) = hear(&mut gcs, 3 * SECOND, |m| {
        matches!(m, MavMessage::HEARTBEAT(h) if !h.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED))
    })
    .await;
    assert!(disarmed, "{:?}", rest.texts);
    assert!(
        rest.texts.iter().any(|t| t == "Disarmed by auto preflight disarming\t"),
        "{:?}",
        rest.texts
    );
    vehicles.stop();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn takeoff_climbs_in_takeoff_mode_then_holds_and_a_landing_disarms() {
    let vehicles = serve(&fleet(1, ""), 5.0, px4_behaviour(3.0)).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    fast_heartbeat(&mut gcs).await;
    arm(&mut gcs).await;
    // No altitude: MIS_TAKEOFF_ALT (2.5 m) above where it is.
    gcs.send(&command_long(1, MavCmd::MAV_CMD_NAV_TAKEOFF, [NAN; 7])).await;
    // Until Hold after Takeoff: the vehicle was in Hold before it too, and a HEARTBEAT
    // sent before the command may still be on its way (a loaded machine reads it late).
    let mut took_off = false;
    let (climb, _) = hear(&mut gcs, 10 * SECOND, |m| match m {
        MavMessage::HEARTBEAT(h) => {
            took_off |= h.custom_mode == TAKEOFF;
            took_off && h.custom_mode == HOLD
        }
        _ => false,
    })
    .await;
    assert_eq!(ack_of(&climb, MavCmd::MAV_CMD_NAV_TAKEOFF), MAV_RESULT_ACCEPTED);
    let texts = climb.texts.clone();
    assert!(texts.iter().any(|t| t == "Using default takeoff altitude: 2.5 m\t"), "{texts:?}");
    assert!(texts.iter().any(|t| t == "Takeoff detected\t"), "{texts:?}");
    let modes: Vec<u32> = climb
        .messages
        .iter()
        .filter_map(|m| match m {
            MavMessage::HEARTBEAT(h) => Some(h.custom_mode),
            _ => None,
        })
        .collect();
    assert!(modes.contains(&TAKEOFF) && modes.last() == Some(&HOLD), "{modes:x?}");
    at(&mut gcs, None, 2.5, 3 * SECOND).await;

    // In the air, to 12 m above sea level plus the origin's: Takeoff again, then Hold.
    let amsl = ORIGIN.2 as f32 + 12.0;
    command(&mut gcs, MavCmd::MAV_CMD_NAV_TAKEOFF, [NAN, NAN, NAN, NAN, NAN, NAN, amsl]).await;
    assert_eq!(heartbeat(&mut gcs).await.custom_mode, TAKEOFF);
    at(&mut gcs, None, 12.0, 20 * SECOND).await;
    heartbeat_until(&mut gcs, 3 * SECOND, |h| h.custom_mode == HOLD).await;

    // Land where it is: Land mode, "Landing detected", and PX4's own disarm 2 s after.
    let land =
        command(&mut gcs, MavCmd::MAV_CMD_NAV_LAND, [0.0, 0.0, 0.0, NAN, NAN, NAN, NAN]).await;
    assert_eq!(ack_of(&land, MavCmd::MAV_CMD_NAV_LAND), MAV_RESULT_ACCEPTED);
    assert_eq!(land.texts, ["Landing at current position\t"]);
    assert_eq!(heartbeat(&mut gcs).await.custom_mode, LAND);
    let (down, _) = hear(&mut gcs, 30 * SECOND, |m| {
        matches!(m, MavMessage::HEARTBEAT(h) if !h.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED))
    })
    .await;
    let at_land = down.texts.iter().position(|t| t == "Landing detected\t");
    let at_disarm = down.texts.iter().position(|t| t == "Disarmed by landing\t");
    assert!(at_land.is_some() && at_land < at_disarm, "{:?}", down.texts);
    // Back in the mode chosen last that allows arming: Hold (Takeoff handed over to it).
    assert_eq!(heartbeat(&mut gcs).await.custom_mode, HOLD);
    vehicles.stop();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn do_reposition_reads_its_altitude_above_sea_level_in_every_frame() {
    let vehicles = serve(&fleet(1, ""), 10.0, px4_behaviour(3.0)).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    take_off(&mut gcs, 12.0).await;
    let amsl = |z: f32| ORIGIN.2 as f32 + z;

    #[allow(deprecated)]
    let relative = MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT;
    #[allow(deprecated)]
    let global = MavFrame::MAV_FRAME_GLOBAL_INT;
    // As MAVSDK's goto_location: COMMAND_INT in MAV_FRAME_GLOBAL_INT, change-mode flag.
    let h = command_int(&mut gcs, reposition(global, 1.0, (0.0, 30.0), amsl(12.0))).await;
    assert_eq!(ack_of(&h, MavCmd::MAV_CMD_DO_REPOSITION), MAV_RESULT_ACCEPTED);
    at(&mut gcs, Some((0.0, 30.0)), 12.0, 20 * SECOND).await;
    // As COMMAND_LONG (PX4 takes it too): param5/6 degrees, param7 above sea level.
    let (lat, lon) = ORIGIN_GEO.to_geodetic(20.0, 30.0);
    let h = command(
        &mut gcs,
        MavCmd::MAV_CMD_DO_REPOSITION,
        [-1.0, 1.0, 0.0, NAN, lat as f32, lon as f32, amsl(15.0)],
    )
    .await;
    assert_eq!(ack_of(&h, MavCmd::MAV_CMD_DO_REPOSITION), MAV_RESULT_ACCEPTED);
    at(&mut gcs, Some((20.0, 30.0)), 15.0, 20 * SECOND).await;
    // Without the change-mode flag: UNSUPPORTED, yet the Hold that is on flies to it.
    let h = command_int(&mut gcs, reposition(global, 0.0, (20.0, 10.0), amsl(15.0))).await;
    assert_eq!(ack_of(&h, MavCmd::MAV_CMD_DO_REPOSITION), MAV_RESULT_UNSUPPORTED);
    at(&mut gcs, Some((20.0, 10.0)), 15.0, 20 * SECOND).await;

    // 12 m "above home" in MAV_FRAME_GLOBAL_RELATIVE_ALT_INT: PX4 does not read the frame
    // and takes 12 m above sea level, far below the ground here (400 m): it descends,
    // touches down, and disarms (what a PX4 SITL user saw).
    let h = command_int(&mut gcs, reposition(relative, 1.0, (20.0, 60.0), 12.0)).await;
    assert_eq!(ack_of(&h, MavCmd::MAV_CMD_DO_REPOSITION), MAV_RESULT_ACCEPTED);
    let (down, disarmed) = hear(&mut gcs, 30 * SECOND, |m| {
        matches!(m, MavMessage::HEARTBEAT(h) if !h.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED))
    })
    .await;
    assert!(disarmed, "{:?}", down.texts);
    assert!(down.texts.iter().any(|t| t == "Landing detected\t"), "{:?}", down.texts);
    assert!(down.texts.iter().any(|t| t == "Disarmed by landing\t"), "{:?}", down.texts);
    let last = down
        .messages
        .iter()
        .rev()
        .find_map(|m| match m {
            MavMessage::GLOBAL_POSITION_INT(p) => Some(p.clone()),
            _ => None,
        })
        .expect("a position");
    let ground = ORIGIN_GEO.from_e7(last.lat, last.lon);
    assert!(last.relative_alt.abs() < 100, "on the ground: {} mm", last.relative_alt);
    // On the way there, short of the point: it came down on the line to it.
    assert!(ground[1] > 10.0 && ground[1] < 60.0 && (ground[0] - 20.0).abs() < 1.0, "{ground:?}");
    vehicles.stop();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn do_orbit_circles_the_centre_clockwise_in_posctl_orbit() {
    let vehicles = serve(&fleet(1, ""), 10.0, px4_behaviour(3.0)).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    take_off(&mut gcs, 10.0).await;
    let center = (20.0, 0.0);
    let (lat, lon) = ORIGIN_GEO.to_e7(center.0, center.1);
    // As MAVSDK's do_orbit: COMMAND_INT, radius, speed, yaw behaviour, centre, altitude.
    let orbit = COMMAND_INT_DATA {
        param1: 10.0,
        param2: 3.0,
        param3: 0.0,
        param4: NAN,
        x: lat,
        y: lon,
        z: ORIGIN.2 as f32 + 15.0,
        command: MavCmd::MAV_CMD_DO_ORBIT,
        target_system: 1,
        target_component: 1,
        ..Default::default()
    };
    let h = command_int(&mut gcs, orbit.clone()).await;
    assert_eq!(ack_of(&h, MavCmd::MAV_CMD_DO_ORBIT), MAV_RESULT_ACCEPTED);
    assert_eq!(heartbeat(&mut gcs).await.custom_mode, ORBIT);
    // On the circle at 15 m, the bearing from the centre turning clockwise (from north
    // to east) by more than half a turn.
    let mut bearings: Vec<f64> = Vec::new();
    let went_round = gcs
        .wait(1, 60 * SECOND, |m| match m {
            MavMessage::GLOBAL_POSITION_INT(p) => {
                let here = ORIGIN_GEO.from_e7(p.lat, p.lon);
                let (dx, dy) = (here[0] - center.0, here[1] - center.1);
                let h = f64::from(p.relative_alt) / 1000.0;
                if ((dx.hypot(dy)) - 10.0).abs() < 1.0 && (h - 15.0).abs() < 0.5 {
                    bearings.push(dx.atan2(dy));
                }
                let turned: f64 = bearings
                    .windows(2)
                    .map(|w| {
                        (w[1] - w[0] + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                            - std::f64::consts::PI
                    })
                    .sum();
                (turned > std::f64::consts::PI).then_some(())
            }
            _ => None,
        })
        .await;
    assert!(went_round.is_some(), "did not circle clockwise: {} samples", bearings.len());
    // A radius over MC_ORBIT_RAD_MAX: PX4's words, and the orbit stops.
    let h = command_int(&mut gcs, COMMAND_INT_DATA { param1: 2000.0, ..orbit }).await;
    assert_eq!(ack_of(&h, MavCmd::MAV_CMD_DO_ORBIT), MAV_RESULT_ACCEPTED);
    let (said, _) = hear(&mut gcs, SECOND, |_| false).await;
    assert!(
        [h.texts, said.texts].concat().iter().any(|t| t == "Orbit radius limit exceeded\t"),
        "no word of the radius"
    );
    vehicles.stop();
}

fn item(seq: u16, command: MavCmd, (x, y): (f64, f64), z: f32) -> MISSION_ITEM_INT_DATA {
    let (lat, lon) = ORIGIN_GEO.to_e7(x, y);
    #[allow(deprecated)]
    let frame = MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT_INT;
    MISSION_ITEM_INT_DATA {
        param1: 0.0,
        param2: 0.0,
        param3: 0.0,
        param4: NAN,
        x: lat,
        y: lon,
        z,
        seq,
        command,
        target_system: 1,
        target_component: 1,
        frame,
        current: u8::from(seq == 0),
        autocontinue: 1,
        mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
    }
}

fn mission_ack(result: MavMissionResult) -> MavMessage {
    MavMessage::MISSION_ACK(MISSION_ACK_DATA {
        target_system: 1,
        target_component: 1,
        mavtype: result,
        mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        opaque_id: 0,
    })
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_mission_is_uploaded_downloaded_and_flown_item_by_item() {
    let vehicles = serve(&fleet(1, ""), 10.0, px4_behaviour(3.0)).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    let items = [
        item(0, MavCmd::MAV_CMD_NAV_TAKEOFF, (0.0, 0.0), 10.0),
        item(1, MavCmd::MAV_CMD_NAV_WAYPOINT, (0.0, 40.0), 10.0),
        item(2, MavCmd::MAV_CMD_NAV_LAND, (20.0, 40.0), 0.0),
    ];
    // The upload: PX4 asks with MISSION_REQUEST (floats) first; refused UNSUPPORTED (as
    // MAVSDK does), it asks with MISSION_REQUEST_INT.
    gcs.send(&MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
        count: 3,
        target_system: 1,
        target_component: 1,
        mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        opaque_id: 0,
    }))
    .await;
    #[allow(deprecated)]
    let first = gcs.wait(1, SECOND, |m| match m {
        MavMessage::MISSION_REQUEST(r) => Some(r.seq),
        MavMessage::MISSION_REQUEST_INT(_) => panic!("PX4 starts with MISSION_REQUEST"),
        _ => None,
    });
    assert_eq!(first.await, Some(0));
    gcs.send(&mission_ack(MavMissionResult::MAV_MISSION_UNSUPPORTED)).await;
    let mut id = 0;
    for expect in 0..=3u16 {
        let got = gcs
            .wait(1, SECOND, |m| match m {
                MavMessage::MISSION_REQUEST_INT(r) => Some(Err(r.seq)),
                MavMessage::MISSION_ACK(a) => Some(Ok((a.mavtype, a.opaque_id))),
                _ => None,
            })
            .await
            .expect("an answer");
        match got {
            Err(seq) => {
                assert_eq!(seq, expect);
                gcs.send(&MavMessage::MISSION_ITEM_INT(items[usize::from(seq)].clone())).await;
            }
            Ok((result, opaque)) => {
                assert_eq!((expect, result), (3, MavMissionResult::MAV_MISSION_ACCEPTED));
                id = opaque;
            }
        }
    }
    assert_ne!(id, 0, "the mission's id");

    // An item in a frame PX4 does not take: PX4's words and UNSUPPORTED_FRAME; the
    // mission kept is the one before.
    gcs.send(&MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
        count: 1,
        target_system: 1,
        target_component: 1,
        mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        opaque_id: 0,
    }))
    .await;
    gcs.wait(1, SECOND, |m| matches!(m, MavMessage::MISSION_REQUEST_INT(_)).then_some(()))
        .await
        .expect("asked");
    let bad = MISSION_ITEM_INT_DATA { frame: MavFrame::MAV_FRAME_LOCAL_NED, ..items[1].clone() };
    gcs.send(&MavMessage::MISSION_ITEM_INT(MISSION_ITEM_INT_DATA { seq: 0, ..bad })).await;
    let (refused, _) = hear(&mut gcs, SECOND, |m| matches!(m, MavMessage::MISSION_ACK(_))).await;
    assert_eq!(refused.texts, ["IGN MISSION_ITEM: Invalid item\t"]);
    assert!(refused.messages.iter().any(|m| matches!(m, MavMessage::MISSION_ACK(a) if a.mavtype == MavMissionResult::MAV_MISSION_UNSUPPORTED_FRAME)));

    // The download gives the mission back.
    gcs.send(&MavMessage::MISSION_REQUEST_LIST(MISSION_REQUEST_LIST_DATA {
        target_system: 1,
        target_component: 1,
        mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
    }))
    .await;
    let count = gcs.wait(1, SECOND, |m| match m {
        MavMessage::MISSION_COUNT(c) => Some((c.count, c.opaque_id)),
        _ => None,
    });
    assert_eq!(count.await, Some((3, id)));
    for (seq, sent) in items.iter().enumerate() {
        gcs.send(&MavMessage::MISSION_REQUEST_INT(MISSION_REQUEST_INT_DATA {
            seq: seq as u16,
            target_system: 1,
            target_component: 1,
            mission_type: MavMissionType::MAV_MISSION_TYPE_MISSION,
        }))
        .await;
        let back = gcs.wait(1, SECOND, |m| match m {
            MavMessage::MISSION_ITEM_INT(i) => Some(i.clone()),
            _ => None,
        });
        let back = back.await.expect("the item");
        assert_eq!(
            (back.seq, back.command, back.x, back.y, back.z),
            (sent.seq, sent.command, sent.x, sent.y, sent.z)
        );
    }
    gcs.send(&mission_ack(MavMissionResult::MAV_MISSION_ACCEPTED)).await;

    // MISSION_START arms and flies it: the climb PX4 makes first on the ground, each item
    // reached in order, the landing at the last one, the disarm.
    let until = Instant::now() + 10 * SECOND;
    let started = loop {
        let h =
            command(&mut gcs, MavCmd::MAV_CMD_MISSION_START, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
                .await;
        if ack_of(&h, MavCmd::MAV_CMD_MISSION_START) == MAV_RESULT_ACCEPTED {
            break h;
        }
        assert!(
            h.texts.iter().any(|t| t == "Switching to Mission is currently not available\t"),
            "{:?}",
            h.texts
        );
        assert!(Instant::now() < until, "the mission did not start");
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    let (flight, disarmed) = hear(&mut gcs, 60 * SECOND, |m| {
        matches!(m, MavMessage::HEARTBEAT(h) if !h.base_mode.contains(MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED))
    })
    .await;
    assert!(disarmed, "{:?}", flight.texts);
    let texts = [started.texts, flight.texts.clone()].concat();
    for said in [
        "Armed by mission start\t",
        "Executing Mission\t",
        "Climb to 10.0 meters above home\t",
        "Takeoff detected\t",
        "Landing detected\t",
        "Mission finished, landed\t",
        "Disarmed by landing\t",
    ] {
        assert!(texts.iter().any(|t| t == said), "no {said:?} in {texts:?}");
    }
    let reached: Vec<u16> = flight
        .messages
        .iter()
        .filter_map(|m| match m {
            MavMessage::MISSION_ITEM_REACHED(r) => Some(r.seq),
            _ => None,
        })
        .collect();
    assert_eq!(reached, [0, 1, 2]);
    let currents: Vec<u16> = flight
        .messages
        .iter()
        .filter_map(|m| match m {
            MavMessage::MISSION_CURRENT(c) => Some(c.seq),
            _ => None,
        })
        .collect();
    assert!(
        currents.windows(2).all(|w| w[0] <= w[1])
            && currents.contains(&1)
            && currents.last() == Some(&2),
        "{currents:?}"
    );
    assert!(flight
        .messages
        .iter()
        .any(|m| matches!(m, MavMessage::HEARTBEAT(h) if h.custom_mode == MISSION)));
    let passed = flight.messages.iter().any(|m| match m {
        MavMessage::GLOBAL_POSITION_INT(p) => {
            let here = ORIGIN_GEO.from_e7(p.lat, p.lon);
            here[0].hypot(here[1] - 40.0) < 1.0
                && (f64::from(p.relative_alt) / 1000.0 - 10.0).abs() < 0.5
        }
        _ => false,
    });
    assert!(passed, "waypoint 1 was not passed");
    let last = flight
        .messages
        .iter()
        .rev()
        .find_map(|m| match m {
            MavMessage::GLOBAL_POSITION_INT(p) => Some(p.clone()),
            _ => None,
        })
        .expect("a position");
    let ground = ORIGIN_GEO.from_e7(last.lat, last.lon);
    assert!(
        (ground[0] - 20.0).hypot(ground[1] - 40.0) < 1.0 && last.relative_alt.abs() < 100,
        "{ground:?}"
    );
    vehicles.stop();
}

fn value(m: &MavMessage) -> Option<PARAM_VALUE_DATA> {
    match m {
        MavMessage::PARAM_VALUE(v) => Some(v.clone()),
        _ => None,
    }
}

async fn read(gcs: &mut Gcs, id: &str) -> Option<PARAM_VALUE_DATA> {
    gcs.send(&MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
        param_index: -1,
        target_system: 1,
        target_component: 1,
        param_id: id.into(),
    }))
    .await;
    gcs.wait(1, SECOND, value).await
}

const FIGURES: &str = "climb_rate = 2.5\ndescent_rate = 1.5\nacceleration = 2.0\nland_speed = 0.6\nland_speed_below = 8.0\nreturn_altitude = 25.0\nreturn_loiter = 3.0\n";

fn figured_world(binding: &str) -> aviary_world::World {
    world(&format!(
        "[site]\nname = \"t\"\norigin = {{ lat = {}, lon = {}, alt = {} }}\n\n[drones.d0]\nhome = [0, 0]\nmax_speed = 8\n{FIGURES}{binding}",
        ORIGIN.0, ORIGIN.1, ORIGIN.2
    ))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn parameters_are_px4s_sent_bytewise_and_the_backend_reads_them() {
    let vehicles = serve(&figured_world(""), 10.0, px4_behaviour(0.0)).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    // The list: _HASH_CHECK first, then every parameter with its index, in name order.
    gcs.send(&MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
        target_system: 1,
        target_component: 1,
    }))
    .await;
    let hash = gcs.wait(1, SECOND, value).await.expect("_HASH_CHECK");
    assert_eq!(hash.param_id.to_str().unwrap(), "_HASH_CHECK");
    assert_eq!(
        (hash.param_type, hash.param_index),
        (MavParamType::MAV_PARAM_TYPE_UINT32, u16::MAX)
    );
    let mut names = Vec::new();
    while let Some(v) = gcs.wait(1, SECOND / 2, value).await {
        assert_eq!((v.param_index as usize, v.param_count), (names.len(), hash.param_count));
        names.push(v.param_id.to_str().unwrap().to_owned());
    }
    assert_eq!(names.len(), usize::from(hash.param_count));
    assert!(names.windows(2).all(|w| w[0] < w[1]), "{names:?}");
    for name in [
        "MPC_XY_CRUISE",
        "MPC_XY_VEL_MAX",
        "MPC_Z_VEL_MAX_UP",
        "MPC_Z_V_AUTO_UP",
        "MPC_Z_V_AUTO_DN",
        "MPC_LAND_SPEED",
        "MPC_ACC_HOR",
        "RTL_RETURN_ALT",
        "RTL_DESCEND_ALT",
        "MIS_TAKEOFF_ALT",
        "BAT1_CAPACITY",
        "NAV_ACC_RAD",
        "MAV_SYS_ID",
        "GF_ACTION",
        "GF_MAX_HOR_DIST",
        "GF_MAX_VER_DIST",
    ] {
        assert!(names.iter().any(|n| n == name), "no {name}");
    }
    // An INT32's four bytes in the float; a REAL32 as it is; read by name with its index.
    let sys = read(&mut gcs, "MAV_SYS_ID").await.expect("MAV_SYS_ID");
    assert_eq!(
        (sys.param_type, sys.param_value.to_bits()),
        (MavParamType::MAV_PARAM_TYPE_INT32, 1)
    );
    assert_eq!(usize::from(sys.param_index), names.iter().position(|n| n == "MAV_SYS_ID").unwrap());
    let gf = read(&mut gcs, "GF_ACTION").await.expect("GF_ACTION");
    assert_eq!(aviary_mavlink::facts::decode(Flavour::Px4, gf.param_value, gf.param_type), 2.0);
    let cruise = read(&mut gcs, "MPC_XY_CRUISE").await.expect("MPC_XY_CRUISE");
    assert_eq!((cruise.param_type, cruise.param_value), (MavParamType::MAV_PARAM_TYPE_REAL32, 8.0));
    assert_eq!(read(&mut gcs, "BAT1_CAPACITY").await.expect("BAT1_CAPACITY").param_value, -1.0);
    // Set as MAVSDK's set_takeoff_altitude does; another type is not answered.
    let set = |v: f32, kind| {
        MavMessage::PARAM_SET(PARAM_SET_DATA {
            param_value: v,
            target_system: 1,
            target_component: 1,
            param_id: "MIS_TAKEOFF_ALT".into(),
            param_type: kind,
        })
    };
    gcs.send(&set(10.0, MavParamType::MAV_PARAM_TYPE_REAL32)).await;
    assert_eq!(gcs.wait(1, SECOND, value).await.map(|v| v.param_value), Some(10.0));
    gcs.send(&set(f32::from_bits(3), MavParamType::MAV_PARAM_TYPE_INT32)).await;
    assert!(
        gcs.wait(1, SECOND / 2, value).await.is_none(),
        "a set of the wrong type is not answered"
    );

    // The MAVLink backend's own reader takes these vehicles for PX4 and reads its table
    // (aviary_mavlink::facts::PX4) under the same names and units: the world's figures.
    let bound = figured_world(&format!("mavlink = \"tcp:{}\"\n", vehicles.address));
    let facts = aviary_mavlink::facts::ask(&bound, 5 * SECOND).await.expect("asked");
    let f = &facts[0];
    assert_eq!(f.flavour, Some(Flavour::Px4), "{f:?}");
    let answer = |name: &str| {
        f.answers
            .iter()
            .find(|(p, _)| p.name == name)
            .and_then(|(_, v)| *v)
            .unwrap_or_else(|| panic!("{name} unanswered: {f:?}"))
    };
    assert_eq!(f.answered(), f.answers.len(), "{f:?}");
    for (name, want) in [
        ("MPC_Z_V_AUTO_UP", 2.5),
        ("MPC_Z_V_AUTO_DN", 1.5),
        ("MPC_ACC_HOR", 2.0),
        ("MPC_LAND_SPEED", 0.6),
        ("MPC_LAND_ALT1", 8.0),
        ("RTL_RETURN_ALT", 25.0),
        ("RTL_LAND_DELAY", 3.0),
        ("BAT1_CAPACITY", -1.0),
    ] {
        assert!((answer(name) - want).abs() < 1e-4, "{name}: {} not {want}", answer(name));
    }
    assert_eq!(f.charge, Some(100.0));
    vehicles.stop();
}
