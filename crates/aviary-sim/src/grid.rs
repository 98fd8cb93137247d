//! Square cells of the ground, so that "who is near" looks at a neighbourhood, not at
//! the whole fleet: the drones in the air (kept up to date as each one moves within a
//! step) and the world's targets (fixed). A query returns a superset of what is within
//! the distance asked, in ascending index order, so callers apply the same exact test
//! in the same order as a scan over everything would: results do not change, only the
//! cost, which does not grow with the size of the fleet.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

type Cell = (i64, i64);

/// A cell's hash: the multiply-and-rotate of Firefox's and rustc's "FxHash". A query hashes
/// every cell it looks at, and cells are coordinates no one chooses, so the default
/// SipHash's resistance to chosen keys would buy nothing for its cost.
#[derive(Default)]
struct CellHasher(u64);

impl Hasher for CellHasher {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.write_u64(u64::from(*b));
        }
    }
    fn write_i64(&mut self, i: i64) {
        self.write_u64(i as u64);
    }
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn finish(&self) -> u64 {
        self.0
    }
}

type Cells = HashMap<Cell, Vec<usize>, BuildHasherDefault<CellHasher>>;

/// `x.floor() as i64` without a call to `floor` (this build has no SSE4.1 to inline it).
fn floor(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t - 1
    } else {
        t
    }
}

/// Cells in a dense window may number at most this many per item (plus a constant):
/// beyond it, items are too spread out for an array to pay.
const DENSE_PER_ITEM: i64 = 4;
const DENSE_SLACK: i64 = 1024;

#[derive(Clone, Debug)]
pub(crate) struct Grid {
    size: f64,
    /// A window of cells kept in an array (`x0..x0 + w` by `y0..y0 + h`, by x then y):
    /// set by [`Grid::reframe`] to where the items are, so that nearly every cell looked
    /// at is an index, not a hash lookup, and neighbouring cells are neighbours in memory.
    x0: i64,
    y0: i64,
    w: i64,
    h: i64,
    dense: Vec<Vec<usize>>,
    /// The cells outside the window.
    cells: Cells,
    /// Where each item is, by index (`None`: not in the grid).
    at: Vec<Option<Cell>>,
    /// Where each item was last put, by index: read by [`Grid::any_within`] from this
    /// dense array rather than from the items themselves (large, and far apart in memory).
    pos: Vec<[f64; 2]>,
}

impl Grid {
    /// An empty grid of cells `size` metres on a side.
    pub fn new(size: f64) -> Grid {
        Grid {
            size,
            x0: 0,
            y0: 0,
            w: 0,
            h: 0,
            dense: Vec::new(),
            cells: Cells::default(),
            at: Vec::new(),
            pos: Vec::new(),
        }
    }

    fn cell(&self, p: [f64; 2]) -> Cell {
        (floor(p[0] / self.size), floor(p[1] / self.size))
    }

    /// The cell's place in the window's array, if it is in the window.
    fn slot(&self, c: Cell) -> Option<usize> {
        let (x, y) = (c.0.wrapping_sub(self.x0), c.1.wrapping_sub(self.y0));
        ((0..self.w).contains(&x) && (0..self.h).contains(&y)).then(|| (x * self.h + y) as usize)
    }

    fn list(&self, c: Cell) -> Option<&Vec<usize>> {
        match self.slot(c) {
            Some(s) => Some(&self.dense[s]),
            None if self.cells.is_empty() => None,
            None => self.cells.get(&c),
        }
    }

    fn list_mut(&mut self, c: Cell) -> &mut Vec<usize> {
        match self.slot(c) {
            Some(s) => &mut self.dense[s],
            None => self.cells.entry(c).or_default(),
        }
    }

    /// Empties the grid and sets its window to the box from `lo` to `hi` (where about
    /// `n` items will be put), unless that box has too many cells for `n`; items may
    /// still be put anywhere.
    pub fn reframe(&mut self, lo: [f64; 2], hi: [f64; 2], n: usize) {
        for list in self.cells.values_mut() {
            list.clear();
        }
        self.at.iter_mut().for_each(|c| *c = None);
        // No window for an empty box (no items: `lo` is +inf) or an absurd one.
        let sane = |x: f64| x.abs() < 1e12;
        let window = (lo[0] <= hi[0] && lo[1] <= hi[1] && lo.iter().chain(&hi).all(|&x| sane(x)))
            .then(|| {
                let (a, b) = (self.cell(lo), self.cell(hi));
                (a, b.0 - a.0 + 1, b.1 - a.1 + 1)
            });
        let limit = (n as i64).saturating_mul(DENSE_PER_ITEM).saturating_add(DENSE_SLACK);
        (self.x0, self.y0, self.w, self.h) = match window {
            Some((a, w, h)) if w <= limit && h <= limit && w.saturating_mul(h) <= limit => {
                (a.0, a.1, w, h)
            }
            _ => (0, 0, 0, 0),
        };
        self.dense.iter_mut().for_each(Vec::clear);
        self.dense.resize_with((self.w * self.h) as usize, Vec::new);
    }

    /// Puts item `i` at `p`, or moves it there.
    pub fn put(&mut self, i: usize, p: [f64; 2]) {
        let cell = self.cell(p);
        if self.at.len() <= i {
            self.at.resize(i + 1, None);
            self.pos.resize(i + 1, [0.0; 2]);
        }
        self.pos[i] = p;
        match self.at[i] {
            Some(old) if old == cell => return,
            Some(old) => self.list_mut(old).retain(|&j| j != i),
            None => {}
        }
        self.at[i] = Some(cell);
        self.list_mut(cell).push(i);
    }

