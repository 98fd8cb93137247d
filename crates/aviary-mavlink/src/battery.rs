//! The battery rule's numbers for a MAVLink drone (docs/WORLD.md's rule, on the vehicle's
//! own figures): how much of a full battery the way home takes, and the current the
//! vehicle measures in flight.
//!
//! The time home is [`aviary_api::flight::time_home`], the one rule the simulator and the
//! plan use too. Its share of the battery comes from the draw: the average current the
//! vehicle reported over the last [`WINDOW`] once it has been in the air for [`SETTLED`]
//! (a take-off's climb draws more than cruise, and a hover less), against the battery's
//! capacity. Before that, the world's `flight_current`; without a capacity, the endurance.

use std::collections::VecDeque;
use std::time::Duration;

use aviary_api::flight::{time_home, Descent};
use aviary_clock::Instant;

/// The measured draw averages this much of the latest flight.
pub const WINDOW: Duration = Duration::from_secs(60);
/// ... once the drone has been in the air this long.
pub const SETTLED: Duration = Duration::from_secs(10);

/// What the rule needs of one drone: the world's figures with the vehicle's applied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Figures {
    /// m/s over the ground on the way home (the world's `return_speed`).
    pub return_speed: f64,
    /// How it comes down at home (ArduCopter: LAND_SPEED_HIGH or WPNAV_SPEED_DN, then
    /// LAND_SPEED under LAND_ALT_LOW).
    pub descent: Descent,
    /// Seconds it waits above home before it lands (RTL_LOIT_TIME).
    pub loiter: f64,
    /// Seconds of flight on a full battery.
    pub endurance: f64,
    /// mAh (BATT_CAPACITY, or the world's `battery_capacity`).
    pub capacity: Option<f64>,
    /// The world's `flight_current` (A): the draw until one is measured.
    pub flight_current: Option<f64>,
}

impl Figures {
    /// The share of a full battery (0..1) that flying home from `ground` metres away at
    /// `height` takes, with `measured` the average current in flight (A), if known.
    pub fn need(&self, ground: f64, height: f64, measured: Option<f64>) -> f64 {
        let time =
            time_home(ground, self.return_speed, height.max(0.0), self.loiter, &self.descent);
        match (self.capacity, measured.or(self.flight_current)) {
            // mAh × 3.6 = ampere-seconds.
            (Some(mah), Some(amps)) if mah > 0.0 && amps > 0.0 => time * amps / (mah * 3.6),
            _ => time / self.endurance,
        }
    }
}

/// The thresholds of docs/WORLD.md's rule: `BatteryLow` under `2 × need + 10 %`, `BatteryCritical` under
/// `need + 10 %` (charge and need as fractions of a full battery).
pub fn alarms(charge: f64, need: f64) -> (bool, bool) {
    (charge < 2.0 * need + 0.10, charge < need + 0.10)
}

/// The current a vehicle reported while in the air, newest last.
#[derive(Debug, Default)]
pub struct Draw {
    samples: VecDeque<(Instant, f64)>,
    airborne_since: Option<Instant>,
}

impl Draw {
    /// Takes one report: `amps` (None: the vehicle does not measure it) at `now`, while
    /// the vehicle is (or is not) in the air. On the ground the record starts over: the
    /// next flight is measured on its own.
    pub fn record(&mut self, now: Instant, amps: Option<f64>, airborne: bool) {
        if !airborne {
            self.airborne_since = None;
            self.samples.clear();
            return;
        }
        self.airborne_since.get_or_insert(now);
        if let Some(a) = amps.filter(|a| a.is_finite() && *a >= 0.0) {
            self.samples.push_back((now, a));
        }
        while self.samples.front().is_some_and(|(t, _)| now.saturating_duration_since(*t) > WINDOW)
        {
            self.samples.pop_front();
        }
    }

    /// The average current (A) over the last [`WINDOW`], once the drone has been in the
    /// air for [`SETTLED`]; `None` before, or when the vehicle reports no current.
    pub fn average(&self, now: Instant) -> Option<f64> {
        let since = self.airborne_since?;
        if now.saturating_duration_since(since) < SETTLED {
            return None;
        }
        let recent: Vec<f64> = self
            .samples
            .iter()
            .filter(|(t, _)| now.saturating_duration_since(*t) <= WINDOW)
            .map(|(_, a)| *a)
            .collect();
        (!recent.is_empty()).then(|| recent.iter().sum::<f64>() / recent.len() as f64)
    }
}

