//! The middle-layer functions (docs/LANGUAGE.md, section 19) as MAVLink exchanges. Every wait has a
//! limit, from the tuning or from the distance to fly, so a silent vehicle ends a call
//! with `Timeout` and never hangs the mission.

use aviary_api::geometry::centroid;
use aviary_api::{Failure, FunctionCall, Place, Region, Value, Waypoint};
use mavlink::dialects::ardupilotmega::MavCmd;

use crate::drone::{failed, Craft, Paused};
use crate::mode::Flavour;
use crate::motion::{
    arm, fly, fly_through, here, hover, land, orbit, routed, rtl, take_off, vertical, Pass,
};
use crate::vehicle::Activation;

use aviary_api::flight::{LOAD_MAX_ALTITUDE, LOAD_TIME};

/// Runs one call to its end.
pub async fn run(
    c: &Craft,
    call: &FunctionCall,
    paused: Paused,
    sensors: &[aviary_world::Sensor],
) -> Result<(), Failure> {
    match call {
        FunctionCall::Arm => arm(c).await,
        FunctionCall::Disarm => disarm(c).await,
        FunctionCall::TakeOff { alt } => take_off(c, number(*alt, "alt")?, paused).await,
        FunctionCall::Land => land(c).await,
        FunctionCall::ReturnToLaunch => rtl(c, paused).await,
        FunctionCall::FlyToPosition { pos, speed } => fly_to_position(c, pos, *speed, paused).await,
        FunctionCall::DescendTo { alt } | FunctionCall::AscendTo { alt } => {
            let here = here(c)?;
            let alt = number(*alt, "alt")?;
            vertical(c, here, alt)?;
            fly(c, &[[here[0], here[1], alt]], c.max_speed, paused).await
        }
        FunctionCall::Hover { duration } => hover(number(*duration, "duration")?, paused).await,
        FunctionCall::Orbit { center, radius, laps } => {
            orbit_around(c, center, *radius, *laps, paused).await
        }
        FunctionCall::Sweep { area, spacing } => sweep(c, area, *spacing, paused).await,
        FunctionCall::FollowPath { points, speed } => follow_path(c, points, *speed, paused).await,
        FunctionCall::StartStreaming => streaming(c, true),
        FunctionCall::StopStreaming => streaming(c, false),
        FunctionCall::StartDetection { kind } => detection(c, true, kind, sensors),
        FunctionCall::StopDetection { kind } => detection(c, false, kind, sensors),
        FunctionCall::LoadPayload { kind } => load(c, kind, paused).await,
        FunctionCall::ReleasePayload => release(c).await,
    }
}

/// `Disarm`, on the ground only; done when the HEARTBEAT says so.
async fn disarm(c: &Craft) -> Result<(), Failure> {
    if c.state().airborne() {
        return Err(failed(format!("{} can only disarm on the ground", c.name)));
    }
    c.command(MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, [0.0; 7]).await?;
    c.wait_for(c.tuning.ready_timeout, "disarming", |c| !c.v.seen().armed).await
}

/// `FlyToPosition`: at the speed asked for, at most the drone's, around the no-fly zones
/// (the detour's corners sent one after the other, each reached before the next).
async fn fly_to_position(
    c: &Craft,
    pos: &Place,
    speed: Option<f64>,
    paused: Paused,
) -> Result<(), Failure> {
    let to = point(c, pos, "pos")?;
    let speed = match speed {
        Some(s) if s > 0.0 => s.min(c.max_speed),
        Some(other) => {
            let other = Value::Number(other);
            return Err(failed(format!("`speed` must be above 0 m/s, not {other}")));
        }
        None => c.max_speed,
    };
    let way = routed(c, here(c)?, &[to])?;
    fly_through(c, &way, speed, paused).await
}

