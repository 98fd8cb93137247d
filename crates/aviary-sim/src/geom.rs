//! Plane geometry on `[x, y]` points in local metres: polygon containment, distances, and
//! the geofence checks of a planned path. Pure and deterministic.

// Containment, distances and the geofence checks of a path live in `aviary_api::geometry`,
// shared with the checker's pre-flight geofence analysis.
pub(crate) use aviary_api::geometry::{
    circle_inside, contains, dist, dist_to_segment, edges, segment_inside,
};

/// Distance from `p` to a polyline (to the point itself when the polyline has one point).
#[cfg(test)]
pub(crate) fn dist_to_polyline(p: [f64; 2], line: &[[f64; 2]]) -> f64 {
    match line {
        [] => f64::INFINITY,
        [only] => dist(p, *only),
        _ => line.windows(2).map(|w| dist_to_segment(p, w[0], w[1])).fold(f64::INFINITY, f64::min),
    }
}

/// The polygon's area (positive either way round).
pub(crate) fn area(polygon: &[[f64; 2]]) -> f64 {
    edges(polygon).map(|(a, b)| a[0] * b[1] - b[0] * a[1]).sum::<f64>().abs() / 2.0
}

/// `y.atan2(x)`, bit for bit, without libm when a side is zero (a drone moving along an
/// axis, as a sweep's legs do): then the result is one of ±0, ±π/2, ±π (C99 Annex F).
fn atan2(y: f64, x: f64) -> f64 {
    if y == 0.0 && !x.is_nan() {
        if x > 0.0 || (x == 0.0 && x.is_sign_positive()) {
            y
        } else {
            std::f64::consts::PI.copysign(y)
        }
    } else if x == 0.0 && !y.is_nan() {
        std::f64::consts::FRAC_PI_2.copysign(y)
    } else {
        y.atan2(x)
    }
}

/// Degrees clockwise from north of a ground velocity.
pub(crate) fn heading(vx: f64, vy: f64) -> f64 {
    let h = atan2(vx, vy).to_degrees();
    if h < 0.0 {
        h + 360.0
    } else {
        h
    }
}

/// A non-convex polygon for tests: an L, 100 m on its long sides.
#[cfg(test)]
pub(crate) const L_SHAPE: [[f64; 2]; 6] =
    [[0.0, 0.0], [100.0, 0.0], [100.0, 40.0], [40.0, 40.0], [40.0, 100.0], [0.0, 100.0]];

#[cfg(test)]
mod tests {
    use super::*;

    const L: [[f64; 2]; 6] = L_SHAPE;

    #[test]
    fn containment_and_segments() {
        assert!(contains(&L, [10.0, 90.0]));
        assert!(!contains(&L, [90.0, 90.0]));
        assert!(contains(&L, [100.0, 20.0]), "the boundary is inside");
        assert!(segment_inside(&L, [10.0, 10.0], [90.0, 10.0]));
        assert!(!segment_inside(&L, [10.0, 90.0], [90.0, 10.0]), "cuts across the notch");
        assert!(segment_inside(&L, [0.0, 0.0], [100.0, 0.0]), "along an edge");
        assert!(circle_inside(&L, [20.0, 20.0], 20.0));
        assert!(!circle_inside(&L, [20.0, 20.0], 21.0));
        assert_eq!(area(&L), 100.0 * 40.0 + 40.0 * 60.0);
        assert_eq!(
            aviary_api::centroid(&[[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]),
            [1.0, 1.0]
        );
    }

    #[test]
    fn atan2_is_libms_bit_for_bit() {
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
            -7e-320,
        ];
        for y in xs {
            for x in xs {
                let (a, b) = (atan2(y, x), y.atan2(x));
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "{y} {x}: {a} {b}"
                );
            }
        }
    }

    #[test]
    fn headings() {
        assert_eq!(heading(0.0, 1.0), 0.0);
        assert_eq!(heading(1.0, 0.0), 90.0);
        assert_eq!(heading(0.0, -1.0), 180.0);
        assert_eq!(heading(-1.0, 0.0), 270.0);
    }
}
