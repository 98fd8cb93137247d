//! The flight itself: arming, take-off, landing, return and flying through points,
//! each confirmed by what the vehicle reports and bounded in time.

use std::time::Duration;

use aviary_api::geometry::{contains, dist};
use aviary_api::show::fixed;
use aviary_api::{BuiltinException, Failure};
use aviary_clock::Instant;
use mavlink::dialects::ardupilotmega::MavCmd;

use crate::drone::{failed, timeout, Craft, Doing, Paused};
use crate::mode::Mode;

/// Legs an orbit is flown in, per lap.
const ORBIT_POINTS: usize = 24;

pub(crate) fn here(c: &Craft) -> Result<[f64; 3], Failure> {
    c.fix().map(|f| f.pos).ok_or_else(|| failed(format!("{} has reported no position yet", c.name)))
}

pub(crate) fn in_air(c: &Craft) -> Result<(), Failure> {
    if c.state().airborne() {
        Ok(())
    } else {
        Err(failed(format!("{} is on the ground: take off first", c.name)))
    }
}

/// Ready, GUIDED, then ARM, asked again while the pre-arm checks still fail (GPS and EKF
/// take about 40 s on a fresh ArduCopter), and confirmed by HEARTBEAT.
pub(crate) async fn arm(c: &Craft) -> Result<(), Failure> {
    if c.v.seen().armed {
        return Ok(());
    }
    c.ready().await?;
    c.set_mode(Mode::Guided).await?;
    let deadline = Instant::now() + c.tuning.arm_timeout;
    loop {
        match c
            .command(MavCmd::MAV_CMD_COMPONENT_ARM_DISARM, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
            .await
        {
            Ok(()) => break,
            Err(f)
                if f.exception == BuiltinException::CommandFailed && Instant::now() < deadline =>
            {
                aviary_clock::sleep(c.tuning.arm_retry).await;
            }
            Err(f) => return Err(f),
        }
    }
    c.wait_for(Duration::from_secs(5), "arming", |c| c.v.seen().armed).await
}

pub(crate) async fn take_off(c: &Craft, alt: f64, paused: Paused) -> Result<(), Failure> {
    if alt <= 0.0 {
        return Err(failed(format!("take-off altitude must be above 0 m, not {alt} m")));
    }
    if c.state().airborne() {
        let here = here(c)?;
        vertical(c, here, alt)?;
        return fly(c, &[[here[0], here[1], alt]], c.max_speed, paused).await;
    }
    if !c.v.seen().armed {
        return Err(failed(format!("{} is not armed: call Arm() before TakeOff", c.name)));
    }
    // NAV_TAKEOFF is refused outside GUIDED, so make sure of it first.
    c.set_mode(Mode::Guided).await?;
    c.set_doing(Doing::TakingOff);
    c.set_level(Some(alt));
    let result = async {
        // ArduPilot reads the take-off altitude above home, PX4 above sea level.
        let param7 = match c.v.flavour() {
            crate::mode::Flavour::ArduPilot => alt,
            crate::mode::Flavour::Px4 => c.fix().map_or(alt, |f| f.home_amsl + alt),
        };
        c.command(
            MavCmd::MAV_CMD_NAV_TAKEOFF,
            [0.0, 0.0, 0.0, f32::NAN, f32::NAN, f32::NAN, param7 as f32],
        )
        .await?;
        let limit = Duration::from_secs_f64(alt / 0.5 + 30.0);
        let tol = c.tuning.arrive_z;
        c.wait_for(limit, &format!("climbing to {alt} m"), |c| {
            c.fix().is_some_and(|f| f.pos[2] >= alt - tol)
        })
        .await
    }
    .await;
    c.set_doing(Doing::Other);
    result
}

pub(crate) async fn land(c: &Craft) -> Result<(), Failure> {
    if !c.state().airborne() {
        return Ok(());
    }
    if let Ok(here) = here(c) {
        vertical(c, here, 0.0)?;
    }
    c.v.seen().expected = Some(Mode::Land);
    c.set_level(None);
    c.set_doing(Doing::Landing);
    let z = here(c).map_or(0.0, |p| p[2]);
    let result = async {
        c.command(MavCmd::MAV_CMD_NAV_LAND, [0.0, 0.0, 0.0, f32::NAN, f32::NAN, f32::NAN, 0.0])
            .await?;
        // ArduCopter disarms by itself once down.
        c.wait_for(Duration::from_secs_f64(z / 0.5 + 60.0), "landing", |c| !c.v.seen().armed).await
    }
    .await;
    c.set_doing(Doing::Other);
    result
}

/// The way home of `ReturnToLaunch` around the no-fly zones: when the straight line home
/// is clear, nothing (the autopilot's RTL flies it); else up to the return height and
/// through the detour's corners in GUIDED, each reached before the next, to the last one,
/// from which the line home is clear and the autopilot's RTL takes over.
async fn detour_home(c: &Craft, here: [f64; 3], paused: Paused) -> Result<(), Failure> {
    let safe = aviary_api::flight::return_height(here[2], c.return_altitude, c.max_altitude);
    let home = [c.home[0], c.home[1], safe];
    let mut way = routed(c, [here[0], here[1], safe], &[home])?;
    way.pop();
    if way.is_empty() {
        return Ok(());
    }
    let up = ([here[0], here[1], safe], Pass::Reach);
    let path: Vec<Waypoint> = std::iter::once(up).chain(way).collect();
    fly_through(c, &path, c.max_speed, paused).await
}

pub(crate) async fn rtl(c: &Craft, paused: Paused) -> Result<(), Failure> {
    let Some(here) = c.fix().map(|f| f.pos) else {
        return Err(failed(format!("{} has reported no position yet", c.name)));
    };
    let away = dist([here[0], here[1]], c.home);
    if !c.state().airborne() {
        if away <= 2.0 {
            return Ok(());
        }
        return Err(failed(format!("{} is on the ground away from home: take off first", c.name)));
    }
    detour_home(c, here, paused).await?;
    let here = c.fix().map_or(here, |f| f.pos);
    let away = dist([here[0], here[1]], c.home);
    c.v.seen().expected = Some(Mode::Rtl);
    c.set_level(None);
    c.command(MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH, [0.0; 7]).await?;
    let limit =
        Duration::from_secs_f64(away / c.max_speed.max(1.0) * 2.0 + (here[2] + 20.0) / 0.5 + 60.0);
    c.wait_for(limit, "returning to launch", |c| !c.v.seen().armed).await
}

/// How close to a point of a path, not its last, the drone may come before the next
/// point is sent: 1.5 times its braking distance at `speed` (ArduPilot's position
/// controller starts to slow down that far from a target; the margin covers an autopilot
/// that brakes more gently than the world's `acceleration`), at least the arrival
/// tolerance, at most 25 m. Switching there keeps the drone at speed through the path's
/// corners, as ArduPilot's own waypoint navigation does, instead of stopping at every
/// point; an orbit is cut inside by well under a metre.
pub(crate) fn pass_radius(speed: f64, accel: f64, arrive_xy: f64) -> f64 {
    (1.5 * speed * speed / (2.0 * accel.max(0.1))).clamp(arrive_xy, 25.0)
}

/// How a point of a flight is flown.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Pass {
    /// A point of the call's own path, passed within [`pass_radius`], at speed.
    Cut,
    /// A point of the call's own path, reached within the arrival tolerances before the
    /// next is sent: a sweep's lanes are flown to their ends, as the simulator flies them,
    /// or the turn would cut across the next lane (the pass radius is often longer than
    /// the spacing).
    Reach,
    /// A detour's corner around a no-fly zone: reached too (a drone that cut it would cut
    /// into the zone's margin), and no point of the call's path.
    Corner,
}

