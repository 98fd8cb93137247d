//! Plane geometry on `[x, y]` points in local metres: polygon containment, distances, and
//! the geofence checks of a planned path. Pure and deterministic.

/// Points this close to a polygon's edge count as inside it (metres).
const ON_EDGE: f64 = 1e-6;

pub(crate) fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// Distance from `p` to the segment `a`-`b`.
pub(crate) fn dist_to_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let len2 = dx * dx + dy * dy;
    if len2 == 0.0 {
        return dist(p, a);
    }
    let t = (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2).clamp(0.0, 1.0);
    dist(p, [a[0] + t * dx, a[1] + t * dy])
}

/// Distance from `p` to a polyline (to the point itself when the polyline has one point).
#[cfg(test)]
pub(crate) fn dist_to_polyline(p: [f64; 2], line: &[[f64; 2]]) -> f64 {
    match line {
        [] => f64::INFINITY,
        [only] => dist(p, *only),
        _ => line
            .windows(2)
            .map(|w| dist_to_segment(p, w[0], w[1]))
            .fold(f64::INFINITY, f64::min),
    }
}

fn edges(polygon: &[[f64; 2]]) -> impl Iterator<Item = ([f64; 2], [f64; 2])> + '_ {
    polygon
        .iter()
        .enumerate()
        .map(|(i, &a)| (a, polygon[(i + 1) % polygon.len()]))
}

/// Distance from `p` to the polygon's boundary.
pub(crate) fn dist_to_boundary(polygon: &[[f64; 2]], p: [f64; 2]) -> f64 {
    edges(polygon)
        .map(|(a, b)| dist_to_segment(p, a, b))
        .fold(f64::INFINITY, f64::min)
}

/// Even-odd containment; a point on the boundary (within a micrometre) is inside.
pub(crate) fn contains(polygon: &[[f64; 2]], p: [f64; 2]) -> bool {
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
pub(crate) fn segment_inside(polygon: &[[f64; 2]], p: [f64; 2], q: [f64; 2]) -> bool {
    contains(polygon, p)
        && contains(polygon, q)
        && !edges(polygon).any(|(a, b)| crosses(p, q, a, b))
}

/// Whether the whole circle (its inside and its line) lies in the polygon.
pub(crate) fn circle_inside(polygon: &[[f64; 2]], center: [f64; 2], radius: f64) -> bool {
    contains(polygon, center) && dist_to_boundary(polygon, center) >= radius - ON_EDGE
}

/// The polygon's area (positive either way round).
pub(crate) fn area(polygon: &[[f64; 2]]) -> f64 {
    edges(polygon)
        .map(|(a, b)| a[0] * b[1] - b[0] * a[1])
        .sum::<f64>()
        .abs()
        / 2.0
}

/// The area centroid; the corners' mean when the polygon encloses no area.
pub(crate) use aviary_api::centroid;

/// Degrees clockwise from north of a ground velocity.
pub(crate) fn heading(vx: f64, vy: f64) -> f64 {
    let h = vx.atan2(vy).to_degrees();
    if h < 0.0 {
        h + 360.0
    } else {
        h
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const L: [[f64; 2]; 6] = [
        [0.0, 0.0],
        [100.0, 0.0],
        [100.0, 40.0],
        [40.0, 40.0],
        [40.0, 100.0],
        [0.0, 100.0],
    ];

    #[test]
    fn containment_and_segments() {
        assert!(contains(&L, [10.0, 90.0]));
        assert!(!contains(&L, [90.0, 90.0]));
        assert!(contains(&L, [100.0, 20.0]), "the boundary is inside");
        assert!(segment_inside(&L, [10.0, 10.0], [90.0, 10.0]));
        assert!(
            !segment_inside(&L, [10.0, 90.0], [90.0, 10.0]),
            "cuts across the notch"
        );
        assert!(
            segment_inside(&L, [0.0, 0.0], [100.0, 0.0]),
            "along an edge"
        );
        assert!(circle_inside(&L, [20.0, 20.0], 20.0));
        assert!(!circle_inside(&L, [20.0, 20.0], 21.0));
        assert_eq!(area(&L), 100.0 * 40.0 + 40.0 * 60.0);
        assert_eq!(
            centroid(&[[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]),
            [1.0, 1.0]
        );
    }

    #[test]
    fn headings() {
        assert_eq!(heading(0.0, 1.0), 0.0);
        assert_eq!(heading(1.0, 0.0), 90.0);
        assert_eq!(heading(0.0, -1.0), 180.0);
        assert_eq!(heading(-1.0, 0.0), 270.0);
    }
}
