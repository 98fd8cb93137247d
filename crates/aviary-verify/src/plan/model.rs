//! What a drone's flight costs: the same kinematic model the built-in simulator flies
//! (each leg a trapezoidal speed profile, horizontal and vertical at once; orbits at the
//! speed a centripetal limit allows; sweeps along the middle layer's lawnmower path),
//! in closed form instead of ticks.

use aviary_api::flight::Descent;
use aviary_api::geometry::dist_to_segment;
use aviary_route::Airspace;
use aviary_world::Drone;

/// A drone as the estimate follows it.
#[derive(Clone, Debug)]
pub struct Flyer {
    pub pos: [f64; 3],
    pub home: [f64; 3],
    pub max_speed: f64,
    pub climb_rate: f64,
    pub descent: Descent,
    pub return_altitude: f64,
    pub return_loiter: f64,
    /// `TakeOff`'s climb from the ground.
    pub takeoff_speed: f64,
    /// `ReturnToLaunch`'s speed over the ground.
    pub return_speed: f64,
    pub accel: f64,
    pub endurance: f64,
    pub battery_start: f64,
    /// Shared: a drone's copy is taken at every undecidable `IF` and unfired handler.
    pub sensors: std::rc::Rc<[String]>,
    pub airborne: bool,
    /// When the drone last took off, while it is in the air.
    pub since: f64,
    pub flight_time: f64,
    pub distance: f64,
    /// When its motion is next free: a statement that claims it starts no earlier.
    pub free_at: f64,
    /// Its fastest through the air, and the world's mean wind (`[east, north]` m/s) with
    /// its drain figure, if it has one: legs go at what the wind triangle leaves.
    pub max_airspeed: f64,
    pub wind: Option<([f64; 2], f64)>,
    /// Seconds of still-air flight the wind has cost the battery beyond the time flown.
    pub wind_drain: f64,
    /// Kinds being detected, with the sensor range, and the targets already found.
    pub detecting: Vec<(String, f64, Vec<usize>)>,
}

impl Flyer {
    pub fn new(d: &Drone, wind: Option<&aviary_world::Wind>) -> Flyer {
        Flyer {
            pos: d.home,
            home: d.home,
            max_speed: d.max_speed,
            climb_rate: d.climb_rate,
            descent: d.descent(),
            return_altitude: d.return_altitude,
            return_loiter: d.return_loiter,
            takeoff_speed: d.takeoff_speed,
            return_speed: d.return_speed,
            accel: d.acceleration,
            endurance: d.endurance,
            battery_start: d.battery / 100.0,
            sensors: d.sensors.iter().cloned().collect(),
            airborne: false,
            since: 0.0,
            flight_time: 0.0,
            distance: 0.0,
            free_at: 0.0,
            max_airspeed: d.max_airspeed,
            wind: wind.map(|w| (w.velocity(), w.drain)),
            wind_drain: 0.0,
            detecting: Vec::new(),
        }
    }

    /// Battery left at time `t`, as a fraction.
    pub fn battery_at(&self, t: f64) -> f64 {
        let air = self.flight_time
            + self.wind_drain
            + if self.airborne { (t - self.since).max(0.0) } else { 0.0 };
        self.battery_start - air / self.endurance
    }

    pub fn take_off(&mut self, t: f64) {
        if !self.airborne {
            self.airborne = true;
            self.since = t;
        }
    }

    pub fn land(&mut self, t: f64) {
        if self.airborne {
            self.airborne = false;
            self.flight_time += (t - self.since).max(0.0);
        }
    }

    /// Flies a straight leg to `to`; returns its duration.
    pub fn leg(&mut self, to: [f64; 3]) -> f64 {
        self.leg_at(to, self.max_speed)
    }

