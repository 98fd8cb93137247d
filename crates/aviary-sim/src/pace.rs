//! What a live run's time follows. A run with MAVLink drones runs on the virtual clock of
//! `aviary_clock` too, so that one clock serves the engine, the simulated drones and the
//! MAVLink backend's waits; its runtime is paced by a [`Pace`] (an
//! `aviary_clock::Reference`), which lets the clock run up to [`Pace::now`]: the wall
//! clock at first (while the vehicles connect), then, once [`Pace::follow`] names one, the
//! vehicles' own clocks, so that a SITL running five times faster than real time has a
//! mission five times faster too.

use parking_lot::Mutex;
use std::time::{Duration, Instant};

/// Seconds a clock has moved on since it was last asked, or `None` when it cannot say
/// (no vehicle heard lately): then the wall clock's are taken.
pub type Source = Box<dyn FnMut() -> Option<f64> + Send>;

/// The reference a live run's time may not run ahead of.
pub struct Pace {
    state: Mutex<State>,
}

struct State {
    /// Seconds since the pace began.
    now: f64,
    wall: Instant,
    source: Option<Source>,
}

impl Default for Pace {
    fn default() -> Pace {
        Pace { state: Mutex::new(State { now: 0.0, wall: Instant::now(), source: None }) }
    }
}

impl Pace {
    /// From now on, time moves as `source` says (as the wall clock when it says nothing).
    pub fn follow(&self, source: Source) {
        let mut s = self.state.lock();
        s.source = Some(source);
    }

    /// The reference now, in seconds since the pace began: never falls.
    pub fn now(&self) -> f64 {
        let mut s = self.state.lock();
        let wall = Instant::now();
        let by_wall = (wall - s.wall).as_secs_f64();
        s.wall = wall;
        let moved = s.source.as_mut().and_then(|f| f()).unwrap_or(by_wall);
        s.now += moved.max(0.0);
        s.now
    }
}

impl aviary_clock::Reference for Pace {
    fn now(&self) -> Duration {
        Duration::try_from_secs_f64(Pace::now(self)).unwrap_or(Duration::MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::Pace;

    #[test]
    fn a_source_sets_the_pace_and_the_wall_stands_in_when_it_is_silent() {
        let pace = Pace::default();
        let before = pace.now();
        assert!(before >= 0.0);
        // Five seconds at every look, then nothing to say.
        let mut said = [Some(5.0), Some(5.0), None, Some(-3.0)].into_iter();
        pace.follow(Box::new(move || said.next().flatten()));
        let a = pace.now();
        let b = pace.now();
        assert!((b - a - 5.0).abs() < 1e-9, "{a} {b}");
        let c = pace.now();
        assert!(c >= b && c - b < 1.0, "the wall's few microseconds: {b} {c}");
        // A clock that went back moves nothing.
        assert_eq!(pace.now(), c);
    }
}
