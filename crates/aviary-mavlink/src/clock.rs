//! The vehicles' own clocks, which a live run's time follows (`aviary_sim::Pace`): each
//! vehicle's `time_boot_ms` as GLOBAL_POSITION_INT carries it, reckoned on between
//! reports at the rate it has been running (a SITL at `--speedup 5` runs five seconds of
//! its own per second of the wall's).
//!
//! Several vehicles: the mission's time moves by the least any of them moved, so that it
//! never runs ahead of the slowest vehicle still heard. A vehicle silent for
//! [`SILENT`] no longer holds it back (a lost vehicle must not stop the clock that its
//! link timeout runs on); with none heard, the wall clock stands in. A clock that goes
//! back by more than a second is a restarted vehicle: it counts again from its next report.

use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::vehicle::Vehicle;

/// A vehicle not heard for this long (wall time) no longer sets the pace.
pub const SILENT: Duration = Duration::from_secs(1);

/// How far past its last report (wall time) a vehicle's clock is reckoned on.
const REACH: Duration = Duration::from_millis(300);

/// A vehicle's clock as last reported.
#[derive(Clone, Copy, Debug)]
pub struct Heard {
    /// Its `time_boot_ms`, in seconds.
    boot: f64,
    /// When the report came (wall clock).
    wall: Instant,
    /// Its seconds per second of the wall's, smoothed over its reports.
    rate: f64,
}

impl Heard {
    /// The clock after a report of `boot_ms` at `wall`.
    pub fn take(before: Option<Heard>, boot_ms: u32, wall: Instant) -> Heard {
        let boot = f64::from(boot_ms) / 1000.0;
        let rate = match before {
            Some(b) => {
                let dt = (wall - b.wall).as_secs_f64();
                let moved = boot - b.boot;
                if dt >= 0.01 && moved > 0.0 {
                    (0.8 * b.rate + 0.2 * moved / dt).clamp(0.05, 100.0)
                } else {
                    b.rate
                }
            }
            None => 1.0,
        };
        Heard { boot, wall, rate }
    }

    /// Its time at `now` (wall clock), or `None` when it has been silent too long.
    fn at(&self, now: Instant) -> Option<f64> {
        let since = now.saturating_duration_since(self.wall);
        (since <= SILENT).then(|| self.boot + since.min(REACH).as_secs_f64() * self.rate)
    }
}

/// The vehicles of a run, as one clock.
pub struct Clocks {
    vehicles: Vec<Arc<Vehicle>>,
    /// Each vehicle's time when last asked.
    last: Vec<Option<f64>>,
}

impl Clocks {
    pub(crate) fn new(vehicles: Vec<Arc<Vehicle>>) -> Clocks {
        let last = vec![None; vehicles.len()];
        Clocks { vehicles, last }
    }

    /// Seconds the slowest vehicle heard has moved on since the last call; `None` when no
    /// vehicle was heard in both (the first call, or all silent).
    pub fn moved(&mut self) -> Option<f64> {
        let now = Instant::now();
        let times = self.vehicles.iter().map(|v| v.seen().clock.and_then(|h| h.at(now)));
        step(&mut self.last, times)
    }
}

/// One look at every clock (`times`, `None` for a silent one) after `last`.
fn step(last: &mut [Option<f64>], times: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let mut least: Option<f64> = None;
    for (last, time) in last.iter_mut().zip(times) {
        match (*last, time) {
            (Some(l), Some(t)) if t + 1.0 >= l => {
                let moved = (t - l).max(0.0);
                least = Some(least.map_or(moved, |m| m.min(moved)));
                *last = Some(l.max(t));
            }
            // New, back after silence, or restarted: counts from the next look.
            (_, t) => *last = t,
        }
    }
    least
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slowest_vehicle_heard_sets_the_pace() {
        let mut last = vec![None, None];
        assert_eq!(step(&mut last, [Some(10.0), Some(3.0)].into_iter()), None);
        // One at 5x, one at 1x: the mission moves as the slower.
        assert_eq!(step(&mut last, [Some(15.0), Some(4.0)].into_iter()), Some(1.0));
        // The slow one falls silent: the fast one alone.
        assert_eq!(step(&mut last, [Some(20.0), None].into_iter()), Some(5.0));
        // It comes back: counted from the look after.
        assert_eq!(step(&mut last, [Some(25.0), Some(9.0)].into_iter()), Some(5.0));
        assert_eq!(step(&mut last, [Some(30.0), Some(10.0)].into_iter()), Some(1.0));
        // All silent: nothing to say (the wall stands in).
        assert_eq!(step(&mut last, [None, None].into_iter()), None);
    }

    #[test]
    fn a_clock_that_goes_back_moves_nothing_and_a_restart_counts_again() {
        let mut last = vec![None];
        step(&mut last, [Some(100.0)].into_iter());
        // A late report under the reckoning: no time twice, none backwards.
        assert_eq!(step(&mut last, [Some(99.5)].into_iter()), Some(0.0));
        assert_eq!(step(&mut last, [Some(100.5)].into_iter()), Some(0.5));
        // Restarted (its boot clock from 0): counts from the next look.
        assert_eq!(step(&mut last, [Some(2.0)].into_iter()), None);
        assert_eq!(step(&mut last, [Some(3.0)].into_iter()), Some(1.0));
    }

    #[test]
    fn a_clock_is_reckoned_at_its_rate_a_little_past_its_report() {
        let t0 = Instant::now();
        let mut h = Heard::take(None, 1_000, t0);
        for k in 1..=50 {
            // Five seconds of its own per second of the wall's, every 20 ms.
            h = Heard::take(
                Some(h),
                1_000 + k * 100,
                t0 + Duration::from_millis(20 * u64::from(k)),
            );
        }
        assert!((h.rate - 5.0).abs() < 0.05, "{}", h.rate);
        let at = |ms| h.at(h.wall + Duration::from_millis(ms)).unwrap();
        assert!((at(100) - (h.boot + 0.5)).abs() < 0.01);
        // No farther than REACH past the report, and nothing once silent.
        assert!((at(800) - (h.boot + 0.3 * h.rate)).abs() < 1e-9);
        assert_eq!(h.at(h.wall + Duration::from_millis(1500)), None);
    }
}
