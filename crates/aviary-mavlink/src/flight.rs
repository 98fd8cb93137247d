//! The middle-layer functions (LANGUAGE.md §4) as MAVLink exchanges. Every wait has a
//! limit, from the tuning or from the distance to fly, so a silent vehicle ends a call
//! with `Timeout` and never hangs the mission.

use std::time::Duration;

use aviary_api::geometry::{centroid, contains, dist};
use aviary_api::{Failure, Value};
use mavlink::dialects::ardupilotmega::MavCmd;
use tokio::time::Instant;

use crate::craft::{failed, timeout, Craft, Doing, Paused};
use crate::mode::Mode;
use crate::vehicle::Activation;

/// Seconds `LoadPayload` waits after closing the gripper, as the simulator does.
pub const LOAD_TIME: f64 = 2.0;
/// Legs an orbit is flown in, per lap.
const ORBIT_POINTS: usize = 24;

/// Runs one call to its end.
pub async fn run(c: &Craft, function: &str, args: &[Value], paused: Paused, sensors: &[aviary_world::Sensor]) -> Result<(), Failure> {
    match function {
        "Arm" => arm(c).await,
        "Disarm" => {
            if c.v.seen().armed && c.state().airborne() {
                return Err(failed(format!("{} can only disarm on the ground", c.name)));
            }
            c.command(MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, [0.0; 7]).await?;
            c.wait_for(c.tuning.ready_timeout, "disarming", |c| !c.v.seen().armed).await
        }
        "TakeOff" => take_off(c, number(args, 0, "alt")?, paused).await,
        "Land" => land(c).await,
        "ReturnToLaunch" => rtl(c).await,
        "FlyToPosition" => {
            let to = point(c, args.first(), "pos")?;
            let speed = match args.get(1) {
                Some(Value::Number(s)) if *s > 0.0 => s.min(c.max_speed),
                Some(other) => return Err(failed(format!("`speed` must be above 0 m/s, not {other:?}"))),
                None => c.max_speed,
            };
            fly(c, &[to], speed, paused).await
        }
        "DescendTo" | "AscendTo" => {
            let here = here(c)?;
            fly(c, &[[here[0], here[1], number(args, 0, "alt")?]], c.max_speed, paused).await
        }
        "Hover" => hover(number(args, 0, "duration")?, paused).await,
        "Orbit" => {
            let center = point(c, args.first(), "center")?;
            let radius = number(args, 1, "radius")?;
            let laps = match args.get(2) { Some(_) => number(args, 2, "laps")?, None => 1.0 };
            if radius <= 0.0 || laps <= 0.0 {
                return Err(failed(format!("an orbit needs a radius and laps above 0 (got {radius} m, {laps})")));
            }
            let here = here(c)?;
            fly(c, &orbit(here, [center[0], center[1]], radius, laps), c.max_speed, paused).await
        }
        "Sweep" => {
            let Some(Value::Area(area)) = args.first() else { return Err(failed("`area` must be an area")) };
            let spacing = number(args, 1, "spacing")?;
            if spacing <= 0.0 {
                return Err(failed(format!("sweep spacing must be above 0 m, not {spacing} m")));
            }
            let z = here(c)?[2];
            let path: Vec<[f64; 3]> = aviary_sim::sweep::lawnmower(area, spacing).into_iter().map(|p| [p[0], p[1], z]).collect();
            fly(c, &path, c.max_speed, paused).await
        }
        "FollowPath" => {
            let mut z = here(c)?[2];
            let mut path = Vec::new();
            for v in args {
                let p = point(c, Some(v), "points")?;
                if !p[2].is_nan() {
                    z = p[2];
                }
                path.push([p[0], p[1], z]);
            }
            fly(c, &path, c.max_speed, paused).await
        }
        "StartStreaming" | "StopStreaming" => {
            // Video is not carried over MAVLink: this records the state a mission reads.
            if !c.sensors.iter().any(|s| s == "camera") {
                return Err(failed(format!("{} has no camera", c.name)));
            }
            c.streaming.store(function == "StartStreaming", std::sync::atomic::Ordering::SeqCst);
            Ok(())
        }
        "StartDetection" | "StopDetection" => detection(c, function == "StartDetection", args, sensors),
        "LoadPayload" => load(c, args, paused).await,
        "ReleasePayload" => {
            if c.carrying.lock().unwrap_or_else(|p| p.into_inner()).is_none() {
                return Err(failed(format!("{} carries nothing to release", c.name)));
            }
            c.command(MavCmd::MAV_CMD_DO_GRIPPER, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]).await?;
            *c.carrying.lock().unwrap_or_else(|p| p.into_inner()) = None;
            Ok(())
        }
        other => Err(failed(format!("{} cannot do {other} over MAVLink", c.name))),
    }
}

fn number(args: &[Value], i: usize, name: &str) -> Result<f64, Failure> {
    match args.get(i) {
        Some(Value::Number(n)) if n.is_finite() => Ok(*n),
        other => Err(failed(format!("`{name}` must be a finite number, not {other:?}"))),
    }
}

