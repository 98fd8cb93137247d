//! The one-dimensional speed profile every move is made of: accelerate at most `a`, cruise
//! at most `vmax`, and brake at most `a` so as to stop exactly at the goal (a trapezoid,
//! or a triangle when the move is too short to reach `vmax`).

/// Distances below this count as arrived (metres).
const EPS: f64 = 1e-9;
/// A step that would leave less than this to go finishes the move (metres).
const SNAP: f64 = 1e-6;

/// The result of one tick of a 1-D move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Advance {
    /// Metres moved this tick (exactly the remaining distance on arrival).
    pub moved: f64,
    /// Speed at the end of the tick (0 on arrival).
    pub speed: f64,
    pub arrived: bool,
}

/// One tick of `dt` seconds of a move with `remaining` metres to go, starting at `speed`.
///
/// The speed at the end of the tick is the largest one that (a) differs from `speed` by at
/// most `a * dt`, (b) is at most `vmax`, and (c) still lets the drone stop at the goal when
/// braking at `a` from the next tick on. Positions integrate the speed exactly (the mean of
/// the two speeds), so a move that starts at rest ends at rest with every speed change
/// within the bound.
pub(crate) fn advance(remaining: f64, speed: f64, vmax: f64, a: f64, dt: f64) -> Advance {
    if remaining <= EPS {
        return Advance { moved: remaining.max(0.0), speed: 0.0, arrived: true };
    }
    // v1^2 / (2a) + (speed + v1) / 2 * dt <= remaining, solved for v1.
    let c = remaining - speed * dt / 2.0;
    let brake = if c > 0.0 {
        a * (-dt / 2.0 + (dt * dt / 4.0 + 2.0 * c / a).sqrt())
    } else {
        f64::NEG_INFINITY
    };
    let lowest = (speed - a * dt).max(0.0);
    let v1 = brake.min(vmax).min(speed + a * dt).max(lowest);
    let moved = (speed + v1) / 2.0 * dt;
    if moved >= remaining - SNAP {
        Advance { moved: remaining, speed: 0.0, arrived: true }
    } else {
        Advance { moved, speed: v1, arrived: false }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(distance: f64, vmax: f64, a: f64, dt: f64) -> (f64, Vec<f64>) {
        let (mut left, mut v, mut t, mut speeds) = (distance, 0.0, 0.0, vec![0.0]);
        loop {
            let step = advance(left, v, vmax, a, dt);
            left -= step.moved;
            v = step.speed;
            t += dt;
            speeds.push(v);
            if step.arrived {
                return (t, speeds);
            }
            assert!(t < 1e4, "never arrives");
        }
    }

    #[test]
    fn trapezoid_time_and_bounds() {
        let (t, speeds) = run(20.0, 3.0, 3.0, 0.05);
        // 1 s up, 1 s down (3 m in all), 17 m at 3 m/s.
        let analytic = 2.0 + 17.0 / 3.0;
        assert!((t - analytic).abs() < 0.05 * analytic, "{t} vs {analytic}");
        for w in speeds.windows(2) {
            assert!(w[1] <= 3.0 + 1e-12);
            assert!((w[1] - w[0]).abs() <= 3.0 * 0.05 + 1e-9, "{w:?}");
        }
    }

    #[test]
    fn short_moves_are_triangles_and_tiny_moves_end() {
        let (t, speeds) = run(1.0, 10.0, 3.0, 0.05);
        let analytic = 2.0 * (1.0f64 / 3.0).sqrt();
        assert!((t - analytic).abs() < 0.1, "{t} vs {analytic}");
        assert!(speeds.iter().all(|&v| v < 2.0));
        let (t, _) = run(1e-4, 10.0, 3.0, 0.05);
        assert!(t <= 0.1 + 1e-12);
        assert!(advance(0.0, 0.0, 10.0, 3.0, 0.05).arrived);
    }
}
