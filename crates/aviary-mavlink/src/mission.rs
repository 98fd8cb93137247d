//! A path on PX4, flown as a mission: PX4's HOLD brakes to a stop at every DO_REPOSITION
//! target, so a `Sweep` or a `FollowPath` sent point by point would stop at each point.
//! Its mission mode (AUTO.MISSION) flies through waypoints, turning at speed where the
//! path bends, as the simulator's drones and ArduCopter in GUIDED do.
//!
//! The path is uploaded with the mission protocol (MISSION_COUNT, a MISSION_ITEM_INT for
//! each MISSION_REQUEST(_INT), MISSION_ACK), begun with MAV_CMD_MISSION_START, and
//! followed by what the vehicle reports: MISSION_CURRENT says which point it flies to
//! (`Craft::flying_to`, for a remainder), MISSION_ITEM_REACHED that the last is reached.
//! PAUSE is HOLD where the drone is; RESUME is AUTO.MISSION again, which goes on from the
//! item it was flying to.

use std::time::Duration;

use aviary_api::geometry::dist;
use aviary_api::Failure;
use aviary_clock::Instant;
use mavlink::dialects::ardupilotmega::{
    MavCmd, MavFrame, MavMessage, MavMissionResult, MavMissionType, MISSION_COUNT_DATA,
    MISSION_ITEM_INT_DATA,
};
use tokio::sync::mpsc;

use crate::drone::{failed, timeout, Craft, Paused};
use crate::mode::{self, Mode};
use crate::motion::{held, here, late, Pass, Waypoint};
use crate::vehicle::Upload;
use aviary_api::geo::Origin;

const MISSION: MavMissionType = MavMissionType::MAV_MISSION_TYPE_MISSION;

/// How long PX4 may take to check a mission it has taken (by the mission's clock).
const CHECKED_WITHIN: Duration = Duration::from_secs(5);

/// A path as mission items, and for each item the index (among the call's own points) of
/// the point the drone flies to while the vehicle is at that item.
#[derive(Debug, PartialEq)]
pub(crate) struct Plan {
    pub items: Vec<MISSION_ITEM_INT_DATA>,
    pub leads_to: Vec<usize>,
}

/// The mission for `path` (heights above home; a NaN height keeps the one before, the
/// first `level`): DO_CHANGE_SPEED first (PX4 resets its cruise speed when a mission
/// starts, so a speed commanded before would be lost), then a NAV_WAYPOINT for each
/// point. A point passed (`Pass::Cut`) has no acceptance radius of its own: PX4's
/// NAV_ACC_RAD and its corner speed apply, and it turns there at speed. A point to be
/// reached (a lane's end, a detour's corner) and the last are accepted within `arrive_xy`.
pub(crate) fn plan(
    path: &[Waypoint],
    speed: f64,
    level: f64,
    arrive_xy: f64,
    origin: Origin,
    system: u8,
) -> Plan {
    let item =
        |seq: usize, command, frame, p: [f32; 4], at: (i32, i32, f32)| MISSION_ITEM_INT_DATA {
            param1: p[0],
            param2: p[1],
            param3: p[2],
            param4: p[3],
            x: at.0,
            y: at.1,
            z: at.2,
            seq: seq as u16,
            command,
            target_system: system,
            target_component: 1,
            frame,
            current: 0,
            autocontinue: 1,
            mission_type: MISSION,
        };
    let mut items = vec![item(
        0,
        MavCmd::MAV_CMD_DO_CHANGE_SPEED,
        MavFrame::MAV_FRAME_MISSION,
        [1.0, speed as f32, -1.0, 0.0],
        (0, 0, 0.0),
    )];
    let mut leads_to = vec![0];
    let (mut z, mut on_path) = (level, 0);
    for (i, &(p, how)) in path.iter().enumerate() {
        if !p[2].is_nan() {
            z = p[2];
        }
        let (lat, lon) = origin.to_e7(p[0], p[1]);
        let last = i + 1 == path.len();
        let accept = if how == Pass::Cut && !last { 0.0 } else { arrive_xy as f32 };
        items.push(item(
            items.len(),
            MavCmd::MAV_CMD_NAV_WAYPOINT,
            MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
            [0.0, accept, 0.0, f32::NAN],
            (lat, lon, z as f32),
        ));
        leads_to.push(on_path);
        if how != Pass::Corner {
            on_path += 1;
        }
    }
    Plan { items, leads_to }
}