/// `Orbit`: to the circle around the no-fly zones, then through its points, at the speed
/// its radius allows; a circle that enters a zone is refused.
async fn orbit_around(
    c: &Craft,
    center: &Place,
    radius: f64,
    laps: Option<f64>,
    paused: Paused,
) -> Result<(), Failure> {
    let center = point(c, center, "center")?;
    let radius = number(radius, "radius")?;
    let laps = match laps {
        Some(laps) => number(laps, "laps")?,
        None => 1.0,
    };
    if radius <= 0.0 || laps <= 0.0 {
        return Err(failed(format!(
            "an orbit needs a radius and laps above 0 (got {radius} m, {laps})"
        )));
    }
    let here = here(c)?;
    let center = [center[0], center[1]];
    if let Some(reason) = c.airspace.circle_refusal(center, radius, c.level()) {
        return Err(Failure::new(aviary_api::BuiltinException::GeofenceViolation, reason));
    }
    let circle = orbit(here, center, radius, laps, c.tuning.arrive_xy);
    let mut way = routed(c, here, &circle[..1])?;
    let speed = aviary_api::geometry::orbit_speed(c.max_speed, c.acceleration, radius);
    if c.v.flavour() == Flavour::Px4 {
        // To the circle, then PX4's own ORBIT mode around it.
        fly_through(c, &way, c.max_speed, paused.clone()).await?;
        return crate::px4::orbit(c, center, radius, circle[0][2], laps, speed, paused).await;
    }
    way.extend(circle[1..].iter().map(|&p| (p, Pass::Cut)));
    fly_through(c, &way, speed, paused).await
}

/// `Sweep`: to the area's lawnmower path, or to the lanes a remainder left (the
/// contract's, `aviary_api::coverage`), around the no-fly zones; then along it, each lane
/// flown to its end, at the altitude kept. A sweep that enters a zone is refused.
async fn sweep(c: &Craft, area: &Region, spacing: f64, paused: Paused) -> Result<(), Failure> {
    let spacing = number(spacing, "spacing")?;
    if spacing <= 0.0 {
        return Err(failed(format!("sweep spacing must be above 0 m, not {spacing} m")));
    }
    let lanes = aviary_api::coverage::sweep_lanes(area, spacing).map_err(failed)?;
    if lanes.is_empty() {
        // Nothing left to sweep: done at once, as in the simulator.
        return Ok(());
    }
    let here = here(c)?;
    let z = c.level();
    let flat = aviary_api::sweep::path(&lanes);
    // A remainder has no area: its lanes alone must keep out of the zones.
    let outline: &[[f64; 2]] = match area {
        Region::Area(a) => a,
        Region::Left(_) => &[],
    };
    if let Some(reason) = c.airspace.sweep_refusal(outline, &flat, z) {
        return Err(Failure::new(aviary_api::BuiltinException::GeofenceViolation, reason));
    }
    let path: Vec<[f64; 3]> = flat.into_iter().map(|p| [p[0], p[1], z]).collect();
    // Each lane is flown to its end, as the simulator flies it: the pass radius is often
    // longer than the spacing, and a turn cut short would cross the next lane.
    let mut way = routed(c, here, &path[..1])?;
    for w in way.iter_mut().filter(|w| w.1 == Pass::Cut) {
        w.1 = Pass::Reach;
    }
    way.extend(path.iter().skip(1).map(|&p| (p, Pass::Reach)));
    fly_through(c, &way, c.max_speed, paused).await
}

/// `FollowPath`: through the points (a remainder's in its place), each a transit around
/// the no-fly zones from the one before; one without an altitude keeps the one before.
/// At the speed asked for (its last argument), at most the drone's, as `FlyToPosition`.
async fn follow_path(
    c: &Craft,
    points: &[Waypoint],
    speed: Option<f64>,
    paused: Paused,
) -> Result<(), Failure> {
    let points = aviary_api::coverage::follow_points(points).map_err(failed)?;
    let speed = aviary_api::coverage::follow_speed(speed).map_err(failed)?;
    let speed = speed.map_or(c.max_speed, |s| s.min(c.max_speed));
    if points.is_empty() {
        return Ok(());
    }
    let here = here(c)?;
    let mut z = c.level();
    let mut path = Vec::new();
    for p in points {
        z = p.z.unwrap_or(z);
        path.push([p.x, p.y, z]);
    }
    let way = routed(c, here, &path)?;
    fly_through(c, &way, speed, paused).await
}

