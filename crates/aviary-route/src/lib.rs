//! The route planner around the world's no-fly zones (docs/WORLD.md, `[no_fly.NAME]`),
//! written once for everything that needs a drone's way from one point to another: the
//! simulator flies it, the MAVLink backend sends it as waypoints, the checker asks whether
//! there is one, and the plan costs it.
//!
//! The method: each zone is grown by [`MARGIN`] on every side ([`geo`]'s buffer, round
//! corners); the corners of the grown zones (and of the geofence, which a route keeps
//! inside) are the nodes of a visibility graph, two nodes joined when the straight line
//! between them passes through no grown zone and does not leave the fence; A*
//! ([`pathfinding`]) finds the shortest way through it from the start to the goal. That is
//! the shortest path that keeps the margin (shortest paths among polygons bend only at
//! their corners), up to the round corners' sides, which cut inside the margin by at most
//! 0.5% of it.
//!
//! Invariants:
//! - A transit that no zone is in the way of is the straight line, unchanged (`[to]`):
//!   a world without zones flies as it did before zones existed.
//! - A route never passes through the inside of a zone that holds at its height, nor
//!   through the grown zone, except where an end of it lies in that zone's margin (a place
//!   closer to the zone than the margin): the pieces from and to such an end keep out of
//!   the zone itself. Only a zone makes a detour, and a detour stays inside the
//!   geofence (when it starts inside): a straight line that no zone is in the way of is
//!   returned as it is, even where it leaves the fence, for the backends to refuse as in
//!   a world without zones.
//! - Pure and deterministic: no IO, no randomness, no panic; the same airspace and query
//!   give the same route.

#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod graph;
mod shape;

use std::sync::OnceLock;

use aviary_api::geometry::{contains, dist};
use aviary_api::show::fixed;
use aviary_world::World;

use shape::{grow, Outline};

/// Metres a planned route keeps from every no-fly zone: room for a drone that does not
/// fly its line exactly (wind, GPS, a controller that cuts a corner). The one figure,
/// used by every backend, the checker and the plan; docs/WORLD.md gives it.
pub const MARGIN: f64 = 10.0;

/// Metres: a route's waypoints are this close to each other at least (a corner the
/// search would turn at twice is one waypoint).
const SAME_POINT: f64 = 1e-6;

/// Why a transit cannot be routed. `zone` is an index into the world's `no_fly`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Blocked {
    /// An end of the transit is inside the zone (its line counts as inside): `start` for
    /// the point it leaves from, else the point it goes to.
    Inside { zone: usize, start: bool },
    /// The straight line crosses the zone, and no way around it stays in the geofence.
    NoWay { zone: usize },
}

/// One zone as the planner holds it.
#[derive(Debug)]
struct Zone {
    outline: Outline,
    grown: Outline,
    up_to: Option<f64>,
}

impl Zone {
    fn holds_at(&self, z: f64) -> bool {
        self.up_to.is_none_or(|top| z <= top)
    }
}

/// The world's geofence and no-fly zones, ready to route through. Build it once per
/// world ([`Airspace::of`]): growing the zones and the visibility graph (made on first
/// use, per set of zones that hold at a height) is the costly part.
#[derive(Debug)]
pub struct Airspace {
    fence: Option<Outline>,
    /// The zones' names, for messages.
    names: Vec<String>,
    zones: Vec<Zone>,
    /// The `up_to` heights, ascending, each once: flights between two of them meet the
    /// same zones.
    levels: Vec<f64>,
    /// One graph per band of heights (`levels.len() + 1` of them), made when first needed.
    graphs: Vec<OnceLock<graph::Graph>>,
}

impl Airspace {
    /// The airspace of a world: its geofence and its `[no_fly]` zones, in file order.
    pub fn of(world: &World) -> Airspace {
        let zones = world.no_fly.iter().map(|z| (z.polygon.as_slice(), z.up_to));
        let mut space = Airspace::new(world.site.geofence.as_deref(), zones, MARGIN);
        space.names = world.no_fly.iter().map(|z| z.name.clone()).collect();
        space
    }

    /// An airspace of `zones` (corners, `up_to`), grown by `margin`, inside `fence`.
    pub fn new<'a>(
        fence: Option<&[[f64; 2]]>,
        zones: impl IntoIterator<Item = (&'a [[f64; 2]], Option<f64>)>,
        margin: f64,
    ) -> Airspace {
        let zones: Vec<Zone> = zones
            .into_iter()
            .map(|(corners, up_to)| Zone {
                outline: Outline::new(corners.to_vec()),
                grown: Outline::new(grow(corners, margin)),
                up_to,
            })
            .collect();
        let mut levels: Vec<f64> = zones.iter().filter_map(|z| z.up_to).collect();
        levels.sort_by(f64::total_cmp);
        levels.dedup();
        let graphs = (0..=levels.len()).map(|_| OnceLock::new()).collect();
        let names = (1..=zones.len()).map(|i| format!("zone {i}")).collect();
        Airspace { fence: fence.map(|f| Outline::new(f.to_vec())), names, zones, levels, graphs }
    }

