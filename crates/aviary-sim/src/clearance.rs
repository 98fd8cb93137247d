//! A lower bound, kept from tick to tick, of how far each drone in the air is from every
//! other one (Chebyshev distance over the ground). With it, "is anybody within reach" of
//! an isolated drone costs a few subtractions instead of a query of the sky's grid; when
//! the bound cannot tell, the grid answers exactly.
//!
//! At a rebuild, each member's gap to its nearest other member is measured (up to a cap)
//! and every member's position is kept as its base. Since then, no member has moved
//! farther than `drift` from its base, so two members are at least
//! `gap - (own move) - drift` apart: the triangle inequality, with a slack far above
//! rounding. Leaving the set keeps the others' bounds valid; joining it needs a rebuild.

use crate::grid::Grid;

/// Chebyshev distance; NaN when either side is NaN (where `f64::max` would drop it).
fn cheb(a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = ((a[0] - b[0]).abs(), (a[1] - b[1]).abs());
    if dx.is_nan() || dy.is_nan() {
        f64::NAN
    } else {
        dx.max(dy)
    }
}

#[derive(Clone, Debug, Default)]
pub(crate) struct Clearance {
    /// Each member's position at the last rebuild; `None` for a non-member.
    base: Vec<Option<[f64; 2]>>,
    /// Each member's gap to the nearest other member at the last rebuild (at most the cap).
    gap: Vec<f64>,
    /// The farthest any member has moved from its base since (NaN: unknown, no bound holds).
    drift: f64,
}

impl Clearance {
    pub fn new(n: usize) -> Clearance {
        Clearance { base: vec![None; n], gap: vec![0.0; n], drift: 0.0 }
    }

    /// How far members have moved since the last rebuild (NaN after a NaN position).
    pub fn drift(&self) -> f64 {
        self.drift
    }

    /// Makes the members exactly `members`, each where `grid` (which holds them all, and
    /// nothing else) has it, and measures their gaps up to `cap`.
    pub fn rebuild(&mut self, members: &[usize], grid: &Grid, cap: f64) {
        self.base.iter_mut().for_each(|b| *b = None);
        self.drift = 0.0;
        for &i in members {
            if self.base.len() <= i {
                self.base.resize(i + 1, None);
                self.gap.resize(i + 1, 0.0);
            }
            let p = grid.at(i);
            self.base[i] = Some(p);
            // A NaN gap (a NaN position anywhere near) never clears anything.
            self.gap[i] =
                if p.iter().all(|x| x.is_finite()) { grid.nearest(p, cap, i) } else { f64::NAN };
        }
    }

    /// Records that `i` is now at `p`; returns whether it is a member.
    // `!(m <= drift)` on purpose: a NaN move must take over the bound (below).
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    pub fn moved(&mut self, i: usize, p: [f64; 2]) -> bool {
        let Some(Some(base)) = self.base.get(i) else { return false };
        let m = cheb(p, *base);
        // NaN-propagating max: a NaN move spoils the bound until the next rebuild.
        if !(m <= self.drift) && !self.drift.is_nan() {
            self.drift = m;
        }
        true
    }

    pub fn is_member(&self, i: usize) -> bool {
        matches!(self.base.get(i), Some(Some(_)))
    }

    /// `i` is no longer in the set (its bound is dropped; the others' stay valid).
    pub fn leave(&mut self, i: usize) {
        if let Some(b) = self.base.get_mut(i) {
            *b = None;
        }
    }

    /// Whether member `i`, now at `p`, is certainly farther than `r` (Chebyshev) from every
    /// other member where it is now. False whenever the bound cannot tell.
    pub fn clear(&self, i: usize, p: [f64; 2], r: f64) -> bool {
        let Some(Some(base)) = self.base.get(i) else { return false };
        let gap = self.gap[i];
        let room = gap - cheb(p, *base) - self.drift;
        let slack = 1e-9 * (gap.abs() + r.abs()) + 1e-9;
        room > r + slack
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn exact(points: &[[f64; 2]], i: usize, r: f64) -> bool {
        let mut g = Grid::new(40.0);
        for (j, p) in points.iter().enumerate() {
            g.put(j, *p);
        }
        !g.any_within(points[i], r, i)
    }

    proptest! {
        /// Whenever the bound says "clear", the grid's exact test agrees, through any
        /// sequence of small moves after a rebuild.
        #[test]
        fn clear_implies_nobody_within(
            start in prop::collection::vec((-300f64..300.0, -300f64..300.0), 2..30),
            moves in prop::collection::vec((0usize..30, -6f64..6.0, -6f64..6.0), 0..80),
            r in 0f64..120.0,
            cap in 10f64..400.0,
        ) {
            let mut points: Vec<[f64; 2]> = start.iter().map(|&(x, y)| [x, y]).collect();
            let mut grid = Grid::new(40.0);
            for (j, p) in points.iter().enumerate() {
                grid.put(j, *p);
            }
            let members: Vec<usize> = (0..points.len()).collect();
            let mut c = Clearance::new(points.len());
            c.rebuild(&members, &grid, cap);
            for (k, dx, dy) in moves {
                let k = k % points.len();
                points[k] = [points[k][0] + dx, points[k][1] + dy];
                prop_assert!(c.moved(k, points[k]));
                for i in 0..points.len() {
                    if c.clear(i, points[i], r) {
                        prop_assert!(exact(&points, i, r), "drone {i} at {:?}", points[i]);
                    }
                }
            }
        }
    }

    #[test]
    fn isolated_members_are_clear_and_joining_needs_a_rebuild() {
        let mut grid = Grid::new(100.0);
        let points = [[0.0, 0.0], [300.0, 0.0], [0.0, 300.0]];
        for (j, p) in points.iter().enumerate() {
            grid.put(j, *p);
        }
        let mut c = Clearance::new(4);
        c.rebuild(&[0, 1, 2], &grid, 400.0);
        assert!(c.clear(0, points[0], 250.0));
        assert!(!c.clear(0, points[0], 300.0), "the edge counts as within");
        c.moved(1, [245.0, 0.0]);
        assert!(!c.clear(0, points[0], 250.0), "drone 1 came closer");
        assert!(!c.moved(3, [1.0, 1.0]), "not a member");
        assert!(!c.clear(3, [1.0, 1.0], 1.0));
        c.leave(2);
        assert!(!c.clear(2, points[2], 1.0));
        c.moved(0, [f64::NAN, 0.0]);
        assert!(c.drift().is_nan());
        assert!(!c.clear(1, [245.0, 0.0], 1.0), "no bound after a NaN");
    }
}
