//! How a drone comes home and down: one rule for the simulator, the plan and the MAVLink
//! backend's battery alarms, with the world's figures or a vehicle's own. And the other
//! figures of the middle layer that every backend and the plan must share.

/// Seconds `LoadPayload` takes: the crew's time to hook the payload on (the simulator
/// waits it, the MAVLink backend waits it after closing the gripper, the plan counts it).
pub const LOAD_TIME: f64 = 2.0;
/// `LoadPayload` needs the drone landed or below this height (metres).
pub const LOAD_MAX_ALTITUDE: f64 = 5.0;

/// The height a `ReturnToLaunch` from `height` flies home at: the drone's
/// `return_altitude`, kept under the geofence's `ceiling`, and never lower than where it
/// is (an autopilot's RTL climbs, it does not descend, before going home).
pub fn return_height(height: f64, return_altitude: f64, ceiling: Option<f64>) -> f64 {
    height.max(return_altitude.min(ceiling.unwrap_or(f64::INFINITY)))
}

/// How a drone lands: at `rate` down, and at `land_speed` in the last `slow_below` metres
/// (autopilots touch down slowly: ArduCopter's LAND_SPEED under LAND_ALT_LOW).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Descent {
    pub rate: f64,
    pub land_speed: f64,
    pub slow_below: f64,
}

impl Descent {
    /// Whether a landing from `height` has a slow last part of its own.
    pub fn slows(&self, height: f64) -> bool {
        self.land_speed < self.rate && height > 0.0
    }

    /// Seconds to come down `height` metres to the ground at full speed (the battery
    /// rule's figure: no acceleration).
    pub fn landing_time(&self, height: f64) -> f64 {
        let height = height.max(0.0);
        if !self.slows(height) {
            return height / self.rate;
        }
        let slow = height.min(self.slow_below);
        (height - slow) / self.rate + slow / self.land_speed
    }
}

/// The battery rule's time home: `ground` metres at `max_speed`, the wait above home,
/// and the landing from `height`.
pub fn time_home(ground: f64, max_speed: f64, height: f64, loiter: f64, descent: &Descent) -> f64 {
    ground / max_speed + loiter + descent.landing_time(height)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_landing_at_one_speed_is_height_over_rate() {
        let d = Descent { rate: 3.0, land_speed: 3.0, slow_below: 10.0 };
        assert_eq!(d.landing_time(20.0), 20.0 / 3.0);
        assert!(!d.slows(20.0));
    }

    #[test]
    fn the_last_metres_are_flown_at_the_landing_speed() {
        // ArduCopter's defaults: 1.5 m/s down, 0.5 m/s under 10 m.
        let d = Descent { rate: 1.5, land_speed: 0.5, slow_below: 10.0 };
        assert!((d.landing_time(25.0) - (15.0 / 1.5 + 10.0 / 0.5)).abs() < 1e-12);
        assert!((d.landing_time(4.0) - 8.0).abs() < 1e-12);
        assert!((time_home(100.0, 10.0, 25.0, 5.0, &d) - 45.0).abs() < 1e-12);
    }

    proptest::proptest! {
        /// Higher never lands sooner, and never sooner than at the descent rate.
        #[test]
        fn higher_takes_longer(h in 0.0f64..500.0, more in 0.0f64..100.0, rate in 0.1f64..10.0, slow in 0.1f64..10.0, below in 0.0f64..50.0) {
            let d = Descent { rate, land_speed: slow, slow_below: below };
            proptest::prop_assert!(d.landing_time(h + more) + 1e-9 >= d.landing_time(h));
            proptest::prop_assert!(d.landing_time(h) + 1e-9 >= h / rate.max(slow));
        }
    }
}

/// The fastest a drone of airspeed `airspeed` can go over the ground along the unit
/// direction `u` in the wind `w` (`[east, north]` m/s, where it blows to): the wind
/// triangle, `w·u + sqrt(airspeed² − (w×u)²)`, at least 0. The simulator flies by it and
/// the plan costs by it.
pub fn ground_speed_limit(u: [f64; 2], w: [f64; 2], airspeed: f64) -> f64 {
    let along = w[0] * u[0] + w[1] * u[1];
    let across = w[0] * u[1] - w[1] * u[0];
    let room = airspeed * airspeed - across * across;
    if room <= 0.0 {
        return 0.0;
    }
    (along + room.sqrt()).max(0.0)
}

/// How much faster than in still air a drone drains flying at `ground` (m/s over the
/// ground, `[east, north]`) in the wind `w`: power grows with airspeed as
/// `P(v) = P0 (1 + drain (v / max_speed)²)`, and still air's drain is that of the
/// ground speed (so `endurance` stays the figure of still air):
/// `P(|ground − w|) / P(|ground|)`.
pub fn wind_drain(ground: [f64; 2], w: [f64; 2], max_speed: f64, drain: f64) -> f64 {
    let air = (ground[0] - w[0]).hypot(ground[1] - w[1]) / max_speed;
    let over = ground[0].hypot(ground[1]) / max_speed;
    (1.0 + drain * air * air) / (1.0 + drain * over * over)
}

#[cfg(test)]
mod wind_tests {
    use super::{ground_speed_limit, wind_drain};

    #[test]
    fn the_wind_triangle_along_against_and_across() {
        assert!((ground_speed_limit([1.0, 0.0], [-4.0, 0.0], 10.0) - 6.0).abs() < 1e-12);
        assert!((ground_speed_limit([1.0, 0.0], [4.0, 0.0], 10.0) - 14.0).abs() < 1e-12);
        assert!((ground_speed_limit([1.0, 0.0], [0.0, 6.0], 10.0) - 8.0).abs() < 1e-12);
        assert_eq!(ground_speed_limit([1.0, 0.0], [0.0, 12.0], 10.0), 0.0);
    }

    #[test]
    fn still_air_drains_as_still_air_and_a_head_wind_more() {
        assert!((wind_drain([5.0, 0.0], [0.0, 0.0], 10.0, 0.5) - 1.0).abs() < 1e-12);
        // 5 m/s over the ground into 5 m/s: 10 m/s through the air.
        let head = wind_drain([5.0, 0.0], [-5.0, 0.0], 10.0, 0.5);
        assert!((head - 1.5 / 1.125).abs() < 1e-12, "{head}");
        assert_eq!(wind_drain([5.0, 0.0], [-5.0, 0.0], 10.0, 0.0), 1.0);
    }
}
