//! The world's targets near one drone, for detection: a grid query over a region wider
//! than the way of one tick, kept for as long as each tick's way (widened by the range)
//! stays inside that region, and narrowed to the items inside the region (plus a margin),
//! since the grid's cells are much larger than a sensor's reach. Ascending, as detection
//! looks at them; the detection test that filters them is unchanged.

use crate::grid::Grid;

/// How much wider than the tick's need a fresh query looks: `WIDEN × range + WIDEN_M`.
const WIDEN: f64 = 2.0;
const WIDEN_M: f64 = 10.0;

#[derive(Clone, Debug)]
pub(crate) struct Nearby {
    /// The region the list was made for (empty at first), and the range it was for.
    lo: [f64; 2],
    hi: [f64; 2],
    range: f64,
    list: Vec<usize>,
}

impl Default for Nearby {
    fn default() -> Nearby {
        Nearby { lo: [f64::INFINITY; 2], hi: [f64::NEG_INFINITY; 2], range: 0.0, list: Vec::new() }
    }
}

/// Metres beyond a region that an item may lie and still be kept: more than detection's
/// rounding slack beyond the range (`range × 1e-9 + 1e-9`).
fn margin(range: f64) -> f64 {
    1.0 + range * 1e-6
}

impl Nearby {
    /// Every item of `grid` (ascending) that lies within `margin(r)` of the box from `a`
    /// to `b` widened by `r`, and perhaps others.
    pub fn around(&mut self, grid: &Grid, a: [f64; 2], b: [f64; 2], r: f64) -> &[usize] {
        let lo = [a[0].min(b[0]) - r, a[1].min(b[1]) - r];
        let hi = [a[0].max(b[0]) + r, a[1].max(b[1]) + r];
        let inside = r <= self.range
            && lo[0] >= self.lo[0]
            && lo[1] >= self.lo[1]
            && hi[0] <= self.hi[0]
            && hi[1] <= self.hi[1];
        if !inside {
            let m = WIDEN * r + WIDEN_M;
            (self.lo, self.hi, self.range) = ([lo[0] - m, lo[1] - m], [hi[0] + m, hi[1] + m], r);
            grid.around(self.lo, self.hi, 0.0, &mut self.list);
            // An item kept is within the margin of the region; NaN positions are never near.
            let e = margin(r);
            let (lo, hi) = ([self.lo[0] - e, self.lo[1] - e], [self.hi[0] + e, self.hi[1] + e]);
            self.list.retain(|&i| {
                let p = grid.at(i);
                p[0] >= lo[0] && p[0] <= hi[0] && p[1] >= lo[1] && p[1] <= hi[1]
            });
        }
        &self.list
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Along any walk, the kept list holds, in order, every item that detection's box
        /// test would let through: within the way's box widened by the range and its slack.
        #[test]
        fn every_item_detection_could_find_in_order(
            items in prop::collection::vec((-500f64..500.0, -500f64..500.0), 0..60),
            walk in prop::collection::vec((-8f64..8.0, -8f64..8.0, 0u8..8), 1..100),
            r in 0f64..40.0,
            size in 20f64..200.0,
        ) {
            let mut g = Grid::new(size);
            for (i, &(x, y)) in items.iter().enumerate() {
                g.put(i, [x, y]);
            }
            let mut near = Nearby::default();
            let mut p = [0.0, 0.0];
            for (dx, dy, shrink) in walk {
                let q = [p[0] + dx, p[1] + dy];
                // Sometimes a smaller range (a detection started with a shorter one).
                let r = r / f64::from(1 + shrink / 6);
                let kept = near.around(&g, p, q, r).to_vec();
                prop_assert!(kept.windows(2).all(|w| w[0] < w[1]));
                let slack = r * (1.0 + 1e-9) + 1e-9;
                let (lo, hi) = ([p[0].min(q[0]) - slack, p[1].min(q[1]) - slack], [p[0].max(q[0]) + slack, p[1].max(q[1]) + slack]);
                for (i, &(x, y)) in items.iter().enumerate() {
                    if x >= lo[0] && x <= hi[0] && y >= lo[1] && y <= hi[1] {
                        prop_assert!(kept.binary_search(&i).is_ok(), "item {i} at {x} {y} missing: {kept:?}");
                    }
                }
                p = q;
            }
        }
    }
}