/// A position argument in local metres; z is NaN when it has none (keep the altitude).
fn point(c: &Craft, v: Option<&Value>, name: &str) -> Result<[f64; 3], Failure> {
    let here_z = c.fix().map_or(f64::NAN, |f| f.pos[2]);
    match v {
        Some(Value::Position(p)) if p.x.is_finite() && p.y.is_finite() => Ok([p.x, p.y, p.z.unwrap_or(if name == "points" { f64::NAN } else { here_z })]),
        Some(Value::Area(a)) if !a.is_empty() => {
            let m = centroid(a);
            Ok([m[0], m[1], if name == "points" { f64::NAN } else { here_z }])
        }
        other => Err(failed(format!("`{name}` must be a position, not {other:?}"))),
    }
}

fn here(c: &Craft) -> Result<[f64; 3], Failure> {
    c.fix().map(|f| f.pos).ok_or_else(|| failed(format!("{} has reported no position yet", c.name)))
}

fn in_air(c: &Craft) -> Result<(), Failure> {
    if c.state().airborne() {
        Ok(())
    } else {
        Err(failed(format!("{} is on the ground: take off first", c.name)))
    }
}

/// Ready, GUIDED, then ARM, asked again while the pre-arm checks still fail (GPS and EKF
/// take about 40 s on a fresh ArduCopter), and confirmed by HEARTBEAT.
async fn arm(c: &Craft) -> Result<(), Failure> {
    if c.v.seen().armed {
        return Ok(());
    }
    c.ready().await?;
    c.set_mode(Mode::Guided).await?;
    let deadline = Instant::now() + c.tuning.arm_timeout;
    loop {
        match c.command(MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]).await {
            Ok(()) => break,
            Err(f) if f.exception == "CommandFailed" && Instant::now() < deadline => {
                tokio::time::sleep(c.tuning.arm_retry).await;
            }
            Err(f) => return Err(f),
        }
    }
    c.wait_for(Duration::from_secs(5), "arming", |c| c.v.seen().armed).await
}

async fn take_off(c: &Craft, alt: f64, paused: Paused) -> Result<(), Failure> {
    if alt <= 0.0 {
        return Err(failed(format!("take-off altitude must be above 0 m, not {alt} m")));
    }
    if c.state().airborne() {
        let here = here(c)?;
        return fly(c, &[[here[0], here[1], alt]], c.max_speed, paused).await;
    }
    if !c.v.seen().armed {
        return Err(failed(format!("{} is not armed: call Arm() before TakeOff", c.name)));
    }
    // NAV_TAKEOFF is refused outside GUIDED, so make sure of it first.
    c.set_mode(Mode::Guided).await?;
    c.set_doing(Doing::TakingOff);
    let result = async {
        c.command(MavCmd::MAV_CMD_NAV_TAKEOFF, [0.0, 0.0, 0.0, f32::NAN, f32::NAN, f32::NAN, alt as f32]).await?;
        let limit = Duration::from_secs_f64(alt / 0.5 + 30.0);
        let tol = c.tuning.arrive_z;
        c.wait_for(limit, &format!("climbing to {alt} m"), |c| c.fix().is_some_and(|f| f.pos[2] >= alt - tol)).await
    }
    .await;
    c.set_doing(Doing::Other);
    result
}

async fn land(c: &Craft) -> Result<(), Failure> {
    if !c.state().airborne() {
        return Ok(());
    }
    c.v.seen().expected = Some(Mode::Land);
    c.set_doing(Doing::Landing);
    let z = here(c).map_or(0.0, |p| p[2]);
    let result = async {
        c.command(MavCmd::MAV_CMD_NAV_LAND, [0.0, 0.0, 0.0, f32::NAN, f32::NAN, f32::NAN, 0.0]).await?;
        // ArduCopter disarms by itself once down.
        c.wait_for(Duration::from_secs_f64(z / 0.5 + 60.0), "landing", |c| !c.v.seen().armed).await
    }
    .await;
    c.set_doing(Doing::Other);
    result
}

async fn rtl(c: &Craft) -> Result<(), Failure> {
    let Some(here) = c.fix().map(|f| f.pos) else { return Err(failed(format!("{} has reported no position yet", c.name))) };
    let away = dist([here[0], here[1]], c.home);
    if !c.state().airborne() {
        if away <= 2.0 {
            return Ok(());
        }
        return Err(failed(format!("{} is on the ground away from home: take off first", c.name)));
    }
    c.v.seen().expected = Some(Mode::Rtl);
    c.command(MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH, [0.0; 7]).await?;
    let limit = Duration::from_secs_f64(away / c.max_speed.max(1.0) * 2.0 + (here[2] + 20.0) / 0.5 + 60.0);
    c.wait_for(limit, "returning to launch", |c| !c.v.seen().armed).await
}

