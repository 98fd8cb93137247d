//! Geodetic coordinates to the world's local frame.
//!
//! An equirectangular projection about the world's `origin`: exact enough for a mission
//! site (the error is under 0.1% within 10 km of the origin), and the same formula the
//! MAVLink backend uses the other way round.

const EARTH_RADIUS: f64 = 6_371_000.0;

/// `(lat, lon[, alt])` in degrees and metres above sea level → local `[x, y, z]`.
pub fn to_local(origin: (f64, f64, f64), lat: f64, lon: f64, alt: Option<f64>) -> [f64; 3] {
    let (lat0, lon0, alt0) = origin;
    let x = (lon - lon0).to_radians() * EARTH_RADIUS * lat0.to_radians().cos();
    let y = (lat - lat0).to_radians() * EARTH_RADIUS;
    [x, y, alt.map_or(f64::NAN, |a| a - alt0)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_thousandth_degree_north_is_about_111_metres() {
        let p = to_local((46.6167, 14.2650, 440.0), 46.6177, 14.2650, Some(460.0));
        assert!((p[0]).abs() < 1e-9);
        assert!((p[1] - 111.19).abs() < 0.01, "{}", p[1]);
        assert!((p[2] - 20.0).abs() < 1e-9);
    }

    #[test]
    fn east_shrinks_with_latitude() {
        let p = to_local((60.0, 10.0, 0.0), 60.0, 10.001, None);
        assert!((p[0] - 55.6).abs() < 0.1, "{}", p[0]);
        assert!(p[2].is_nan());
    }
}