    /// Every item in a cell that meets the square of half-side `r` around the box from
    /// `a` to `b`, in ascending order (into `out`, which is cleared first).
    pub fn around(&self, a: [f64; 2], b: [f64; 2], r: f64, out: &mut Vec<usize>) {
        out.clear();
        self.visit(a, b, r, |list| {
            out.extend_from_slice(list);
            false
        });
        out.sort_unstable();
    }

    /// Whether an item other than `except` is where it was last put within the square of
    /// half-side `r` around `p` (edges included): what filtering [`Grid::around`] would
    /// tell, without a list, a sort, or a look at anything but the grid.
    pub fn any_within(&self, p: [f64; 2], r: f64, except: usize) -> bool {
        self.visit(p, p, r, |list| {
            list.iter().any(|&j| {
                let q = self.pos[j];
                j != except && !((q[0] - p[0]).abs() > r || (q[1] - p[1]).abs() > r)
            })
        })
    }

    /// Where item `i` was last put.
    pub fn at(&self, i: usize) -> [f64; 2] {
        self.pos[i]
    }

    /// The Chebyshev distance from `p` to the nearest item other than `except`, or `cap`
    /// when none is within `cap`; NaN when one that may be is at NaN.
    pub fn nearest(&self, p: [f64; 2], cap: f64, except: usize) -> f64 {
        let mut best = cap;
        self.visit(p, p, cap, |list| {
            for &j in list.iter().filter(|&&j| j != except) {
                let q = self.pos[j];
                let (dx, dy) = ((q[0] - p[0]).abs(), (q[1] - p[1]).abs());
                if dx.is_nan() || dy.is_nan() {
                    best = f64::NAN;
                    return true;
                }
                best = best.min(dx.max(dy));
            }
            false
        });
        best
    }

    /// Calls `f` on the list of every cell that meets the square of half-side `r` around
    /// the box from `a` to `b`, until it returns true; returns whether it did.
    fn visit(&self, a: [f64; 2], b: [f64; 2], r: f64, mut f: impl FnMut(&[usize]) -> bool) -> bool {
        let lo = self.cell([a[0].min(b[0]) - r, a[1].min(b[1]) - r]);
        let hi = self.cell([a[0].max(b[0]) + r, a[1].max(b[1]) + r]);
        // A query wider than the world's cells would visit many empty cells: walk the
        // cells that exist instead.
        let span = (hi.0 - lo.0 + 1).saturating_mul(hi.1 - lo.1 + 1);
        if span < 0 || span as usize > self.dense.len() + self.cells.len() {
            for x in lo.0.max(self.x0)..=hi.0.min(self.x0 + self.w - 1) {
                for y in lo.1.max(self.y0)..=hi.1.min(self.y0 + self.h - 1) {
                    if f(&self.dense[((x - self.x0) * self.h + (y - self.y0)) as usize]) {
                        return true;
                    }
                }
            }
            let inside = |c: &Cell| (lo.0..=hi.0).contains(&c.0) && (lo.1..=hi.1).contains(&c.1);
            self.cells.iter().any(|(c, list)| inside(c) && f(list))
        } else {
            for x in lo.0..=hi.0 {
                for y in lo.1..=hi.1 {
                    if self.list((x, y)).is_some_and(|list| f(list)) {
                        return true;
                    }
                }
            }
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_query_finds_everything_within_reach_in_order() {
        let mut g = Grid::new(10.0);
        let points = [[0.0, 0.0], [25.0, 0.0], [-3.0, 4.0], [100.0, 100.0], [9.9, -9.9]];
        for (i, p) in points.iter().enumerate() {
            g.put(i, *p);
        }
        let mut out = Vec::new();
        g.around([0.0, 0.0], [0.0, 0.0], 12.0, &mut out);
        assert_eq!(out, [0, 2, 4]);
        g.put(3, [1.0, 1.0]);
        g.around([0.0, 0.0], [0.0, 0.0], 5.0, &mut out);
        assert_eq!(out, [0, 2, 3, 4]);
        g.around([-1e9, -1e9], [1e9, 1e9], 0.0, &mut out);
        assert_eq!(out, [0, 1, 2, 3, 4]);
    }

    #[test]
    fn a_window_gives_the_same_answers_as_the_hash_map() {
        let points: Vec<[f64; 2]> = (0..200)
            .map(|i| [((i * 37) % 101) as f64 * 3.7 - 150.0, ((i * 53) % 97) as f64 * 4.1 - 90.0])
            .collect();
        let (mut sparse, mut dense) = (Grid::new(10.0), Grid::new(10.0));
        // A window smaller than the points' box: some go to the hash map.
        dense.reframe([-100.0, -50.0], [100.0, 200.0], points.len());
        for (i, p) in points.iter().enumerate() {
            sparse.put(i, *p);
            dense.put(i, *p);
        }
        for (i, p) in points.iter().enumerate().step_by(7) {
            // Moves, some across the window's edge.
            let q = [p[1] * 1.3, p[0] - 20.0];
            sparse.put(i, q);
            dense.put(i, q);
        }
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for (c, r) in
            [([0.0, 0.0], 15.0), ([-120.0, 30.0], 40.0), ([90.0, -80.0], 5.0), ([0.0, 0.0], 1e6)]
        {
            sparse.around(c, c, r, &mut a);
            dense.around(c, c, r, &mut b);
            assert_eq!(a, b);
            for except in [0, 7, 100] {
                let by_list = a.iter().any(|&j| {
                    let q = sparse.pos[j];
                    j != except && !((q[0] - c[0]).abs() > r || (q[1] - c[1]).abs() > r)
                });
                assert_eq!(dense.any_within(c, r, except), by_list);
                assert_eq!(sparse.any_within(c, r, except), by_list);
            }
        }
    }
}