    /// Zone `zone`'s name (the `NAME` of `[no_fly.NAME]`).
    pub fn name(&self, zone: usize) -> &str {
        self.names.get(zone).map_or("", String::as_str)
    }

    /// Zone `zone`'s `up_to`: `None` when it holds at every height.
    pub fn up_to(&self, zone: usize) -> Option<f64> {
        self.zones.get(zone).and_then(|z| z.up_to)
    }

    /// Whether there are no zones: every transit is then the straight line.
    pub fn is_open(&self) -> bool {
        self.zones.is_empty()
    }

    /// The zone (its index) that point `p` at height `z` is in, if any; a zone's line
    /// counts as in it.
    pub fn zone_at(&self, p: [f64; 2], z: f64) -> Option<usize> {
        self.zones.iter().position(|zone| zone.holds_at(z) && contains(&zone.outline.corners, p))
    }

    /// The highest `up_to` of the zones, if any holds only up to a height: no flight
    /// below it may be sure to be clear of every zone.
    pub fn highest_up_to(&self) -> Option<f64> {
        self.levels.last().copied()
    }

    /// The way from `from` to `to` over the ground for a flight whose lowest height on
    /// the way is `low` (zones whose `up_to` is below it are flown over): the points to
    /// fly through after `from`, `to` last. `[to]` when the straight line is clear.
    pub fn route(&self, from: [f64; 2], to: [f64; 2], low: f64) -> Result<Vec<[f64; 2]>, Blocked> {
        if self.zones.is_empty() {
            return Ok(vec![to]);
        }
        let band = self.band(low);
        let held: Vec<usize> = (0..self.zones.len()).filter(|&i| self.holds(i, band)).collect();
        if let Some(zone) = held.iter().copied().find(|&i| self.in_zone(i, from)) {
            return Err(Blocked::Inside { zone, start: true });
        }
        if let Some(zone) = held.iter().copied().find(|&i| self.in_zone(i, to)) {
            return Err(Blocked::Inside { zone, start: false });
        }
        let fenced = self.fence.as_ref().is_some_and(|f| contains(&f.corners, from));
        // Only a zone makes a detour: a straight line that no zone is in the way of is
        // the transit, whatever the fence says (the backends refuse what leaves it, as
        // in a world without zones), and so is one to a point outside the fence.
        let ends = graph::Ends::new(self, &held, from, to, false);
        let outside = fenced && self.fence.as_ref().is_some_and(|f| !contains(&f.corners, to));
        if outside || ends.clear(from, to) {
            return Ok(vec![to]);
        }
        let ends = graph::Ends::new(self, &held, from, to, fenced);
        let graph = self.graphs[band].get_or_init(|| graph::Graph::new(self, &held));
        match graph.search(&ends) {
            Some(way) => Ok(taut(from, way)),
            None => {
                let zone = held
                    .iter()
                    .copied()
                    .find(|&i| self.zones[i].outline.crossed_by(from, to))
                    .or_else(|| {
                        held.iter().copied().find(|&i| self.zones[i].grown.crossed_by(from, to))
                    })
                    .unwrap_or(held.first().copied().unwrap_or(0));
                Err(Blocked::NoWay { zone })
            }
        }
    }

    /// The zone that a path flown straight from point to point (at heights no lower than
    /// `low`) enters, if any: for a path a mission asks for itself (a sweep's lanes),
    /// which is not routed around. Touching a zone's line is not entering it.
    pub fn path_enters(&self, from: [f64; 2], path: &[[f64; 2]], low: f64) -> Option<usize> {
        let mut prev = from;
        for &p in std::iter::once(&from).chain(path) {
            let hit = (0..self.zones.len()).find(|&i| {
                let z = &self.zones[i];
                z.holds_at(low) && (z.outline.holds(p) || z.outline.crossed_by(prev, p))
            });
            if hit.is_some() {
                return hit;
            }
            prev = p;
        }
        None
    }

    /// The zone that the circle of `radius` around `center` (its line: the way an orbit
    /// flies) enters at height `z`, if any. A zone wholly inside the circle is not
    /// entered: an orbit may circle a zone.
    pub fn circle_enters(&self, center: [f64; 2], radius: f64, z: f64) -> Option<usize> {
        self.zones.iter().position(|zone| {
            let c = &zone.outline.corners;
            let near = if zone.outline.holds(center) {
                0.0
            } else {
                aviary_api::geometry::dist_to_boundary(c, center)
            };
            let far = c.iter().map(|p| dist(*p, center)).fold(0.0, f64::max);
            zone.holds_at(z) && near < radius - shape::ON_LINE && radius < far - shape::ON_LINE
        })
    }

    /// The zone that a sweep enters at height `z`, if any: its `area` overlaps the zone,
    /// or its `lanes` (the lawnmower path, which reaches a little past a slanted side)
    /// cross it. A sweep is the mission's own path: it is not routed around.
    pub fn sweep_enters(&self, area: &[[f64; 2]], lanes: &[[f64; 2]], z: f64) -> Option<usize> {
        let lanes_enter = || match lanes.split_first() {
            Some((first, rest)) => self.path_enters(*first, rest, z),
            None => None,
        };
        self.area_overlaps(area, z).or_else(lanes_enter)
    }

