//! Where a drone can be within a few seconds, as a box, read from its legs without
//! flying them: the planner of [`crate::avoid`] uses it to see, before it predicts
//! anything, that two drones cannot come within `min_separation` over its horizon.
//!
//! The box holds every point the drone's own motion code ([`SimDrone::tick_motion`]) would
//! take it through in that time, flying as it does now without a yield: along a straight
//! leg it stays on the segment to the leg's end and never passes it, at a ground speed no
//! higher than the larger of its speed now and the leg's (the speed profile only brakes
//! from above a limit, see [`crate::profile::advance`]); its altitude moves from where it
//! is towards the leg's, never beyond; an arc stays on its circle; a hover stays put; a
//! leg begins where the one before it ended, at rest. So a leg `d` metres long takes at
//! least `d / speed`, and the legs that could not begin within the time add nothing.
//! A drone that yields (whose altitude the planner steers) has no box here: its track is
//! predicted.

use crate::drone::SimDrone;
use crate::motion::Leg;

/// An axis-aligned box, `lo` to `hi` on each axis (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Bounds {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
}

impl Bounds {
    fn point(p: [f64; 3]) -> Bounds {
        Bounds { lo: p, hi: p }
    }

    fn take(&mut self, p: [f64; 3]) {
        for ((lo, hi), x) in self.lo.iter_mut().zip(&mut self.hi).zip(p) {
            *lo = lo.min(x);
            *hi = hi.max(x);
        }
    }

    /// The box of a predicted track's points (the ones in the air); `None` when it has none.
    pub fn of_points<'a>(points: impl IntoIterator<Item = &'a [f64; 3]>) -> Option<Bounds> {
        let mut points = points.into_iter();
        let mut b = Bounds::point(*points.next()?);
        for p in points {
            b.take(*p);
        }
        Some(b)
    }

    /// Whether every point of `self` is more than `sep` from every point of `other`, by a
    /// margin beyond the rounding of the positions they bound and of the distances the
    /// planner measures between them (a false "no" only costs a prediction). Never true
    /// with a NaN.
    pub fn apart(&self, other: &Bounds, sep: f64) -> bool {
        let mut gap2 = 0.0;
        let mut scale = 1.0f64;
        for a in 0..3 {
            let g = (other.lo[a] - self.hi[a]).max(self.lo[a] - other.hi[a]).max(0.0);
            gap2 += g * g;
            scale = scale.max(self.lo[a].abs()).max(self.hi[a].abs());
            scale = scale.max(other.lo[a].abs()).max(other.hi[a].abs());
        }
        let need = sep + 1e-6 + 1e-9 * scale;
        gap2 >= need * need
    }

    /// Whether `p` is in the box, give or take the rounding [`Bounds::apart`] allows for.
    #[cfg(any(test, debug_assertions))]
    pub fn holds(&self, p: [f64; 3]) -> bool {
        (0..3).all(|a| {
            let slack = 1e-7 + 1e-10 * (self.lo[a].abs() + self.hi[a].abs());
            self.lo[a] - slack <= p[a] && p[a] <= self.hi[a] + slack
        })
    }
}

/// Every point drone `d` can reach within `time` seconds, flying its legs as it does now,
/// without a yield; `None` when it yields or a figure is not finite.
pub(crate) fn reach_box(d: &SimDrone, time: f64) -> Option<Bounds> {
    if d.avoid.is_some() {
        return None;
    }
    let mut b = Bounds::point(d.pos);
    let Some(task) = d.motion.as_deref().filter(|t| !t.paused) else {
        return Some(b);
    };
    // The time the legs so far take at least, and where the next one begins.
    let (mut spent, mut at) = (0.0, d.pos);
    for (k, leg) in task.legs.iter().enumerate() {
        // Also when the time spent is NaN: the check after the loop gives up then.
        if spent.partial_cmp(&time) != Some(std::cmp::Ordering::Less) {
            break;
        }
        let left = time - spent;
        match *leg {
            Leg::Move { to, speed, .. } => {
                let v = if k == 0 { speed.max(task.ground_speed) } else { speed };
                let (dx, dy) = (to[0] - at[0], to[1] - at[1]);
                let length = (dx * dx + dy * dy).sqrt();
                let reach = length.min(v * left);
                let end = if reach < length {
                    let f = reach / length;
                    [at[0] + dx * f, at[1] + dy * f, to[2]]
                } else {
                    to
                };
                // The altitude moves towards the leg's all along, whatever the ground does.
                b.take([end[0], end[1], at[2]]);
                b.take(end);
                spent += least_time(length, v);
                at = to;
            }
            Leg::Hold { left: hold } => spent += hold.max(0.0),
            Leg::Arc { center, radius, start, total, speed } => {
                let r = radius.abs();
                b.take([center[0] - r, center[1] - r, at[2]]);
                b.take([center[0] + r, center[1] + r, at[2]]);
                let (done, v) =
                    if k == 0 { (task.arc_done, speed.max(task.arc_speed)) } else { (0.0, speed) };
                spent += least_time((total - done) * radius, v);
                let theta = start - total;
                at = [center[0] + radius * theta.cos(), center[1] + radius * theta.sin(), at[2]];
            }
        }
    }
    let finite = b.lo.iter().chain(&b.hi).all(|x| x.is_finite());
    (finite && !spent.is_nan()).then_some(b)
}

/// The least time `length` metres take at up to `speed`: none for none, for ever at no
/// speed (a NaN stays NaN, and [`reach_box`] gives up).
fn least_time(length: f64, speed: f64) -> f64 {
    if length == 0.0 {
        0.0
    } else {
        length / speed
    }
}
