//! What PX4 flies in its own modes where ArduCopter is given points one by one: an orbit
//! is PX4's ORBIT mode (MAV_CMD_DO_ORBIT), which circles at a steady speed, where a
//! string of repositions would brake at each point (PX4's HOLD stops at its target).
//!
//! PX4 circles until told otherwise, so the laps are counted here, from the positions the
//! vehicle reports: the angle it has turned about the center, unwrapped, until the laps
//! asked for are done; then HOLD, where it brakes and stays.

use std::f64::consts::TAU;
use std::time::Duration;

use aviary_api::show::fixed;
use aviary_api::Failure;
use aviary_clock::Instant;
use mavlink::dialects::ardupilotmega::{MavCmd, MavFrame};

use crate::drone::{failed, timeout, Craft, Paused};
use crate::mode::Mode;
use crate::motion::here;

/// DO_ORBIT's param3: the nose points at the center, as the simulator's drones look in.
const YAW_TO_CENTER: f32 = 0.0;

/// Circles `center` at `radius` (m) and height `z` (above home) `laps` times, clockwise
/// (as the simulator and the ArduPilot path fly it), at `speed`, from where the drone is
/// (on the circle: the caller flies it there first). PAUSE holds; RESUME circles on and
/// counts on.
pub(crate) async fn orbit(
    c: &Craft,
    center: [f64; 2],
    radius: f64,
    z: f64,
    laps: f64,
    speed: f64,
    mut paused: Paused,
) -> Result<(), Failure> {
    let goal = laps * TAU;
    let mut turned = Turned::from(center, here(c)?);
    let mut left = Duration::from_secs_f64(goal * radius / speed.max(0.5) * 3.0 + 30.0);
    circle(c, center, radius, z, speed).await?;
    loop {
        if turned.to(here(c)?) >= goal {
            break;
        }
        c.refused()?;
        if *paused.borrow() {
            crate::motion::held(c, &mut paused).await?;
            turned = Turned { from: here(c)?, ..turned };
            circle(c, center, radius, z, speed).await?;
        }
        if left.is_zero() {
            return Err(timeout(format!(
                "{} did not finish {} laps around ({}, {}) in time ({} done)",
                c.name,
                fixed(laps, 2),
                fixed(center[0], 1),
                fixed(center[1], 1),
                fixed(turned.angle / TAU, 2)
            )));
        }
        let started = Instant::now();
        aviary_clock::sleep(c.tuning.poll).await;
        left = left.saturating_sub(started.elapsed());
    }
    // Done: HOLD, where PX4 brakes and stays.
    c.set_mode(Mode::Guided).await
}

/// DO_ORBIT: PX4 switches to ORBIT and circles for as long as it is left there. Positive
/// radius is clockwise; the altitude is above sea level (as all of PX4's).
async fn circle(
    c: &Craft,
    center: [f64; 2],
    radius: f64,
    z: f64,
    speed: f64,
) -> Result<(), Failure> {
    let Some(home) = c.fix().map(|f| f.home_amsl) else {
        return Err(failed(format!("{} has reported no position yet", c.name)));
    };
    let (lat, lon) = c.v.origin().to_e7(center[0], center[1]);
    c.set_targeted();
    c.command_int(
        MavCmd::MAV_CMD_DO_ORBIT,
        MavFrame::MAV_FRAME_GLOBAL,
        [radius as f32, speed as f32, YAW_TO_CENTER, 0.0],
        (lat, lon, (home + z) as f32),
    )
    .await
}

/// Whether PX4's words refuse a target it has acknowledged: its navigator's "Reposition
/// is outside geofence", "Orbit is outside geofence", "Altitude change is outside
/// geofence" (`navigator_main.cpp`), said instead of flying there.
pub(crate) fn refuses(words: &str) -> bool {
    words.to_ascii_lowercase().contains("is outside geofence")
}

/// The angle (radians) a drone has turned clockwise about a center, from the positions it
/// reports one after another.
#[derive(Clone, Copy, Debug)]
struct Turned {
    center: [f64; 2],
    /// The position last seen.
    from: [f64; 3],
    angle: f64,
}

impl Turned {
    fn from(center: [f64; 2], here: [f64; 3]) -> Turned {
        Turned { center, from: here, angle: 0.0 }
    }

    /// Takes in the next position; the angle turned so far. Clockwise is a falling
    /// bearing from the center; each step is wrapped into (-π, π], so a step back (a gust,
    /// noise) counts back, and crossing west of the center is no jump.
    fn to(&mut self, here: [f64; 3]) -> f64 {
        let bearing = |p: [f64; 3]| (p[1] - self.center[1]).atan2(p[0] - self.center[0]);
        let mut step = bearing(self.from) - bearing(here);
        step -= TAU * (step / TAU).round();
        self.angle += step;
        self.from = here;
        self.angle
    }
}

#[cfg(test)]
mod tests {
    use super::Turned;
    use std::f64::consts::{PI, TAU};

    fn at(center: [f64; 2], r: f64, a: f64) -> [f64; 3] {
        [center[0] + r * a.cos(), center[1] + r * a.sin(), 10.0]
    }

    #[test]
    fn the_navigators_refusals_are_told_from_other_words() {
        for said in [
            "Reposition is outside geofence",
            "Orbit is outside geofence",
            "Altitude change is outside geofence",
        ] {
            assert!(super::refuses(said), "{said}");
        }
        for said in
            ["Geofence violation: exceeding maximum distance to Home", "Takeoff detected", ""]
        {
            assert!(!super::refuses(said), "{said}");
        }
    }

    #[test]
    fn laps_are_counted_clockwise_across_the_west_of_the_center() {
        let c = [100.0, -50.0];
        // Two laps clockwise from the north, in 10-degree steps: 72 steps.
        let start = PI / 2.0;
        let mut t = Turned::from(c, at(c, 30.0, start));
        let mut last = 0.0;
        for k in 1..=72 {
            last = t.to(at(c, 30.0, start - f64::from(k) * TAU / 36.0));
        }
        assert!((last - 2.0 * TAU).abs() < 1e-9, "{last}");
    }

    #[test]
    fn a_step_back_counts_back_and_counterclockwise_is_negative() {
        let c = [0.0, 0.0];
        let mut t = Turned::from(c, at(c, 20.0, 0.0));
        t.to(at(c, 20.0, -0.5));
        let back = t.to(at(c, 20.0, -0.3));
        assert!((back - 0.3).abs() < 1e-9, "{back}");
        let mut ccw = Turned::from(c, at(c, 20.0, 3.0));
        let a = ccw.to(at(c, 20.0, -3.0));
        assert!((a + (TAU - 6.0)).abs() < 1e-9, "{a}");
    }
}