/// A point of a flight (local metres; a NaN height keeps the altitude), and how it is
/// flown.
pub(crate) type Waypoint = ([f64; 3], Pass);

/// The waypoints of transits from `from` through `points`: each the planner's way around
/// the no-fly zones (aviary-route), its corners reached, at the height of the point it
/// leads to, and the point itself passed (`Pass::Cut`). Refused with `GeofenceViolation`,
/// as the simulator refuses it, when there is no way.
pub(crate) fn routed(
    c: &Craft,
    from: [f64; 3],
    points: &[[f64; 3]],
) -> Result<Vec<Waypoint>, Failure> {
    let mut out = Vec::new();
    let mut prev = from;
    for &p in points {
        let to = [p[0], p[1], if p[2].is_nan() { c.level() } else { p[2] }];
        let low = if prev[2].is_nan() { to[2] } else { prev[2].min(to[2]) };
        let way = c.airspace.route([prev[0], prev[1]], [to[0], to[1]], low).map_err(|b| {
            Failure::new(BuiltinException::GeofenceViolation, c.airspace.refusal(b, prev, to))
        })?;
        let corners = way.len().saturating_sub(1);
        out.extend(way.into_iter().take(corners).map(|q| ([q[0], q[1], to[2]], Pass::Corner)));
        out.push((p, Pass::Cut));
        prev = to;
    }
    Ok(out)
}