/// `StartStreaming` and `StopStreaming`. Video is not carried over MAVLink: this records
/// the state a mission reads.
fn streaming(c: &Craft, on: bool) -> Result<(), Failure> {
    if !c.sensors.iter().any(|s| s == "camera") {
        return Err(failed(format!("{} has no camera", c.name)));
    }
    c.streaming.store(on, std::sync::atomic::Ordering::SeqCst);
    Ok(())
}

/// `ReleasePayload`: opens the gripper (MAV_CMD_DO_GRIPPER release).
async fn release(c: &Craft) -> Result<(), Failure> {
    if c.carrying.lock().is_none() {
        return Err(failed(format!("{} carries nothing to release", c.name)));
    }
    c.command(MavCmd::MAV_CMD_DO_GRIPPER, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]).await?;
    *c.carrying.lock() = None;
    Ok(())
}

fn number(n: f64, name: &str) -> Result<f64, Failure> {
    if n.is_finite() {
        return Ok(n);
    }
    Err(failed(format!("`{name}` must be a finite number, not {}", Value::Number(n))))
}

/// A position argument in local metres; without a height, the altitude kept.
fn point(c: &Craft, v: &Place, name: &str) -> Result<[f64; 3], Failure> {
    let here_z = c.level();
    match v {
        Place::Point(p) if p.x.is_finite() && p.y.is_finite() => {
            Ok([p.x, p.y, p.z.unwrap_or(here_z)])
        }
        Place::Area(a) if !a.is_empty() => {
            let m = centroid(a);
            Ok([m[0], m[1], here_z])
        }
        other => Err(failed(format!("`{name}` must be a position, not {other}"))),
    }
}

fn detection(
    c: &Craft,
    start: bool,
    kind: &str,
    sensors: &[aviary_world::Sensor],
) -> Result<(), Failure> {
    let kind = kind.to_owned();
    let range = sensors
        .iter()
        .filter(|s| c.sensors.contains(&s.kind) && s.detects.contains(&kind))
        .map(|s| s.range)
        .reduce(f64::max)
        .ok_or_else(|| failed(format!("{} has no sensor that detects {kind}", c.name)))?;
    let n = c.v.target_count();
    let mut seen = c.v.seen();
    seen.detecting.retain(|a| a.kind != kind);
    if start {
        seen.detecting.push(Activation { kind, range, found: vec![false; n] });
    }
    Ok(())
}

/// Closes the gripper (MAV_CMD_DO_GRIPPER grab) and gives the crew `LOAD_TIME` to hook on.
async fn load(c: &Craft, kind: &str, paused: Paused) -> Result<(), Failure> {
    let kind = kind.to_owned();
    if !c.payload.contains(&kind) {
        return Err(failed(format!("{} cannot carry {kind}", c.name)));
    }
    if let Some(held) = c.carrying.lock().as_ref() {
        return Err(failed(format!("{} already carries {held}: release it first", c.name)));
    }
    let z = c.fix().map_or(0.0, |f| f.pos[2]);
    if c.state().airborne() && z >= LOAD_MAX_ALTITUDE {
        return Err(failed(format!(
            "{} is at {z:.1} m: load while landed or below {LOAD_MAX_ALTITUDE} m",
            c.name
        )));
    }
    c.command(MavCmd::MAV_CMD_DO_GRIPPER, [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]).await?;
    hover(LOAD_TIME, paused).await?;
    *c.carrying.lock() = Some(kind);
    Ok(())
}
