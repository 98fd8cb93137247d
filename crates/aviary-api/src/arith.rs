//! Arithmetic on values (docs/LANGUAGE.md, section 3): a position moved by an offset in
//! metres (`where + (20m, 0m)`), a point at a distance and bearing (`OFFSET`), the
//! midpoint of two positions (`MIDPOINT`), and sums of quantities of one kind. One
//! definition for the compiler (which folds what is constant), the engine and the
//! pre-flight plan, so the three agree to the bit. Local metres: x east, y north, z up;
//! a `GEO(...)` position has already been placed by [`crate::geo`]'s projection.

use crate::{centroid, Point, Value};

/// Where a value stands on the map: a position, or an area's centroid (without height).
/// A drone's position is the caller's to read (telemetry), so it is not handled here.
pub fn point_of(v: &Value) -> Option<Point> {
    match v {
        Value::Position(p) => Some(*p),
        Value::Area(poly) => {
            let [x, y] = centroid(poly);
            Some(Point::flat(x, y))
        }
        _ => None,
    }
}

/// `p + by` (`sign` 1) or `p - by` (`sign` -1): `by` is (east, north[, up]) in metres.
/// Heights add where `p` has one; a position without a height counts as on the ground
/// (0 m) when the offset has an up part, and stays without one when it has none.
pub fn shift(p: Point, by: Point, sign: f64) -> Point {
    let z = match (p.z, by.z) {
        (Some(z), Some(dz)) => Some(z + sign * dz),
        (None, Some(dz)) => Some(sign * dz),
        (z, None) => z,
    };
    Point { x: p.x + sign * by.x, y: p.y + sign * by.y, z }
}

/// The point `distance` metres from `p` over the ground, towards `bearing` degrees
/// clockwise from north (90 is east); its height is `p`'s.
pub fn offset(p: Point, distance: f64, bearing: f64) -> Point {
    let (sin, cos) = bearing.to_radians().sin_cos();
    // To the nanometre: 90deg is due east, not 1e-13 m north of it (which a message
    // would show).
    let nano = |v: f64| (v * 1e9).round() / 1e9;
    Point { x: p.x + nano(distance * sin), y: p.y + nano(distance * cos), z: p.z }
}

/// Halfway between `a` and `b`; at the mean height when both have one, else without.
pub fn midpoint(a: Point, b: Point) -> Point {
    let z = match (a.z, b.z) {
        (Some(za), Some(zb)) => Some((za + zb) / 2.0),
        _ => None,
    };
    Point { x: (a.x + b.x) / 2.0, y: (a.y + b.y) / 2.0, z }
}

/// `a + b` (`sign` 1) or `a - b` (`sign` -1) on two values: two numbers (quantities of
/// one kind, in SI), or a position (or an area's centroid) and an offset. `None` when
/// the values are of no such kinds (the checker refuses those before flight).
pub fn add(a: &Value, b: &Value, sign: f64) -> Option<Value> {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => Some(Value::Number(x + sign * y)),
        (a, Value::Position(by)) => Some(Value::Position(shift(point_of(a)?, *by, sign))),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn near(a: Point, b: Point) -> bool {
        (a.x - b.x).abs() < 1e-9 && (a.y - b.y).abs() < 1e-9 && a.z == b.z
    }

    #[test]
    fn bearings_are_clockwise_from_north() {
        let home = Point::flat(100.0, 50.0);
        assert!(near(offset(home, 20.0, 0.0), Point::flat(100.0, 70.0)));
        assert!(near(offset(home, 20.0, 90.0), Point::flat(120.0, 50.0)));
        assert!(near(offset(home, 20.0, 180.0), Point::flat(100.0, 30.0)));
        assert!(near(offset(home, 20.0, 270.0), Point::flat(80.0, 50.0)));
    }

    #[test]
    fn an_offset_adds_metres_and_heights() {
        let p = Point { x: 1.0, y: 2.0, z: Some(30.0) };
        let by = Point { x: 20.0, y: -5.0, z: Some(10.0) };
        assert_eq!(shift(p, by, 1.0), Point { x: 21.0, y: -3.0, z: Some(40.0) });
        assert_eq!(shift(p, by, -1.0), Point { x: -19.0, y: 7.0, z: Some(20.0) });
        assert_eq!(shift(Point::flat(0.0, 0.0), by, 1.0).z, Some(10.0));
        assert_eq!(shift(p, Point::flat(1.0, 1.0), 1.0).z, Some(30.0));
        let sum = add(&Value::Number(3.0), &Value::Number(2.0), -1.0);
        assert_eq!(sum, Some(Value::Number(1.0)));
        assert_eq!(add(&Value::Number(3.0), &Value::Text("x".into()), 1.0), None);
    }

    mod laws {
        use super::super::*;
        use proptest::prelude::*;

        fn point() -> impl Strategy<Value = Point> {
            (-5000.0..5000.0f64, -5000.0..5000.0f64, prop::option::of(0.0..120.0f64))
                .prop_map(|(x, y, z)| Point { x, y, z })
        }

        fn ground(a: Point, b: Point) -> f64 {
            (a.x - b.x).hypot(a.y - b.y)
        }

        proptest! {
            /// `OFFSET(p, d, b)` is `d` from `p` over the ground, for every bearing, at
            /// `p`'s height; going back on the opposite bearing returns to `p`.
            #[test]
            fn an_offset_is_its_distance_away(p in point(), d in 0.0..2000.0f64, b in -720.0..720.0f64) {
                let q = offset(p, d, b);
                prop_assert!((ground(p, q) - d).abs() < 1e-6);
                prop_assert_eq!(q.z, p.z);
                let back = offset(q, d, b + 180.0);
                prop_assert!(ground(back, p) < 1e-6);
            }

            /// `MIDPOINT(a, b)` is as far from `a` as from `b`, half the way.
            #[test]
            fn a_midpoint_is_equidistant(a in point(), b in point()) {
                let m = midpoint(a, b);
                prop_assert!((ground(a, m) - ground(m, b)).abs() < 1e-6);
                prop_assert!((2.0 * ground(a, m) - ground(a, b)).abs() < 1e-6);
            }

            /// Moving by an offset and back by it returns to the start.
            #[test]
            fn plus_then_minus_is_nothing(p in point(), by in point()) {
                let there = shift(shift(p, by, 1.0), by, -1.0);
                prop_assert!(ground(there, p) < 1e-6);
                if let (Some(z), Some(back)) = (p.z, there.z) {
                    prop_assert!((z - back).abs() < 1e-6);
                }
            }
        }
    }
}
