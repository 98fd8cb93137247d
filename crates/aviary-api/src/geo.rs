//! Geodetic ↔ local conversion about the world's `origin`: the one projection of the
//! project, used by `GEO(...)` (compiled or evaluated at run time, and by the plan) and by
//! the MAVLink backend, so a place written as `GEO(lat, lon)` and the position a vehicle
//! reports agree.
//!
//! An equirectangular projection: exact enough for a mission site, under 0.1% of the
//! distance within 10 km of the origin. Heights are relative: local z is metres above the
//! origin's altitude, which is the ground of the site and, for a vehicle, its home
//! (MAVLink's `relative_alt`).

const EARTH_RADIUS: f64 = 6_371_000.0;

/// The world's origin: latitude and longitude in degrees, altitude in metres above sea level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Origin {
    pub lat: f64,
    pub lon: f64,
    pub alt: f64,
}

impl Origin {
    /// Degrees of latitude and longitude → local `[x, y]` metres (x east, y north).
    pub fn to_local(&self, lat: f64, lon: f64) -> [f64; 2] {
        let x = (lon - self.lon).to_radians() * EARTH_RADIUS * self.lat.to_radians().cos();
        let y = (lat - self.lat).to_radians() * EARTH_RADIUS;
        [x, y]
    }

    /// `GEO(lat, lon[, alt])`: degrees and metres above sea level → local `[x, y, z]`;
    /// z is NaN when no altitude is given.
    pub fn place(&self, lat: f64, lon: f64, alt: Option<f64>) -> [f64; 3] {
        let [x, y] = self.to_local(lat, lon);
        [x, y, alt.map_or(f64::NAN, |a| a - self.alt)]
    }

    /// Local `[x, y]` metres → `(lat, lon)` degrees.
    pub fn to_geodetic(&self, x: f64, y: f64) -> (f64, f64) {
        let lat = self.lat + (y / EARTH_RADIUS).to_degrees();
        let lon = self.lon + (x / (EARTH_RADIUS * self.lat.to_radians().cos())).to_degrees();
        (lat, lon)
    }

    /// Degrees of latitude and of longitude per metre north and east: the projection is
    /// linear, `to_geodetic(x, y)` = (lat + y · these.0, lon + x · these.1) but for rounding,
    /// so a map that places local points on the Earth needs only these and the origin.
    pub fn degrees_per_metre(&self) -> (f64, f64) {
        let north = (1.0 / EARTH_RADIUS).to_degrees();
        let east = (1.0 / (EARTH_RADIUS * self.lat.to_radians().cos())).to_degrees();
        (north, east)
    }

    /// Local `[x, y]` → MAVLink's degrees × 10⁷.
    pub fn to_e7(&self, x: f64, y: f64) -> (i32, i32) {
        let (lat, lon) = self.to_geodetic(x, y);
        ((lat * 1e7).round() as i32, (lon * 1e7).round() as i32)
    }

    /// MAVLink's degrees × 10⁷ → local `[x, y]`.
    pub fn from_e7(&self, lat: i32, lon: i32) -> [f64; 2] {
        self.to_local(f64::from(lat) / 1e7, f64::from(lon) / 1e7)
    }
}

impl Default for Origin {
    /// A world without `origin`: the local frame sits at 0°N 0°E, sea level, so that a
    /// vehicle still gets coordinates (a real flight needs a real origin; see REAL_DRONES.md).
    fn default() -> Origin {
        Origin { lat: 0.0, lon: 0.0, alt: 0.0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn there_and_back_within_a_centimetre() {
        let o = Origin { lat: 46.6167, lon: 14.2650, alt: 440.0 };
        for p in [[0.0, 0.0], [350.0, -450.0], [-600.0, 600.0], [5000.0, 2000.0]] {
            let (lat, lon) = o.to_e7(p[0], p[1]);
            let q = o.from_e7(lat, lon);
            assert!((q[0] - p[0]).abs() < 0.01 && (q[1] - p[1]).abs() < 0.01, "{p:?} -> {q:?}");
        }
    }

    #[test]
    fn a_place_is_above_the_origins_altitude_and_east_shrinks_with_latitude() {
        let o = Origin { lat: 46.6167, lon: 14.2650, alt: 440.0 };
        assert!((o.place(46.6167, 14.2650, Some(460.0))[2] - 20.0).abs() < 1e-9);
        let north = Origin { lat: 60.0, lon: 10.0, alt: 0.0 };
        let p = north.place(60.0, 10.001, None);
        assert!((p[0] - 55.6).abs() < 0.1, "{}", p[0]);
        assert!(p[2].is_nan());
    }

    #[test]
    fn one_thousandth_degree_north_is_about_111_metres() {
        let o = Origin { lat: 46.6167, lon: 14.2650, alt: 440.0 };
        let p = o.to_local(46.6177, 14.2650);
        assert!(p[0].abs() < 1e-9);
        assert!((p[1] - 111.19).abs() < 0.01, "{}", p[1]);
    }
}