/// A move straight up or down at `here` to height `z`: refused (`GeofenceViolation`) when
/// it would come down into a no-fly zone.
pub(crate) fn vertical(c: &Craft, here: [f64; 3], z: f64) -> Result<(), Failure> {
    match c.airspace.vertical_refusal(here, z) {
        Some(reason) => Err(Failure::new(BuiltinException::GeofenceViolation, reason)),
        None => Ok(()),
    }
}

/// Flies through `path` (local metres), every point before the last passed within
/// [`pass_radius`] (see [`fly_through`]).
pub(crate) async fn fly(
    c: &Craft,
    path: &[[f64; 3]],
    speed: f64,
    paused: Paused,
) -> Result<(), Failure> {
    let path: Vec<Waypoint> = path.iter().map(|&p| (p, Pass::Cut)).collect();
    fly_through(c, &path, speed, paused).await
}

/// Flies through `path`: the last point, and every point to be reached, is reached by
/// position within the tolerances before the next is sent; the others are passed within
/// [`pass_radius`]. On PX4, a path of more than one point is uploaded and flown as a
/// mission instead (`crate::mission`), with the same tolerances. PAUSE holds where the drone is, RESUME sends the target again. The
/// point of the call's own path flown to is noted on the craft by its index among them
/// (`Craft::flying_to`; a detour's corners lead to the point after them): for a `Sweep`
/// or `FollowPath` those points are the contract's path point for point, which is what a
/// remainder is computed from.
pub(crate) async fn fly_through(
    c: &Craft,
    path: &[Waypoint],
    speed: f64,
    mut paused: Paused,
) -> Result<(), Failure> {
    in_air(c)?;
    let points: Vec<[f64; 3]> = path.iter().map(|(p, _)| *p).collect();
    fenced(c, &points)?;
    if c.v.flavour() == crate::mode::Flavour::Px4 && path.len() > 1 {
        // PX4's HOLD stops at every target: a path is its mission (`crate::mission`).
        return crate::mission::fly(c, path, speed, paused).await;
    }
    c.set_mode(Mode::Guided).await?;
    c.speed(speed).await?;
    let pass = pass_radius(speed, c.acceleration, c.tuning.arrive_xy);
    let mut on_path = 0;
    for (i, &(to, how)) in path.iter().enumerate() {
        let last = i + 1 == path.len() || how != Pass::Cut;
        let flying_to = on_path;
        if how != Pass::Corner {
            on_path += 1;
        }
        let from = here(c)?;
        let to = [to[0], to[1], if to[2].is_nan() { c.level() } else { to[2] }];
        if to[2] < 0.0 {
            return Err(failed(format!("altitude {} m is below the ground", to[2])));
        }
        let far = dist([from[0], from[1]], [to[0], to[1]]).hypot(to[2] - from[2]);
        let mut left = Duration::from_secs_f64(far / speed.max(0.5) * 3.0 + 30.0);
        c.set_level(Some(to[2]));
        c.set_flying_to(Some(flying_to));
        c.target(to).await?;
        let mut resend = Instant::now() + c.tuning.resend;
        loop {
            let fix = here(c)?;
            let off = dist([fix[0], fix[1]], [to[0], to[1]]);
            let arrived = off <= c.tuning.arrive_xy && (fix[2] - to[2]).abs() <= c.tuning.arrive_z;
            if arrived || (!last && off.hypot(fix[2] - to[2]) <= pass) {
                break;
            }
            c.refused()?;
            if *paused.borrow() {
                held(c, &mut paused).await?;
                c.target(to).await?;
            }
            if Instant::now() >= resend {
                // A lost UDP datagram must not leave the drone without its target.
                c.target(to).await?;
                resend = Instant::now() + c.tuning.resend;
            }
            if left.is_zero() {
                return Err(late(c, "reach", to));
            }
            aviary_clock::sleep(c.tuning.poll).await;
            left = left.saturating_sub(c.tuning.poll);
        }
    }
    Ok(())
}