/// A current as SYS_STATUS and BATTERY_STATUS carry it: centiamperes, -1 for "not
/// measured".
pub fn amps(centiamps: i16) -> Option<f64> {
    (centiamps >= 0).then(|| f64::from(centiamps) / 100.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SITL's copter with ArduCopter's defaults: 10 m/s home, 1.5 m/s down, 0.5 m/s under
    /// 10 m, 5 s above home, 3300 mAh.
    fn sitl() -> Figures {
        Figures {
            return_speed: 10.0,
            descent: Descent { rate: 1.5, land_speed: 0.5, slow_below: 10.0 },
            loiter: 5.0,
            endurance: 1800.0,
            capacity: Some(3300.0),
            flight_current: None,
        }
    }

    #[test]
    fn the_way_home_costs_its_time_at_the_measured_draw() {
        // 300 m away at 25 m: 30 s + 5 s + (15 m / 1.5 + 10 m / 0.5) = 65 s. At 30 A on
        // 3300 mAh (11 880 As): 1950 As, 16.4 % of the battery.
        let need = sitl().need(300.0, 25.0, Some(30.0));
        assert!((need - 65.0 * 30.0 / 11_880.0).abs() < 1e-12, "{need}");
        // Without a measured draw or the world's, the endurance: 65 s of 1800 s.
        assert!((sitl().need(300.0, 25.0, None) - 65.0 / 1800.0).abs() < 1e-12);
        // The world's flight_current stands in until a draw is measured ...
        let world = Figures { flight_current: Some(20.0), ..sitl() };
        assert!((world.need(300.0, 25.0, None) - 65.0 * 20.0 / 11_880.0).abs() < 1e-12);
        // ... and the measured one replaces it.
        assert!((world.need(300.0, 25.0, Some(30.0)) - need).abs() < 1e-12);
        // No capacity: a draw says nothing about the share; the endurance does.
        let unknown = Figures { capacity: None, ..sitl() };
        assert!((unknown.need(300.0, 25.0, Some(30.0)) - 65.0 / 1800.0).abs() < 1e-12);
    }

    #[test]
    fn the_alarms_follow_the_need() {
        // 16.4 % needed: low under 42.8 %, critical under 26.4 %.
        let need = sitl().need(300.0, 25.0, Some(30.0));
        assert_eq!(alarms(0.50, need), (false, false));
        assert_eq!(alarms(0.40, need), (true, false));
        assert_eq!(alarms(0.25, need), (true, true));
    }

    #[test]
    fn the_draw_is_averaged_over_the_last_minute_once_settled() {
        let t0 = Instant::now();
        let at = |s: u64| t0 + Duration::from_secs(s);
        let mut draw = Draw::default();
        draw.record(at(0), Some(5.0), false);
        assert_eq!(draw.average(at(0)), None, "on the ground");
        // The take-off draws 45 A for 5 s, then cruise 30 A.
        for s in 1..=5 {
            draw.record(at(s), Some(45.0), true);
        }
        assert_eq!(draw.average(at(5)), None, "not settled after 4 s in the air");
        for s in 6..=11 {
            draw.record(at(s), Some(30.0), true);
        }
        let early = draw.average(at(11)).expect("settled after 10 s");
        assert!((early - (5.0 * 45.0 + 6.0 * 30.0) / 11.0).abs() < 1e-9, "{early}");
        // A minute later the take-off has left the window.
        for s in 12..=80 {
            draw.record(at(s), Some(30.0), true);
        }
        assert!((draw.average(at(80)).unwrap() - 30.0).abs() < 1e-9);
        // Landed: the next flight starts its own record.
        draw.record(at(81), Some(1.0), false);
        draw.record(at(82), Some(30.0), true);
        assert_eq!(draw.average(at(85)), None);
    }

    #[test]
    fn a_vehicle_that_measures_no_current_has_no_draw() {
        let t0 = Instant::now();
        let mut draw = Draw::default();
        for s in 0..30 {
            draw.record(t0 + Duration::from_secs(s), amps(-1), true);
        }
        assert_eq!(draw.average(t0 + Duration::from_secs(30)), None);
        assert_eq!(amps(3012), Some(30.12));
    }
}
