//! Plane geometry of the values the middle layer passes (`[x, y]` in local metres):
//! one definition for the checker, the engine and the simulator. Pure and deterministic.

/// Shoelace centroid; the corners' mean when the polygon encloses (almost) no area.
pub fn centroid(polygon: &[[f64; 2]]) -> [f64; 2] {
    if polygon.is_empty() {
        return [0.0, 0.0];
    }
    let n = polygon.len() as f64;
    let mean = [
        polygon.iter().map(|p| p[0]).sum::<f64>() / n,
        polygon.iter().map(|p| p[1]).sum::<f64>() / n,
    ];
    // Relative to the mean, for precision far from the origin.
    let (mut twice_area, mut cx, mut cy) = (0.0, 0.0, 0.0);
    let mut extent: f64 = 0.0;
    for (i, a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        let (ax, ay) = (a[0] - mean[0], a[1] - mean[1]);
        let (bx, by) = (b[0] - mean[0], b[1] - mean[1]);
        let cross = ax * by - bx * ay;
        twice_area += cross;
        cx += (ax + bx) * cross;
        cy += (ay + by) * cross;
        extent = extent.max(ax.abs()).max(ay.abs());
    }
    if !twice_area.is_finite() || twice_area.abs() <= 1e-12 * extent * extent {
        return mean;
    }
    [mean[0] + cx / (3.0 * twice_area), mean[1] + cy / (3.0 * twice_area)]
}

/// Points this close to a polygon's edge count as inside it (metres).
pub const ON_EDGE: f64 = 1e-6;

/// The speed of an orbit of `radius`: at most `max_speed`, and a centripetal
/// acceleration of at most half the drone's `accel`. The simulator flies it, the plan
/// counts with it and the MAVLink backend asks a vehicle for it.
pub fn orbit_speed(max_speed: f64, accel: f64, radius: f64) -> f64 {
    max_speed.min((accel * radius / 2.0).sqrt())
}

pub fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    hypot(b[0] - a[0], b[1] - a[1])
}

/// `x.hypot(y)`, bit for bit, without the call to libm when one side is zero (a drone
/// at rest, or moving along an axis, as a sweep's legs do): libm's `hypot` returns
/// `|x| + |y|` whenever the smaller side is that small, and then `|x| + 0` is `|x|`.
/// The simulator calls it several times per drone per tick.
#[inline]
pub fn hypot(x: f64, y: f64) -> f64 {
    if y == 0.0 {
        x.abs()
    } else if x == 0.0 {
        y.abs()
    } else {
        x.hypot(y)
    }
}

/// The length of `v`, `hypot(hypot(v[0], v[1]), v[2])`.
#[inline]
pub fn norm(v: [f64; 3]) -> f64 {
    hypot(hypot(v[0], v[1]), v[2])
}

/// Exactly `norm(v) < limit`, mostly without computing the norm (the simulator asks it
/// of every pair of drones near each other, every tick): a side as long as `limit` says
/// no; a sum of squares short of `limit²` by far more than the rounding of either says
/// yes; only the rest are measured.
#[inline]
pub fn norm_below(v: [f64; 3], limit: f64) -> bool {
    let longest = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if longest >= limit {
        return false;
    }
    // Within these bounds no square underflows or overflows enough to matter.
    if limit > 1e-140 && limit < 1e140 {
        let squares = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if squares < limit * limit * (1.0 - 1e-9) {
            return true;
        }
    }
    norm(v) < limit
}

/// Distance from `p` to the segment `a`-`b`.
pub fn dist_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    if len2 == 0.0 {
        return dist(p, a);
    }
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0);
    dist(p, [a[0] + t * dx, a[1] + t * dy])
}

pub fn edges(polygon: &[[f64; 2]]) -> impl Iterator<Item = ([f64; 2], [f64; 2])> + '_ {
    polygon.iter().enumerate().map(|(i, &a)| (a, polygon[(i + 1) % polygon.len()]))
}

/// Distance from `p` to the polygon's boundary.
pub fn dist_to_boundary(polygon: &[[f64; 2]], p: [f64; 2]) -> f64 {
    edges(polygon).map(|(a, b)| dist_to_segment(p, a, b)).fold(f64::INFINITY, f64::min)
}