/// Flies `path` (already checked against the fence and the no-fly zones) through its
/// points at `speed` in PX4's mission mode.
pub(crate) async fn fly(
    c: &Craft,
    path: &[Waypoint],
    speed: f64,
    mut paused: Paused,
) -> Result<(), Failure> {
    let began = Instant::now();
    let start = here(c)?;
    let plan = plan(path, speed, c.level(), c.tuning.arrive_xy, c.v.origin(), c.v.system);
    let (Some(&(p, _)), Some(item)) = (path.last(), plan.items.last()) else { return Ok(()) };
    let end = [p[0], p[1], f64::from(item.z)];
    if let Some(low) = plan.items.iter().skip(1).find(|it| it.z < 0.0) {
        return Err(failed(format!("altitude {} m is below the ground", low.z)));
    }
    let last = item.seq;
    c.set_flying_to(Some(0));
    c.set_level(Some(end[2]));
    upload(c, &plan.items).await?;
    begin(c).await?;
    let mut left = Duration::from_secs_f64(length(start, path) / speed.max(0.5) * 3.0 + 30.0);
    loop {
        let (current, reached, custom_mode) = {
            let seen = c.v.seen();
            (seen.mission_current, seen.mission_reached, seen.custom_mode)
        };
        if let Some(&at) = current.and_then(|seq| plan.leads_to.get(usize::from(seq))) {
            c.set_flying_to(Some(at));
        }
        let fix = here(c)?;
        let there = dist([fix[0], fix[1]], [end[0], end[1]]) <= c.tuning.arrive_xy
            && (fix[2] - end[2]).abs() <= c.tuning.arrive_z;
        if reached == Some(last) || (current == Some(last) && there) {
            break;
        }
        if *paused.borrow() {
            held(c, &mut paused).await?;
            resume(c, speed).await?;
            continue;
        }
        let flavour = c.v.flavour();
        let now = mode::classify(flavour, custom_mode);
        // PX4 goes to HOLD by itself once the last item is reached: done, if its
        // MISSION_ITEM_REACHED was lost on the way.
        if now == Mode::Guided && current == Some(last) {
            break;
        }
        // A failsafe's RTL or LAND is the vehicle's alarm, which ends the call; any other
        // mode (HOLD after PX4 rejected the mission, a pilot's) ends the path here.
        if !matches!(now, Mode::Mission | Mode::Rtl | Mode::Land) {
            let why = c.v.texts_since(began).unwrap_or_else(|| "no reason given".into());
            return Err(failed(format!(
                "{} left its path for {} before its end: {why}",
                c.name,
                mode::name(flavour, custom_mode)
            )));
        }
        if left.is_zero() {
            return Err(late(c, "fly its path to", end));
        }
        aviary_clock::sleep(c.tuning.poll).await;
        left = left.saturating_sub(c.tuning.poll);
    }
    // At the end: HOLD, where PX4 brakes and stays (it may have gone there by itself).
    c.set_mode(Mode::Guided).await
}

/// Metres from `from` through the points of `path` (a NaN height keeps the one before).
fn length(from: [f64; 3], path: &[Waypoint]) -> f64 {
    let mut at = from;
    let mut total = 0.0;
    for &(p, _) in path {
        let to = [p[0], p[1], if p[2].is_nan() { at[2] } else { p[2] }];
        total += dist([at[0], at[1]], [to[0], to[1]]).hypot(to[2] - at[2]);
        at = to;
    }
    total
}

/// Uploads `items` (MISSION_COUNT, then each item the vehicle asks for, to its
/// MISSION_ACK). The vehicle asks again for what it did not get; this side sends the
/// count or the last item again when the vehicle is silent, and gives up when it stays
/// silent for the command tries' time, by the mission's clock and the wall's.
async fn upload(c: &Craft, items: &[MISSION_ITEM_INT_DATA]) -> Result<(), Failure> {
    let began = Instant::now();
    let (tx, mut rx) = mpsc::unbounded_channel();
    {
        let mut seen = c.v.seen();
        seen.upload = Some(tx);
        seen.mission_current = None;
        seen.mission_reached = None;
    }
    let result = async {
        let count = MavMessage::MISSION_COUNT(MISSION_COUNT_DATA {
            count: items.len() as u16,
            target_system: c.v.system,
            target_component: 1,
            mission_type: MISSION,
            opaque_id: 0,
        });
        let mut last = count;
        let mut silent = 0;
        c.link.send(&last).await;
        loop {
            let sent = std::time::Instant::now();
            let heard = loop {
                match aviary_clock::timeout(c.tuning.ack_timeout, rx.recv()).await {
                    Ok(heard) => break heard,
                    // Silent by the mission's clock; by the wall's too? (As for commands:
                    // a vehicle that lags the others has had less of the mission's time.)
                    Err(_) if sent.elapsed() < c.tuning.ack_timeout => continue,
                    Err(_) => break None,
                }
            };
            match heard {
                Some(Upload::Request(seq)) => {
                    let Some(item) = items.get(usize::from(seq)) else {
                        return Err(failed(format!(
                            "{} asked for mission item {seq} of {}",
                            c.name,
                            items.len()
                        )));
                    };
                    silent = 0;
                    last = MavMessage::MISSION_ITEM_INT(item.clone());
                }
                Some(Upload::Ack(MavMissionResult::MAV_MISSION_ACCEPTED)) => return Ok(()),
                Some(Upload::Ack(result)) => {
                    // The reason usually comes with the answer; give a late one a moment.
                    aviary_clock::sleep(Duration::from_millis(50)).await;
                    let why = c.v.texts_since(began).unwrap_or_else(|| "no reason given".into());
                    return Err(failed(format!("{} refused its path ({result:?}): {why}", c.name)));
                }
                None => {
                    silent += 1;
                    if silent >= c.tuning.command_tries {
                        return Err(timeout(format!(
                            "{} did not take its path as a mission: no answer after {} tries ({} s each) on {}",
                            c.name,
                            c.tuning.command_tries,
                            c.tuning.ack_timeout.as_secs_f64(),
                            c.link.address
                        )));
                    }
                }
            }
            c.link.send(&last).await;
        }
    }
    .await;
    c.v.seen().upload = None;
    result
}