    /// The zone that an area overlaps (their insides meet) at height `z`, if any.
    pub fn area_overlaps(&self, area: &[[f64; 2]], z: f64) -> Option<usize> {
        let outline = Outline::new(area.to_vec());
        self.zones.iter().position(|zone| {
            let c = &zone.outline.corners;
            zone.holds_at(z)
                && (c.iter().any(|p| outline.holds(*p))
                    || area.iter().any(|p| zone.outline.holds(*p))
                    || aviary_api::geometry::edges(area)
                        .any(|(a, b)| zone.outline.crossed_by(a, b))
                    || aviary_api::geometry::edges(c).any(|(a, b)| outline.crossed_by(a, b)))
        })
    }

    /// A zone as a refusal names it: "the no-fly zone `Fire` (up to 40.0 m)".
    pub fn describe(&self, zone: usize) -> String {
        let name = self.name(zone);
        match self.up_to(zone) {
            Some(top) => format!("the no-fly zone `{name}` (up to {} m)", fixed(top, 1)),
            None => format!("the no-fly zone `{name}`"),
        }
    }

    /// Why a transit from `from` to `to` (local metres, z the height) was `blocked`, as a
    /// backend's refusal says it (`GeofenceViolation`): the simulator and the MAVLink
    /// backend say the same.
    pub fn refusal(&self, blocked: Blocked, from: [f64; 3], to: [f64; 3]) -> String {
        let (a, b) = ([from[0], from[1]], [to[0], to[1]]);
        match blocked {
            Blocked::Inside { zone, start: true } => {
                format!("{} is inside {}", at(a), self.describe(zone))
            }
            Blocked::Inside { zone, start: false } if self.zone_at(b, to[2]).is_none() => format!(
                "{} at {} m is above {}, but the way there from {} m would pass through it: climb above it first",
                at(b),
                fixed(to[2], 1),
                self.describe(zone),
                fixed(from[2], 1)
            ),
            Blocked::Inside { zone, start: false } => {
                format!("{} is inside {}", at(b), self.describe(zone))
            }
            Blocked::NoWay { zone } => format!(
                "there is no way from {} to {} around {} inside the geofence",
                at(a),
                at(b),
                self.describe(zone)
            ),
        }
    }

    /// A move straight up or down at `p` (z its height now) to height `z`: the refusal
    /// when it would come down into a zone.
    pub fn vertical_refusal(&self, p: [f64; 3], z: f64) -> Option<String> {
        let xy = [p[0], p[1]];
        let zone = self.zone_at(xy, z.min(p[2]))?;
        Some(format!(
            "coming down to {} m at {} enters {}",
            fixed(z, 1),
            at(xy),
            self.describe(zone)
        ))
    }

    /// An orbit's circle: the refusal when it enters a zone at height `z`.
    pub fn circle_refusal(&self, center: [f64; 2], radius: f64, z: f64) -> Option<String> {
        let zone = self.circle_enters(center, radius, z)?;
        Some(format!(
            "a circle of {} m around {} enters {}",
            fixed(radius, 1),
            at(center),
            self.describe(zone)
        ))
    }

    /// A sweep: the refusal when its area or lanes enter a zone at height `z`.
    pub fn sweep_refusal(&self, area: &[[f64; 2]], lanes: &[[f64; 2]], z: f64) -> Option<String> {
        let zone = self.sweep_enters(area, lanes, z)?;
        Some(format!("the area swept enters {}", self.describe(zone)))
    }

    /// The band of heights `z` lies in: how many `up_to` levels are below it.
    fn band(&self, z: f64) -> usize {
        self.levels.partition_point(|&level| level < z)
    }

    /// Whether zone `i` holds in band `band` (the band's heights are above the levels
    /// below it and up to the next).
    fn holds(&self, i: usize, band: usize) -> bool {
        self.zones[i].up_to.is_none_or(|top| self.band(top) >= band)
    }

    /// Strictly inside zone `i`, or on its line.
    fn in_zone(&self, i: usize, p: [f64; 2]) -> bool {
        contains(&self.zones[i].outline.corners, p)
    }
}

/// A point as a refusal shows it: `(12.0, -3.5)`.
fn at(p: [f64; 2]) -> String {
    format!("({}, {})", fixed(p[0], 1), fixed(p[1], 1))
}

/// The way without its needless points: one the search turned at twice, and one on the
/// straight line between its neighbours (two zones' sides in line).
fn taut(from: [f64; 2], way: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::with_capacity(way.len());
    for p in way {
        if dist(out.last().copied().unwrap_or(from), p) <= SAME_POINT {
            continue;
        }
        let before = if out.len() >= 2 { out[out.len() - 2] } else { from };
        if let Some(&last) = out.last() {
            if aviary_api::geometry::dist_to_segment(last, before, p) <= SAME_POINT {
                out.pop();
            }
        }
        out.push(p);
    }
    out
}

#[cfg(test)]
mod tests;