    /// A straight leg at up to `speed` over the ground; in the mean wind, at what the wind
    /// triangle leaves of the drone's airspeed that way (as the simulator flies it, gusts
    /// aside), its battery drained by the airspeed (`aviary_api::flight::wind_drain`).
    pub fn leg_at(&mut self, to: [f64; 3], speed: f64) -> f64 {
        let (dx, dy) = (to[0] - self.pos[0], to[1] - self.pos[1]);
        let h = dx.hypot(dy);
        let v = (to[2] - self.pos[2]).abs();
        self.distance += (h * h + v * v).sqrt();
        let vertical = if to[2] >= self.pos[2] { self.climb_rate } else { self.descent.rate };
        self.pos = to;
        let mut cruise = speed;
        let mut drain = 1.0;
        if let (Some((w, k)), true) = (self.wind, h > 0.0) {
            let u = [dx / h, dy / h];
            cruise = speed.min(aviary_api::flight::ground_speed_limit(u, w, self.max_airspeed));
            let ground = [u[0] * cruise, u[1] * cruise];
            drain = aviary_api::flight::wind_drain(ground, w, self.max_speed, k);
        }
        let across = trapezoid(h, cruise, self.accel);
        self.wind_drain += across * (drain - 1.0);
        across.max(trapezoid(v, vertical, self.accel))
    }

    /// `TakeOff` from the ground: straight up to `alt` at the take-off speed (as the
    /// simulator flies it); the duration.
    pub fn lift_off(&mut self, alt: f64) -> f64 {
        let v = (alt - self.pos[2]).abs();
        self.distance += v;
        self.pos[2] = alt;
        trapezoid(v, self.takeoff_speed, self.accel)
    }

    /// `Land`, and the end of `ReturnToLaunch`: straight down, the last `slow_below`
    /// metres at the landing speed when the drone lands slower than it descends (as the
    /// simulator flies it: two legs).
    pub fn land_here(&mut self) -> f64 {
        let (x, y, z) = (self.pos[0], self.pos[1], self.pos[2]);
        let descent = self.descent;
        if !descent.slows(z) {
            return self.leg([x, y, 0.0]);
        }
        let upper = if z > descent.slow_below { self.leg([x, y, descent.slow_below]) } else { 0.0 };
        let low = self.pos[2];
        self.distance += low;
        self.pos[2] = 0.0;
        upper + trapezoid(low, descent.land_speed, self.accel)
    }

    /// The points a transit from here to `to` flies through, as the simulator flies it:
    /// the planner's way around the no-fly zones, each point at `to`'s height (`[to]` when
    /// nothing is in the way, or when there is no way: the flight is refused then, and
    /// the checker said so).
    pub fn way(&self, space: &Airspace, to: [f64; 3]) -> Vec<[f64; 3]> {
        let from = [self.pos[0], self.pos[1]];
        match space.route(from, [to[0], to[1]], self.pos[2].min(to[2])) {
            Ok(way) => way.into_iter().map(|p| [p[0], p[1], to[2]]).collect(),
            Err(_) => vec![to],
        }
    }

    /// A transit to `to` at up to `speed`: its legs around the zones; the duration.
    pub fn transit(&mut self, space: &Airspace, to: [f64; 3], speed: f64) -> f64 {
        self.way(space, to).into_iter().map(|p| self.leg_at(p, speed)).sum()
    }

    /// `Orbit`: to the nearest point of the circle (a transit), then `laps` turns.
    pub fn orbit(&mut self, space: &Airspace, center: [f64; 2], radius: f64, laps: f64) -> f64 {
        let (dx, dy) = (self.pos[0] - center[0], self.pos[1] - center[1]);
        let angle = if dx == 0.0 && dy == 0.0 { 0.0 } else { dy.atan2(dx) };
        let entry =
            [center[0] + radius * angle.cos(), center[1] + radius * angle.sin(), self.pos[2]];
        let to_circle = self.transit(space, entry, self.max_speed);
        let arc = laps * std::f64::consts::TAU * radius;
        let speed = aviary_api::geometry::orbit_speed(self.max_speed, self.accel, radius);
        self.distance += arc;
        to_circle + trapezoid(arc, speed, self.accel * 0.75f64.sqrt())
    }

