//! Where a position an operator sends may be: inside the site's geofence, at or under its
//! `max_altitude`, and outside every no-fly zone that holds at its height. A position
//! beyond one of them is refused (400) with the limit and by how much, before the mission
//! hears it: accepted, it would fail the whole mission later (`GeofenceViolation`).
//!
//! The tests are the world's own: `Site::in_geofence` for the fence, and the route
//! planner's `Airspace::zone_at` for the zones, which every backend and the checker use.
//! A position without a height inside a zone that holds only up to a height is refused,
//! as the checker refuses it (E128): the height the drone will keep is not known.

use aviary_api::geometry::dist_to_boundary;
use aviary_api::show::fixed;
use aviary_api::Point;
use aviary_route::Airspace;
use aviary_world::{NoFly, Site, World};

/// A world's limits on where a drone may be sent.
#[derive(Debug)]
pub struct Bounds {
    site: Site,
    no_fly: Vec<NoFly>,
    airspace: Airspace,
}

impl Bounds {
    /// The limits of `world`: its `[site]`'s geofence and `max_altitude`, its `[no_fly]`.
    pub fn of(world: &World) -> Bounds {
        Bounds {
            site: world.site.clone(),
            no_fly: world.no_fly.clone(),
            airspace: Airspace::of(world),
        }
    }

    /// Why a drone may not be sent to `p` (local metres, z the height), shown to the
    /// operator as `shown`; `None` when it may.
    pub(crate) fn refusal(&self, p: Point, shown: &str) -> Option<String> {
        let xy = [p.x, p.y];
        if let (Some(z), Some(max)) = (p.z, self.site.max_altitude) {
            if z > max + 1e-9 {
                return Some(format!(
                    "{shown} is {} m above the site's max_altitude of {} m: give a height of at most {} m",
                    fixed(z - max, 1),
                    fixed(max, 1),
                    fixed(max, 1)
                ));
            }
        }
        if let Some(fence) = self.site.geofence.as_deref().filter(|_| !self.site.in_geofence(xy)) {
            return Some(format!(
                "{shown} is outside the geofence, {} m beyond its nearest side: choose a position inside it",
                fixed(dist_to_boundary(fence, xy), 1)
            ));
        }
        // Without a height, the lowest: a zone that holds up to a height may hold where
        // the drone will be.
        let zone = self.airspace.zone_at(xy, p.z.unwrap_or(0.0))?;
        let inside = self.no_fly.get(zone).map_or(0.0, |z| dist_to_boundary(&z.polygon, xy));
        let leave = "choose a position outside it (a flight is routed around a zone, not into it)";
        let what = self.airspace.describe(zone);
        let why = match (self.airspace.up_to(zone), p.z) {
            (Some(top), Some(z)) => format!(
                "{shown} is inside {what}, {} m from its nearest side and {} m below its top: {leave}, or give a height above {} m",
                fixed(inside, 1),
                fixed(top - z, 1),
                fixed(top, 1)
            ),
            (Some(top), None) => format!(
                "{shown} is inside {what}, {} m from its nearest side, and has no height to pass above it: {leave}, or give a height above {} m, e.g. [{}, {}, {}]",
                fixed(inside, 1),
                fixed(top, 1),
                fixed(p.x, 1),
                fixed(p.y, 1),
                (top + 10.0).ceil()
            ),
            (None, _) => {
                format!("{shown} is inside {what}, {} m from its nearest side: {leave}", fixed(inside, 1))
            }
        };
        Some(why)
    }
}
