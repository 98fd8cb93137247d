//! The plane tests the planner makes millions of times: whether a straight segment passes
//! through a polygon's inside (or outside), and a zone grown by the margin. Written for
//! speed and for polygons of any shape (concave ones too); the tests hold them to `geo`'s
//! DE-9IM predicates.

use aviary_api::geometry::{contains, dist_to_boundary, edges};
use geo::algorithm::buffer::{Buffer, BufferStyle, LineJoin};
use geo::{Coord, LineString, Polygon};

/// Metres: a point this close to a polygon's line is on it (neither inside nor outside).
pub(crate) const ON_LINE: f64 = 1e-6;

/// The radians of arc each side of a grown corner spans: the round joins are polygons,
/// their corners on the arc at the margin, so a side cuts inside by at most
/// `margin × (1 - cos(JOIN / 2))`, 0.5% of it (5 cm of 10 m).
const JOIN: f64 = 0.2;

/// An axis-aligned box, for the quick "far apart" answer.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Bounds {
    lo: [f64; 2],
    hi: [f64; 2],
}

impl Bounds {
    pub fn of(points: &[[f64; 2]]) -> Bounds {
        let mut b = Bounds { lo: [f64::INFINITY; 2], hi: [f64::NEG_INFINITY; 2] };
        for p in points {
            b.lo = [b.lo[0].min(p[0]), b.lo[1].min(p[1])];
            b.hi = [b.hi[0].max(p[0]), b.hi[1].max(p[1])];
        }
        b
    }

    /// Whether the segment's box meets this one (grown by `ON_LINE`).
    pub fn meets(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        (0..2).all(|k| {
            a[k].min(b[k]) <= self.hi[k] + ON_LINE && a[k].max(b[k]) >= self.lo[k] - ON_LINE
        })
    }
}

/// A polygon with its box.
#[derive(Clone, Debug)]
pub(crate) struct Outline {
    pub corners: Vec<[f64; 2]>,
    pub bounds: Bounds,
}

impl Outline {
    pub fn new(corners: Vec<[f64; 2]>) -> Outline {
        let bounds = Bounds::of(&corners);
        Outline { corners, bounds }
    }

    /// Strictly inside: inside and not on the line.
    pub fn holds(&self, p: [f64; 2]) -> bool {
        contains(&self.corners, p) && dist_to_boundary(&self.corners, p) > ON_LINE
    }

    /// Whether the segment `a`-`b` passes through the polygon's inside (touching its line,
    /// or running along it, does not count).
    pub fn crossed_by(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        self.bounds.meets(a, b) && pieces(&self.corners, a, b).any(|m| self.holds(m))
    }

    /// Whether the segment `a`-`b` passes outside the polygon (its line counts as inside).
    pub fn left_by(&self, a: [f64; 2], b: [f64; 2]) -> bool {
        !contains(&self.corners, a)
            || !contains(&self.corners, b)
            || pieces(&self.corners, a, b).any(|m| !contains(&self.corners, m))
    }
}

/// The midpoints of the pieces the polygon's line cuts the segment `a`-`b` into: each piece
/// lies wholly inside or wholly outside (or on the line), so its midpoint tells which.
fn pieces(polygon: &[[f64; 2]], a: [f64; 2], b: [f64; 2]) -> impl Iterator<Item = [f64; 2]> {
    let mut cuts = vec![0.0, 1.0];
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    if len2 > 0.0 {
        for (p, q) in edges(polygon) {
            cut(a, d, len2, p, q, &mut cuts);
        }
    }
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|x, y| (*x - *y).abs() <= 1e-12);
    let mids: Vec<[f64; 2]> = cuts
        .windows(2)
        .map(|w| {
            let t = (w[0] + w[1]) / 2.0;
            [a[0] + t * d[0], a[1] + t * d[1]]
        })
        .collect();
    mids.into_iter()
}

/// Where the edge `p`-`q` meets the segment from `a` along `d` (`len2` its length
/// squared), as fractions of the segment: the crossing, or the ends of an overlap.
fn cut(a: [f64; 2], d: [f64; 2], len2: f64, p: [f64; 2], q: [f64; 2], cuts: &mut Vec<f64>) {
    let e = [q[0] - p[0], q[1] - p[1]];
    let denom = d[0] * e[1] - d[1] * e[0];
    let ap = [p[0] - a[0], p[1] - a[1]];
    // Where the edge's ends project onto the segment, and how far off it they are.
    let along = |r: [f64; 2]| ((r[0] - a[0]) * d[0] + (r[1] - a[1]) * d[1]) / len2;
    let off = |r: [f64; 2]| ((r[0] - a[0]) * d[1] - (r[1] - a[1]) * d[0]).abs() / len2.sqrt();
    let mut push = |t: f64| {
        if t > 0.0 && t < 1.0 {
            cuts.push(t);
        }
    };
    // An end of the edge on the segment cuts it there (a corner touched, or an overlap).
    for r in [p, q] {
        if off(r) <= ON_LINE {
            push(along(r));
        }
    }
    if denom.abs() > 1e-12 * len2.sqrt() * e[0].hypot(e[1]) {
        let t = (ap[0] * e[1] - ap[1] * e[0]) / denom;
        let u = (ap[0] * d[1] - ap[1] * d[0]) / denom;
        if (-1e-12..=1.0 + 1e-12).contains(&u) {
            push(t);
        }
    }
}