    /// `ReturnToLaunch`: up to a safe altitude, home (around the zones), down.
    pub fn return_home(&mut self, space: &Airspace, max_altitude: Option<f64>) -> f64 {
        if !self.airborne {
            return 0.0;
        }
        let safe =
            aviary_api::flight::return_height(self.pos[2], self.return_altitude, max_altitude);
        let up = self.leg([self.pos[0], self.pos[1], safe]);
        let across = self.transit(space, [self.home[0], self.home[1], safe], self.return_speed);
        up + across + self.return_loiter + self.land_here()
    }
}

/// The time of a move of `d` metres from rest to rest: accelerate at `a`, cruise at `v`,
/// brake at `a` (a triangle when `d` is too short to reach `v`).
pub fn trapezoid(d: f64, v: f64, a: f64) -> f64 {
    if d <= 0.0 || v <= 0.0 || a <= 0.0 {
        return 0.0;
    }
    if d >= v * v / a {
        d / v + v / a
    } else {
        2.0 * (d / a).sqrt()
    }
}

/// Where along the ground segment `from`→`to` a target at `p` first comes within `range`,
/// as a fraction of the segment; `None` if it never does.
pub fn first_within(from: [f64; 2], to: [f64; 2], p: [f64; 2], range: f64) -> Option<f64> {
    if dist_to_segment(p, from, to) > range {
        return None;
    }
    let (dx, dy) = (to[0] - from[0], to[1] - from[1]);
    let len2 = dx * dx + dy * dy;
    if len2 == 0.0 {
        return Some(0.0);
    }
    // |from + s·d − p| = range, the smaller root, clamped to the segment.
    let (fx, fy) = (from[0] - p[0], from[1] - p[1]);
    let b = 2.0 * (fx * dx + fy * dy);
    let c = fx * fx + fy * fy - range * range;
    let disc = (b * b - 4.0 * len2 * c).max(0.0);
    Some(((-b - disc.sqrt()) / (2.0 * len2)).clamp(0.0, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_move_cruises_and_a_short_one_never_reaches_full_speed() {
        // 100 m at 10 m/s with 2 m/s²: 10 s cruising plus 5 s lost to speeding up and braking.
        assert!((trapezoid(100.0, 10.0, 2.0) - 15.0).abs() < 1e-9);
        // 25 m: a triangle, 2·sqrt(25/2).
        assert!((trapezoid(25.0, 10.0, 2.0) - 2.0 * 12.5f64.sqrt()).abs() < 1e-9);
        assert_eq!(trapezoid(0.0, 10.0, 2.0), 0.0);
    }

    proptest::proptest! {
        /// A move never beats cruising the whole way, and a longer one never takes less time.
        #[test]
        fn a_move_takes_at_least_cruising_time_and_grows_with_distance(d in 0.0f64..5000.0, extra in 0.0f64..500.0, v in 0.5f64..30.0, a in 0.5f64..10.0) {
            let t = trapezoid(d, v, a);
            proptest::prop_assert!(t + 1e-9 >= d / v);
            proptest::prop_assert!(trapezoid(d + extra, v, a) + 1e-9 >= t);
        }

        /// Where a target first comes within range is a point of the segment within range.
        #[test]
        fn the_first_point_within_range_is_within_range(fx in -100.0f64..100.0, tx in -100.0f64..100.0, px in -100.0f64..100.0, py in -50.0f64..50.0, r in 1.0f64..60.0) {
            if let Some(s) = first_within([fx, 0.0], [tx, 0.0], [px, py], r) {
                let x = fx + s * (tx - fx);
                proptest::prop_assert!(((x - px).powi(2) + py * py).sqrt() <= r + 1e-6);
            }
        }
    }

    #[test]
    fn a_target_is_met_where_the_path_enters_its_range() {
        let s = first_within([0.0, 0.0], [100.0, 0.0], [50.0, 0.0], 10.0);
        assert_eq!(s, Some(0.4));
        assert_eq!(first_within([0.0, 0.0], [100.0, 0.0], [50.0, 30.0], 10.0), None);
        assert_eq!(first_within([0.0, 0.0], [100.0, 0.0], [0.0, 5.0], 10.0), Some(0.0));
    }
}