/// `Timeout`: the drone did not `what` (reach, fly its path to) `to` in its time.
pub(crate) fn late(c: &Craft, what: &str, to: [f64; 3]) -> Failure {
    timeout(format!(
        "{} did not {what} ({}, {}, {}) in time",
        c.name,
        fixed(to[0], 1),
        fixed(to[1], 1),
        fixed(to[2], 1)
    ))
}

/// A PAUSE: holds where the drone is until RESUME.
pub(crate) async fn held(c: &Craft, paused: &mut Paused) -> Result<(), Failure> {
    c.hold().await;
    while *paused.borrow() {
        if paused.changed().await.is_err() {
            return Err(failed("the call was dropped"));
        }
    }
    Ok(())
}

/// The world's geofence and ceiling hold for MAVLink drones too: a path that leaves them
/// is refused before anything is sent (`GeofenceViolation`).
pub(crate) fn fenced(c: &Craft, path: &[[f64; 3]]) -> Result<(), Failure> {
    let violation = |reason: String| Failure::new(BuiltinException::GeofenceViolation, reason);
    for p in path {
        if let Some(max) = c.max_altitude.filter(|m| p[2] > m + 1e-9) {
            return Err(violation(format!(
                "altitude {} m is above the site's max_altitude of {} m",
                fixed(p[2], 1),
                fixed(max, 1)
            )));
        }
        if let Some(fence) = c.fence.as_deref().filter(|f| !contains(f, [p[0], p[1]])) {
            let _ = fence;
            return Err(violation(format!(
                "({}, {}) is outside the geofence",
                fixed(p[0], 1),
                fixed(p[1], 1)
            )));
        }
    }
    Ok(())
}

pub(crate) async fn hover(duration: f64, paused: Paused) -> Result<(), Failure> {
    if duration < 0.0 || !duration.is_finite() {
        return Err(failed(format!("a hover cannot last {duration} s")));
    }
    let step = Duration::from_millis(50);
    let mut left = Duration::from_secs_f64(duration);
    while !left.is_zero() {
        aviary_clock::sleep(step.min(left)).await;
        if !*paused.borrow() {
            left = left.saturating_sub(step);
        }
    }
    Ok(())
}

/// Points on the circle, clockwise from the one nearest the drone, at its altitude. A
/// drone at the center (within `at_center`, the arrival tolerance: which way it is off
/// is noise) starts east of it, as the simulator's does.
pub(crate) fn orbit(
    here: [f64; 3],
    center: [f64; 2],
    radius: f64,
    laps: f64,
    at_center: f64,
) -> Vec<[f64; 3]> {
    let (dx, dy) = (here[0] - center[0], here[1] - center[1]);
    let start = if dx.hypot(dy) <= at_center { 0.0 } else { dy.atan2(dx) };
    let n = (laps * ORBIT_POINTS as f64).ceil() as usize;
    let step = laps * std::f64::consts::TAU / n as f64;
    (0..=n)
        .map(|i| {
            let a = start - step * i as f64;
            [center[0] + radius * a.cos(), center[1] + radius * a.sin(), here[2]]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::{orbit, pass_radius};

    #[test]
    fn points_are_passed_at_the_braking_distance_within_bounds() {
        // 10 m/s at 3 m/s²: 16.7 m to brake, 25 m with the margin (the cap).
        assert_eq!(pass_radius(10.0, 3.0, 1.0), 25.0);
        assert!((pass_radius(5.0, 3.0, 1.0) - 6.25).abs() < 1e-9);
        // Slow: never closer than the arrival tolerance; no acceleration: no division by 0.
        assert_eq!(pass_radius(0.5, 3.0, 1.0), 1.0);
        assert_eq!(pass_radius(10.0, 0.0, 1.0), 25.0);
        let mut last = 0.0;
        for v in 0..40 {
            let r = pass_radius(f64::from(v) * 0.5, 3.0, 1.0);
            assert!(r >= last && (1.0..=25.0).contains(&r));
            last = r;
        }
    }

    #[test]
    fn an_orbit_ends_where_it_began_after_whole_laps() {
        let path = orbit([120.0, 0.0, 10.0], [100.0, 0.0], 20.0, 2.0, 1.0);
        assert_eq!(path.len(), 49);
        let (a, b) = (path[0], path[48]);
        assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
        assert!(path
            .iter()
            .all(|p| ((p[0] - 100.0).hypot(p[1]) - 20.0).abs() < 1e-9 && p[2] == 10.0));
    }
}
