//! The world's targets near one drone, for detection: a grid query over a region wider
//! than the way of one tick, reused for as long as each tick's way (widened by the range)
//! stays inside that region. A superset in ascending order, as the query itself gives:
//! the detection test that filters it is unchanged.

use crate::grid::Grid;

/// How much wider than the tick's need a fresh query looks: `WIDEN × range + WIDEN_M`.
const WIDEN: f64 = 2.0;
const WIDEN_M: f64 = 10.0;

#[derive(Clone, Debug)]
pub(crate) struct Nearby {
    /// The region the list was found for (empty at first).
    lo: [f64; 2],
    hi: [f64; 2],
    list: Vec<usize>,
}

impl Default for Nearby {
    fn default() -> Nearby {
        Nearby { lo: [f64::INFINITY; 2], hi: [f64::NEG_INFINITY; 2], list: Vec::new() }
    }
}

impl Nearby {
    /// At least every item of `grid` that `grid.around(a, b, r, ..)` gives, ascending.
    pub fn around(&mut self, grid: &Grid, a: [f64; 2], b: [f64; 2], r: f64) -> &[usize] {
        // The same box as `Grid::around` computes: inside ours, its cells are among ours.
        let lo = [a[0].min(b[0]) - r, a[1].min(b[1]) - r];
        let hi = [a[0].max(b[0]) + r, a[1].max(b[1]) + r];
        let inside = lo[0] >= self.lo[0] && lo[1] >= self.lo[1] && hi[0] <= self.hi[0] && hi[1] <= self.hi[1];
        if !inside {
            let m = WIDEN * r + WIDEN_M;
            self.lo = [lo[0] - m, lo[1] - m];
            self.hi = [hi[0] + m, hi[1] + m];
            grid.around(self.lo, self.hi, 0.0, &mut self.list);
        }
        &self.list
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Along any walk, the kept list holds every item the direct query gives, in order.
        #[test]
        fn a_superset_of_the_query_in_order(
            items in prop::collection::vec((-500f64..500.0, -500f64..500.0), 0..60),
            walk in prop::collection::vec((-8f64..8.0, -8f64..8.0), 1..100),
            r in 0f64..40.0,
            size in 20f64..200.0,
        ) {
            let mut g = Grid::new(size);
            for (i, &(x, y)) in items.iter().enumerate() {
                g.put(i, [x, y]);
            }
            let (mut near, mut direct) = (Nearby::default(), Vec::new());
            let mut p = [0.0, 0.0];
            for (dx, dy) in walk {
                let q = [p[0] + dx, p[1] + dy];
                g.around(p, q, r, &mut direct);
                let kept = near.around(&g, p, q, r).to_vec();
                prop_assert!(kept.windows(2).all(|w| w[0] < w[1]));
                prop_assert!(direct.iter().all(|i| kept.binary_search(i).is_ok()), "{direct:?} {kept:?}");
                p = q;
            }
        }
    }
}
