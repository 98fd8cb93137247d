//! Square cells of the ground, so that "who is near" looks at a neighbourhood, not at
//! the whole fleet: the drones in the air (kept up to date as each one moves within a
//! step) and the world's targets (fixed). A query returns a superset of what is within
//! the distance asked, in ascending index order, so callers apply the same exact test
//! in the same order as a scan over everything would: results do not change, only the
//! cost, which no longer grows with the size of the fleet.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

type Cell = (i64, i64);

/// A cell's hash: SipHash (the default, made to resist chosen keys) was most of the cost
/// of a query, and cells are no one's choice. The multiply-and-rotate of Firefox's and
/// rustc's "FxHash".
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

#[derive(Clone, Debug)]
pub(crate) struct Grid {
    size: f64,
    cells: Cells,
    /// Where each item is, by index (`None`: not in the grid).
    at: Vec<Option<Cell>>,
}

impl Grid {
    /// An empty grid of cells `size` metres on a side.
    pub fn new(size: f64) -> Grid {
        Grid { size, cells: Cells::default(), at: Vec::new() }
    }

    fn cell(&self, p: [f64; 2]) -> Cell {
        (floor(p[0] / self.size), floor(p[1] / self.size))
    }

    pub fn contains(&self, i: usize) -> bool {
        self.at.get(i).is_some_and(Option::is_some)
    }

    pub fn clear(&mut self) {
        for list in self.cells.values_mut() {
            list.clear();
        }
        self.at.iter_mut().for_each(|c| *c = None);
    }

    /// Puts item `i` at `p`, or moves it there.
    pub fn put(&mut self, i: usize, p: [f64; 2]) {
        let cell = self.cell(p);
        if self.at.len() <= i {
            self.at.resize(i + 1, None);
        }
        match self.at[i] {
            Some(old) if old == cell => return,
            Some(old) => {
                if let Some(list) = self.cells.get_mut(&old) {
                    list.retain(|&j| j != i);
                }
            }
            None => {}
        }
        self.at[i] = Some(cell);
        self.cells.entry(cell).or_default().push(i);
    }

    /// Every item in a cell that meets the square of half-side `r` around the box from
    /// `a` to `b`, in ascending order (into `out`, which is cleared first).
    pub fn around(&self, a: [f64; 2], b: [f64; 2], r: f64, out: &mut Vec<usize>) {
        out.clear();
        let lo = self.cell([a[0].min(b[0]) - r, a[1].min(b[1]) - r]);
        let hi = self.cell([a[0].max(b[0]) + r, a[1].max(b[1]) + r]);
        // A query wider than the world's cells would visit many empty cells: walk the
        // cells that exist instead.
        let span = (hi.0 - lo.0 + 1).saturating_mul(hi.1 - lo.1 + 1);
        if span < 0 || span as usize > self.cells.len() {
            for (c, list) in &self.cells {
                if (lo.0..=hi.0).contains(&c.0) && (lo.1..=hi.1).contains(&c.1) {
                    out.extend_from_slice(list);
                }
            }
        } else {
            for x in lo.0..=hi.0 {
                for y in lo.1..=hi.1 {
                    if let Some(list) = self.cells.get(&(x, y)) {
                        out.extend_from_slice(list);
                    }
                }
            }
        }
        out.sort_unstable();
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
}