/// Flies through `path` (local metres), each point reached by position within the
/// tolerances; PAUSE holds where the drone is, RESUME sends the target again.
async fn fly(c: &Craft, path: &[[f64; 3]], speed: f64, mut paused: Paused) -> Result<(), Failure> {
    in_air(c)?;
    fenced(c, path)?;
    c.set_mode(Mode::Guided).await?;
    c.speed(speed).await?;
    for &to in path {
        let from = here(c)?;
        let to = [to[0], to[1], if to[2].is_nan() { from[2] } else { to[2] }];
        if to[2] < 0.0 {
            return Err(failed(format!("altitude {} m is below the ground", to[2])));
        }
        let far = dist([from[0], from[1]], [to[0], to[1]]).hypot(to[2] - from[2]);
        let mut left = Duration::from_secs_f64(far / speed.max(0.5) * 3.0 + 30.0);
        c.target(to).await?;
        let mut resend = Instant::now() + c.tuning.resend;
        loop {
            let fix = here(c)?;
            if dist([fix[0], fix[1]], [to[0], to[1]]) <= c.tuning.arrive_xy && (fix[2] - to[2]).abs() <= c.tuning.arrive_z {
                break;
            }
            if *paused.borrow() {
                c.hold().await;
                while *paused.borrow() {
                    if paused.changed().await.is_err() {
                        return Err(failed("the call was dropped"));
                    }
                }
                c.target(to).await?;
            }
            if Instant::now() >= resend {
                // A lost UDP datagram must not leave the drone without its target.
                c.target(to).await?;
                resend = Instant::now() + c.tuning.resend;
            }
            if left.is_zero() {
                return Err(timeout(format!("{} did not reach ({:.1}, {:.1}, {:.1}) in time", c.name, to[0], to[1], to[2])));
            }
            tokio::time::sleep(c.tuning.poll).await;
            left = left.saturating_sub(c.tuning.poll);
        }
    }
    Ok(())
}

/// The world's geofence and ceiling hold for MAVLink drones too: a path that leaves them
/// is refused before anything is sent (`GeofenceViolation`).
fn fenced(c: &Craft, path: &[[f64; 3]]) -> Result<(), Failure> {
    let violation = |reason: String| Failure { exception: "GeofenceViolation", reason };
    for p in path {
        if let Some(max) = c.max_altitude.filter(|m| p[2] > m + 1e-9) {
            return Err(violation(format!("altitude {:.1} m is above the site's max_altitude of {max:.1} m", p[2])));
        }
        if let Some(fence) = c.fence.as_deref().filter(|f| !contains(f, [p[0], p[1]])) {
            let _ = fence;
            return Err(violation(format!("({:.1}, {:.1}) is outside the geofence", p[0], p[1])));
        }
    }
    Ok(())
}

async fn hover(duration: f64, paused: Paused) -> Result<(), Failure> {
    if duration < 0.0 || !duration.is_finite() {
        return Err(failed(format!("a hover cannot last {duration} s")));
    }
    let step = Duration::from_millis(50);
    let mut left = Duration::from_secs_f64(duration);
    while !left.is_zero() {
        tokio::time::sleep(step.min(left)).await;
        if !*paused.borrow() {
            left = left.saturating_sub(step);
        }
    }
    Ok(())
}

/// Points on the circle, clockwise from the one nearest the drone, at its altitude.
fn orbit(here: [f64; 3], center: [f64; 2], radius: f64, laps: f64) -> Vec<[f64; 3]> {
    let start = (here[1] - center[1]).atan2(here[0] - center[0]);
    let n = (laps * ORBIT_POINTS as f64).ceil() as usize;
    let step = laps * std::f64::consts::TAU / n as f64;
    (0..=n)
        .map(|i| {
            let a = start - step * i as f64;
            [center[0] + radius * a.cos(), center[1] + radius * a.sin(), here[2]]
        })
        .collect()
}

fn detection(c: &Craft, start: bool, args: &[Value], sensors: &[aviary_world::Sensor]) -> Result<(), Failure> {
    let kind = match args.first() {
        Some(Value::Symbol(s) | Value::Text(s)) => s.clone(),
        other => return Err(failed(format!("`kind` must be a kind such as Body, not {other:?}"))),
    };
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
async fn load(c: &Craft, args: &[Value], paused: Paused) -> Result<(), Failure> {
    let kind = match args.first() {
        Some(Value::Symbol(s) | Value::Text(s)) => s.clone(),
        other => return Err(failed(format!("`kind` must be a kind such as Body, not {other:?}"))),
    };
    if !c.payload.contains(&kind) {
        return Err(failed(format!("{} cannot carry {kind}", c.name)));
    }
    if let Some(held) = c.carrying.lock().unwrap_or_else(|p| p.into_inner()).as_ref() {
        return Err(failed(format!("{} already carries {held}: release it first", c.name)));
    }
    let z = c.fix().map_or(0.0, |f| f.pos[2]);
    if c.state().airborne() && z >= 5.0 {
        return Err(failed(format!("{} is at {z:.1} m: load while landed or below 5 m", c.name)));
    }
    c.command(MavCmd::MAV_CMD_DO_GRIPPER, [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]).await?;
    hover(LOAD_TIME, paused).await?;
    *c.carrying.lock().unwrap_or_else(|p| p.into_inner()) = Some(kind);
    Ok(())
}
