//! Reading a call's arguments, and the refusals a call can meet before it starts.

use aviary_api::show::fixed;
use aviary_api::{BuiltinException, Failure, Place, Point, Value};

use aviary_route::Airspace;

use crate::geom::{self, circle_inside, contains, segment_inside};

pub(crate) fn failed(reason: impl Into<String>) -> Failure {
    Failure::new(BuiltinException::CommandFailed, reason)
}

pub(crate) fn fence_violation(reason: impl Into<String>) -> Failure {
    Failure::new(BuiltinException::GeofenceViolation, reason)
}

/// A number the call was given, refused when it is not finite.
pub(crate) fn finite(n: f64, name: &str) -> Result<f64, Failure> {
    if n.is_finite() {
        Ok(n)
    } else {
        Err(failed(format!("`{name}` must be a finite number, not {}", Value::Number(n))))
    }
}

pub(crate) fn opt_finite(n: Option<f64>, name: &str) -> Result<Option<f64>, Failure> {
    n.map(|n| finite(n, name)).transpose()
}

/// A position; an area stands for its centroid (at the altitude the drone keeps).
pub(crate) fn point(place: &Place, name: &str) -> Result<Point, Failure> {
    place.point().ok_or_else(|| failed(format!("`{name}` must be a position, not {place}")))
}

/// An area to sweep: at least 3 finite corners, enclosing something.
pub(crate) fn polygon(corners: &[[f64; 2]], name: &str) -> Result<Vec<[f64; 2]>, Failure> {
    if corners.len() >= 3 && corners.iter().all(|c| c[0].is_finite() && c[1].is_finite()) {
        if geom::area(corners) <= 1e-9 {
            return Err(failed(format!("`{name}` encloses no area")));
        }
        return Ok(corners.to_vec());
    }
    Err(failed(format!(
        "`{name}` must be an area of at least 3 corners, not {}",
        Value::Area(corners.to_vec())
    )))
}

/// The site's limits on where a drone may fly.
pub(crate) struct Limits<'a> {
    pub fence: Option<&'a [[f64; 2]]>,
    pub max_altitude: Option<f64>,
    /// The no-fly zones (and the fence again), for the routes of transits.
    pub airspace: &'a Airspace,
}

impl Limits<'_> {
    pub fn altitude(&self, z: f64) -> Result<(), Failure> {
        match self.max_altitude {
            Some(max) if z > max + 1e-9 => Err(fence_violation(format!(
                "altitude {} m is above the site's max_altitude of {} m",
                fixed(z, 1),
                fixed(max, 1)
            ))),
            _ => Ok(()),
        }
    }

    /// A path of straight segments from `from` through `points`: every point within the
    /// altitude limit and the geofence, and no segment leaving the geofence. (The first
    /// segment is not checked when the drone is outside the geofence already.)
    pub fn path(&self, from: [f64; 3], points: &[[f64; 3]]) -> Result<(), Failure> {
        for p in points {
            self.altitude(p[2])?;
        }
        let Some(fence) = self.fence else {
            return Ok(());
        };
        let mut prev = [from[0], from[1]];
        let mut check = contains(fence, prev);
        for p in points {
            let q = [p[0], p[1]];
            if !contains(fence, q) {
                return Err(fence_violation(format!(
                    "({}, {}) is outside the geofence",
                    fixed(q[0], 1),
                    fixed(q[1], 1)
                )));
            }
            if check && !segment_inside(fence, prev, q) {
                return Err(fence_violation(format!(
                    "the way from ({}, {}) to ({}, {}) leaves the geofence",
                    fixed(prev[0], 1),
                    fixed(prev[1], 1),
                    fixed(q[0], 1),
                    fixed(q[1], 1)
                )));
            }
            prev = q;
            check = true;
        }
        Ok(())
    }

    /// The way over the ground from `from` to `to` (aviary-route) around the no-fly zones
    /// that hold at the lower of their heights: the points after `from`, `to` last.
    pub fn route(&self, from: [f64; 3], to: [f64; 3]) -> Result<Vec<[f64; 2]>, Failure> {
        let (a, b) = ([from[0], from[1]], [to[0], to[1]]);
        (self.airspace.route(a, b, from[2].min(to[2])))
            .map_err(|blocked| fence_violation(self.airspace.refusal(blocked, from, to)))
    }

    /// A move straight up or down at `p` to height `z`: refused when it would enter a
    /// zone (coming down into one whose `up_to` is below the drone).
    pub fn vertical(&self, p: [f64; 3], z: f64) -> Result<(), Failure> {
        self.airspace.vertical_refusal(p, z).map_or(Ok(()), |why| Err(fence_violation(why)))
    }

    /// The circle an orbit flies, clear of the zones at height `z`.
    pub fn orbit_clear(&self, center: [f64; 2], radius: f64, z: f64) -> Result<(), Failure> {
        (self.airspace.circle_refusal(center, radius, z))
            .map_or(Ok(()), |why| Err(fence_violation(why)))
    }

    /// A sweep's area and lanes, clear of the zones at height `z`.
    pub fn sweep_clear(
        &self,
        area: &[[f64; 2]],
        lanes: &[[f64; 2]],
        z: f64,
    ) -> Result<(), Failure> {
        (self.airspace.sweep_refusal(area, lanes, z))
            .map_or(Ok(()), |why| Err(fence_violation(why)))
    }

    pub fn circle(&self, center: [f64; 2], radius: f64) -> Result<(), Failure> {
        match self.fence {
            Some(fence) if !circle_inside(fence, center, radius) => Err(fence_violation(format!(
                "a circle of {} m around ({}, {}) leaves the geofence",
                fixed(radius, 1),
                fixed(center[0], 1),
                fixed(center[1], 1)
            ))),
            _ => Ok(()),
        }
    }
}