/// MISSION_START from the first item: PX4's commander switches to AUTO.MISSION, its
/// navigator to item 0. Done when HEARTBEAT shows the mode. PX4 checks a mission after
/// it has acknowledged it, and until its navigator has said the mission is valid its
/// commander denies the start ("No valid mission"): asked again for [`CHECKED_WITHIN`],
/// then refused with PX4's words (a mission it finds unfeasible says why).
async fn begin(c: &Craft) -> Result<(), Failure> {
    c.v.seen().expected = Some(Mode::Mission);
    let deadline = Instant::now() + CHECKED_WITHIN;
    loop {
        match c.command(MavCmd::MAV_CMD_MISSION_START, [0.0; 7]).await {
            Ok(()) => break,
            Err(f)
                if f.exception == aviary_api::BuiltinException::CommandFailed
                    && Instant::now() < deadline =>
            {
                aviary_clock::sleep(Duration::from_millis(250)).await;
            }
            Err(f) => return Err(f),
        }
    }
    let flavour = c.v.flavour();
    let on = |c: &Craft| mode::classify(flavour, c.v.seen().custom_mode) == Mode::Mission;
    if c.wait_for(Duration::from_secs(3), "", on).await.is_err() {
        c.set_mode(Mode::Mission).await?;
    }
    Ok(())
}

/// After a PAUSE: AUTO.MISSION again, on from the item it was flying to, at the path's
/// speed (PX4 resets its cruise speed when a mode starts).
async fn resume(c: &Craft, speed: f64) -> Result<(), Failure> {
    c.set_mode(Mode::Mission).await?;
    c.command(MavCmd::MAV_CMD_DO_CHANGE_SPEED, [1.0, speed as f32, -1.0, 0.0, 0.0, 0.0, 0.0]).await
}

#[cfg(test)]
mod tests {
    use super::*;

    fn origin() -> Origin {
        Origin { lat: 46.6167, lon: 14.2650, alt: 440.0 }
    }

    #[test]
    fn a_path_is_a_speed_then_a_waypoint_for_each_point() {
        let path = [
            ([40.0, 0.0, f64::NAN], Pass::Corner),
            ([60.0, 30.0, 20.0], Pass::Cut),
            ([60.0, 90.0, f64::NAN], Pass::Reach),
            ([0.0, 90.0, 25.0], Pass::Cut),
        ];
        let plan = plan(&path, 7.5, 15.0, 1.0, origin(), 3);
        let seen: Vec<_> = plan
            .items
            .iter()
            .map(|it| (it.seq, it.command, it.frame, it.param1, it.param2, it.z, it.autocontinue))
            .collect();
        use MavCmd::*;
        use MavFrame::*;
        assert_eq!(
            seen,
            [
                (0, MAV_CMD_DO_CHANGE_SPEED, MAV_FRAME_MISSION, 1.0, 7.5, 0.0, 1),
                // A corner is reached; NaN keeps the level before.
                (1, MAV_CMD_NAV_WAYPOINT, MAV_FRAME_GLOBAL_RELATIVE_ALT, 0.0, 1.0, 15.0, 1),
                // Passed: PX4's own acceptance radius.
                (2, MAV_CMD_NAV_WAYPOINT, MAV_FRAME_GLOBAL_RELATIVE_ALT, 0.0, 0.0, 20.0, 1),
                (3, MAV_CMD_NAV_WAYPOINT, MAV_FRAME_GLOBAL_RELATIVE_ALT, 0.0, 1.0, 20.0, 1),
                // The last is reached, passed or not.
                (4, MAV_CMD_NAV_WAYPOINT, MAV_FRAME_GLOBAL_RELATIVE_ALT, 0.0, 1.0, 25.0, 1),
            ]
        );
        assert!(plan.items.iter().all(|it| it.target_system == 3 && it.mission_type == MISSION));
        // The corner leads to the call's first point; each point of the call is its own.
        assert_eq!(plan.leads_to, [0, 0, 0, 1, 2]);
        let (lat, lon) = origin().to_e7(60.0, 90.0);
        assert_eq!((plan.items[3].x, plan.items[3].y), (lat, lon));
    }

    #[test]
    fn a_path_s_length_counts_its_climbs() {
        let path = [([30.0, 40.0, f64::NAN], Pass::Cut), ([30.0, 40.0, 22.0], Pass::Cut)];
        assert!((length([0.0, 0.0, 10.0], &path) - 62.0).abs() < 1e-9);
    }
}