/// Even-odd containment; a point on the boundary (within a micrometre) is inside.
pub fn contains(polygon: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    for (a, b) in edges(polygon) {
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside || dist_to_boundary(polygon, p) <= ON_EDGE
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Whether segments `p`-`q` and `a`-`b` cross each other properly (each one's ends strictly
/// on both sides of the other). Touching and overlapping do not count.
fn crosses(p: [f64; 2], q: [f64; 2], a: [f64; 2], b: [f64; 2]) -> bool {
    let scale = dist(p, q).max(dist(a, b)).max(1.0);
    let tol = ON_EDGE * scale;
    let d1 = cross(a, b, p);
    let d2 = cross(a, b, q);
    let d3 = cross(p, q, a);
    let d4 = cross(p, q, b);
    ((d1 > tol && d2 < -tol) || (d1 < -tol && d2 > tol))
        && ((d3 > tol && d4 < -tol) || (d3 < -tol && d4 > tol))
}

/// Whether the straight segment `p`-`q` stays inside the polygon: both ends inside and no
/// edge crossed.
pub fn segment_inside(polygon: &[[f64; 2]], p: [f64; 2], q: [f64; 2]) -> bool {
    contains(polygon, p)
        && contains(polygon, q)
        && !edges(polygon).any(|(a, b)| crosses(p, q, a, b))
}

/// The polygon's area, positive when its corners go counter-clockwise (the shoelace
/// formula).
pub fn signed_area(polygon: &[[f64; 2]]) -> f64 {
    edges(polygon).map(|(a, b)| a[0] * b[1] - b[0] * a[1]).sum::<f64>() / 2.0
}

/// Two edges of the polygon that cross each other (by index: edge `i` runs from corner
/// `i` to the next), if any: a polygon whose outline crosses itself. Edges are compared
/// only when their extents along x overlap (sorted by their left end), so an outline of
/// many corners costs far less than every pair.
pub fn self_crossing(polygon: &[[f64; 2]]) -> Option<(usize, usize)> {
    let n = polygon.len();
    if n < 4 {
        return None;
    }
    let edge = |i: usize| (polygon[i], polygon[(i + 1) % n]);
    let mut by_left: Vec<(f64, f64, usize)> = (0..n)
        .map(|i| {
            let (a, b) = edge(i);
            (a[0].min(b[0]), a[0].max(b[0]), i)
        })
        .collect();
    by_left.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.2.cmp(&y.2)));
    for (k, &(_, right, i)) in by_left.iter().enumerate() {
        for &(left, _, j) in &by_left[k + 1..] {
            if left > right + ON_EDGE {
                break;
            }
            // Neighbouring edges share a corner; they cannot cross properly.
            let adjacent = (i + 1) % n == j || (j + 1) % n == i;
            let (p, q) = edge(i);
            let (a, b) = edge(j);
            if !adjacent && crosses(p, q, a, b) {
                return Some((i.min(j), i.max(j)));
            }
        }
    }
    None
}

/// Whether the whole circle (its inside and its line) lies in the polygon.
pub fn circle_inside(polygon: &[[f64; 2]], center: [f64; 2], radius: f64) -> bool {
    contains(polygon, center) && dist_to_boundary(polygon, center) >= radius - ON_EDGE
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_outline_that_crosses_itself_is_found_and_a_simple_one_is_not() {
        let square = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        assert_eq!(self_crossing(&square), None);
        assert_eq!(signed_area(&square), 100.0);
        let bowtie = [[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]];
        assert_eq!(self_crossing(&bowtie), Some((0, 2)));
        assert_eq!(signed_area(&[[0.0, 0.0], [5.0, 5.0], [10.0, 10.0]]), 0.0);
        // A star of many corners: every corner on a circle, each edge jumping 3 ahead.
        let n = 2000;
        let circle: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                [a.cos() * 100.0, a.sin() * 100.0]
            })
            .collect();
        assert_eq!(self_crossing(&circle), None);
        let star: Vec<[f64; 2]> = (0..7).map(|i| circle[(i * 3 * n / 7) % n]).collect();
        assert!(self_crossing(&star).is_some());
    }

    #[test]
    fn norm_below_is_the_norm_compared() {
        // A fixed walk through lengths near the limit, every scale and every sign.
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..200_000 {
            let scale = 10f64.powf(next() * 12.0 - 6.0);
            let v = [(next() - 0.5) * scale, (next() - 0.5) * scale, (next() - 0.5) * scale];
            let n = norm(v);
            // The limit at the norm, an ulp or a hair either side, or anywhere.
            let limit = match (next() * 5.0) as u8 {
                0 => n,
                1 => f64::from_bits(n.to_bits() + 1),
                2 => f64::from_bits(n.to_bits().saturating_sub(1)),
                3 => n * (1.0 + (next() - 0.5) * 1e-8),
                _ => next() * scale,
            };
            assert_eq!(norm_below(v, limit), n < limit, "{v:?} {limit}");
        }
        for x in [0.0, f64::NAN, f64::INFINITY, 1e-200, 1e200] {
            for limit in [0.0, 1.0, f64::NAN, f64::INFINITY, 1e-150, 1e150] {
                let v = [x, 0.5, -x];
                assert_eq!(norm_below(v, limit), norm(v) < limit, "{v:?} {limit}");
            }
        }
    }

    #[test]
    fn hypot_is_libms_bit_for_bit() {
        let xs = [
            0.0,
            -0.0,
            1e-300,
            3.0,
            -4.5,
            1e300,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            0.1,
            -7e-320,
        ];
        for x in xs {
            for y in xs {
                let (a, b) = (hypot(x, y), x.hypot(y));
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "{x} {y}: {a} {b}"
                );
            }
        }
    }
}