/// The zone grown by `margin` on every side, with round corners: the outline of the points
/// within `margin` of it (its inside included). A grown outline that encloses a pocket
/// (the arms of a U that meet) keeps only its outer ring: the pocket could be flown into
/// only through the zone's margin.
pub(crate) fn grow(zone: &[[f64; 2]], margin: f64) -> Vec<[f64; 2]> {
    if margin <= 0.0 {
        return zone.to_vec();
    }
    let ring: Vec<Coord<f64>> = zone.iter().map(|p| Coord { x: p[0], y: p[1] }).collect();
    let polygon = Polygon::new(LineString::new(ring), Vec::new());
    let style = BufferStyle::new(margin).line_join(LineJoin::Round(JOIN));
    let grown = polygon.buffer_with_style(style);
    // One zone grows into one piece: its largest, should rounding ever make more.
    let outer =
        grown.0.iter().map(|p| p.exterior()).max_by(|a, b| {
            Bounds::of(&corners(a)).span().total_cmp(&Bounds::of(&corners(b)).span())
        });
    match outer {
        Some(ring) if ring.0.len() > 3 => corners(ring),
        _ => zone.to_vec(),
    }
}

impl Bounds {
    fn span(&self) -> f64 {
        (self.hi[0] - self.lo[0]) + (self.hi[1] - self.lo[1])
    }
}

/// A closed ring's corners, without the repeated first one.
fn corners(ring: &LineString<f64>) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = ring.0.iter().map(|c| [c.x, c.y]).collect();
    if out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use geo::{coord, Line, Relate};
    use proptest::prelude::*;

    fn to_geo(corners: &[[f64; 2]]) -> Polygon<f64> {
        Polygon::new(
            LineString::new(corners.iter().map(|p| coord! { x: p[0], y: p[1] }).collect()),
            Vec::new(),
        )
    }

    /// An L, concave, with corners on a 10 m grid (so that segments between grid points
    /// touch its corners and run along its sides).
    const ELL: [[f64; 2]; 6] =
        [[0.0, 0.0], [40.0, 0.0], [40.0, 10.0], [10.0, 10.0], [10.0, 40.0], [0.0, 40.0]];

    proptest! {
        /// `crossed_by` is DE-9IM's "the segment's inside meets the polygon's inside", on
        /// segments between grid points (corners touched, sides run along) and anywhere.
        #[test]
        fn crossing_agrees_with_geo(a in (-2i32..7, -2i32..7), b in (-2i32..7, -2i32..7), jitter in any::<bool>()) {
            let k = if jitter { 7.3 } else { 10.0 };
            let a = [f64::from(a.0) * k, f64::from(a.1) * k];
            let b = [f64::from(b.0) * k, f64::from(b.1) * k];
            prop_assume!(a != b);
            let ell = Outline::new(ELL.to_vec());
            let line = Line::new(coord! { x: a[0], y: a[1] }, coord! { x: b[0], y: b[1] });
            let m = line.relate(&to_geo(&ELL));
            let geo_says = m.is_intersects() && !m.is_touches();
            prop_assert_eq!(ell.crossed_by(a, b), geo_says, "{:?} to {:?}", a, b);
            let geo_within = line.relate(&to_geo(&ELL)).is_coveredby();
            prop_assert_eq!(!ell.left_by(a, b), geo_within, "{:?} to {:?} (within)", a, b);
        }
    }

    #[test]
    fn a_grown_square_keeps_the_margin_and_no_more_than_a_little_over() {
        let square = [[0.0, 0.0], [100.0, 0.0], [100.0, 100.0], [0.0, 100.0]];
        let grown = grow(&square, 10.0);
        let inside = Outline::new(square.to_vec());
        for p in &grown {
            let d = dist_to_boundary(&square, *p);
            assert!(!inside.holds(*p) && (9.99..=10.01).contains(&d), "{p:?} is {d} m away");
        }
        // Each side's midpoint: the sides cut inside the arc by at most 0.5%.
        for (p, q) in edges(&grown) {
            let m = [(p[0] + q[0]) / 2.0, (p[1] + q[1]) / 2.0];
            assert!(dist_to_boundary(&square, m) >= 9.95, "{m:?}");
        }
    }
}
