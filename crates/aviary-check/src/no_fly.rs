//! No-fly zones before flight (E128; docs/LANGUAGE.md, section 22), on the geofence's walk
//! (`geofence.rs`), which follows values and drones from each mission statement into the
//! capabilities it calls.
//!
//! What cannot be routed around is an error: a position flown to (a place, an area's
//! centre, coordinates, a path's point) inside a zone, an orbit's circle that enters one, a
//! sweep whose area or lanes overlap one, and a position that the drone cannot reach from
//! its home around the zones inside the geofence. A flight *across* a zone is not: it is
//! routed around, by the planner the backends fly (`aviary_route`).
//!
//! Heights: a zone with `up_to` holds up to that height. A position's own height counts
//! where it is written (`(x, y, 70m)`, a place with z). Where it is not, the checker does
//! not know the drone's altitude: a position without a height in such a zone is an error
//! (the help says to write the height meant), while what cannot be given a height (an
//! orbit's circle, a sweep's area, whether a position can be reached) is checked against
//! the zones that hold at every height only, the others being checked in flight. So every
//! E128 is true, and each one can be answered in the mission.

use std::collections::HashMap;

use aviary_api::show::number;

use aviary_diagnostics::{Code, FileId, Span};
use aviary_route::{Airspace, Blocked};
use aviary_syntax::ast::{ApiCall, Capability, Statement};
use aviary_world::World;

use crate::geofence::{ground, shown, Known, Values, Walker};

/// The world's zones, ready to route through, and the answers already found.
pub(crate) struct Zones {
    space: Airspace,
    /// Whether a drone from a home reaches a point at a height: by the three's bits.
    reached: HashMap<([u64; 2], [u64; 2], u64), Option<Blocked>>,
}

impl Zones {
    pub fn of(world: &World) -> Option<Zones> {
        (!world.no_fly.is_empty())
            .then(|| Zones { space: Airspace::of(world), reached: HashMap::new() })
    }

    fn reach(&mut self, home: [f64; 2], to: [f64; 2], z: f64) -> Option<Blocked> {
        let key = (
            [home[0].to_bits(), home[1].to_bits()],
            [to[0].to_bits(), to[1].to_bits()],
            z.to_bits(),
        );
        let space = &self.space;
        *self.reached.entry(key).or_insert_with(|| space.route(home, to, z).err())
    }

    /// A height above every zone that holds only up to a height: where a flight whose
    /// height is not known is checked against the zones that hold at every height only.
    fn above_limited(&self) -> f64 {
        self.space.highest_up_to().map_or(0.0, |top| top + 1.0)
    }

    /// "the no-fly zone `Fire` (up to 60 m)".
    fn named(&self, zone: usize) -> String {
        let name = self.space.name(zone);
        match self.space.up_to(zone) {
            Some(top) => format!("the no-fly zone `{name}` (up to {} m)", number(top)),
            None => format!("the no-fly zone `{name}`"),
        }
    }
}

/// The help for a position in a zone: leave the zone, or, if it holds only up to a
/// height, fly above it.
fn help_inside(up_to: Option<f64>, p: [f64; 2]) -> String {
    let leave =
        "choose a position outside the zone (a flight is routed around a zone, not into it)";
    match up_to {
        Some(top) => format!(
            "{leave}, or give the position a height above the zone's {} m, e.g. `({}, {}, {}m)`",
            number(top),
            number(p[0]),
            number(p[1]),
            number((top + 10.0).ceil())
        ),
        None => leave.to_owned(),
    }
}

impl Walker<'_, '_> {
    /// The drones an actor's name stands for: an alias or a parameter bound on the way, a
    /// drone, or a group. Followed only in a world with zones, which alone needs them.
    pub(crate) fn actor(&self, name: &str, values: &Values) -> Option<Known> {
        self.zones.as_ref()?;
        match values.get(name) {
            Some(Known::Drones(d)) => Some(Known::Drones(d.clone())),
            Some(_) => None,
            None => self.actors.drones(name).map(|d| Known::Drones(d.to_vec())),
        }
    }

    /// Binds the capability's `BY` parameters to the drones of the statement's actors:
    /// all of them to a capability of one actor (each drone runs it), one each, in order,
    /// to one of several. Left unbound when an actor is not known.
    pub(crate) fn bind_actors(
        &self,
        callee: &Capability,
        s: &Statement,
        values: &Values,
        inner: &mut Values,
    ) {
        if self.zones.is_none() {
            return;
        }
        let mut each = Vec::new();
        for a in &s.actors {
            match self.actor(&a.name, values) {
                Some(Known::Drones(d)) => each.push(d),
                _ => return,
            }
        }
        let all: Vec<usize> = each.concat();
        match callee.actors.as_slice() {
            [one] => {
                inner.insert(one.name.clone(), Known::Drones(all));
            }
            many if many.len() == all.len() => {
                for (p, d) in many.iter().zip(all) {
                    inner.insert(p.name.clone(), Known::Drones(vec![d]));
                }
            }
            _ => {}
        }
    }

    /// A position flown to (`FlyToPosition`, a point of `FollowPath`): not in a zone at its
    /// height, and reachable from the home of each drone that flies it. `kept`: the height
    /// a point without one keeps, when known.
    pub(crate) fn zone_point(
        &mut self,
        k: &Known,
        kept: Option<f64>,
        call: &ApiCall,
        values: &Values,
        site: Option<(FileId, Span)>,
        file: FileId,
    ) {
        let Some(zones) = &self.zones else { return };
        let Some(p) = ground(k) else { return };
        // What the checker knows of a value, not a construct: only a point has a height.
        #[allow(clippy::wildcard_enum_match_arm)]
        let written = match k {
            Known::Point(_, Some(z)) => Some(*z),
            _ => kept,
        };
        if let Some(zone) = zones.space.zone_at(p, written.unwrap_or(0.0)) {
            let message = format!("this flies to {}, inside {}", shown(p), zones.named(zone));
            let help = help_inside(zones.space.up_to(zone), p);
            self.report_with(Code::IntoNoFlyZone, message, help, call, site, file);
            return;
        }
        let z = written.unwrap_or_else(|| zones.above_limited());
        self.reachable(p, z, call, values, site, file);
    }

    /// A position the drone flies to must be reachable from its home: routes go around the
    /// zones inside the geofence, and a zone can cut the fenced ground in two.
    fn reachable(
        &mut self,
        p: [f64; 2],
        z: f64,
        call: &ApiCall,
        values: &Values,
        site: Option<(FileId, Span)>,
        file: FileId,
    ) {
        let Some(Known::Drones(drones)) = values.get(&call.actor.name) else { return };
        let world = self.world;
        let Some(zones) = self.zones.as_mut() else { return };
        let mut cut_off = None;
        for &i in drones {
            let Some(d) = world.drones.get(i) else { continue };
            if let Some(Blocked::NoWay { zone }) = zones.reach([d.home[0], d.home[1]], p, z) {
                cut_off = Some((d.name.clone(), zone));
                break;
            }
        }
        let Some((name, zone)) = cut_off else { return };
        let message = format!(
            "there is no way from `{name}`'s home to {} around {} inside the geofence",
            shown(p),
            zones.named(zone)
        );
        let help = format!(
            "choose a position the drone can reach, or widen `geofence` in the world file's [site]: a flight goes around no-fly zones, {} m from them, inside the geofence",
            number(aviary_route::MARGIN)
        );
        self.report_with(Code::IntoNoFlyZone, message, help, call, site, file);
    }

    /// An orbit's circle must keep out of the zones (the way to it is routed, the circle
    /// is not); one around a whole zone is fine.
    pub(crate) fn zone_circle(
        &mut self,
        center: [f64; 2],
        radius: f64,
        call: &ApiCall,
        site: Option<(FileId, Span)>,
        file: FileId,
    ) {
        let Some(zones) = &self.zones else { return };
        let at = zones.above_limited();
        let Some(zone) = zones.space.circle_enters(center, radius, at) else { return };
        let message = format!(
            "the circle of {} m around {} enters {}",
            number(radius),
            shown(center),
            zones.named(zone)
        );
        let help = "choose a radius whose circle goes round the whole zone or keeps clear of it, or another centre: an orbit's circle is not routed around a zone".to_owned();
        self.report_with(Code::IntoNoFlyZone, message, help, call, site, file);
    }

    /// A sweep's area (and its lanes, when the spacing is known) must keep out of the
    /// zones, and its first lane be reachable from the drone's home.
    pub(crate) fn zone_sweep(
        &mut self,
        area: &[[f64; 2]],
        spacing: Option<f64>,
        call: &ApiCall,
        values: &Values,
        site: Option<(FileId, Span)>,
        file: FileId,
    ) {
        let Some(zones) = &self.zones else { return };
        let lanes = spacing.map(|s| aviary_api::sweep::lawnmower(area, s)).unwrap_or_default();
        let at = zones.above_limited();
        if let Some(zone) = zones.space.sweep_enters(area, &lanes, at) {
            let message = format!("the area swept overlaps {}", zones.named(zone));
            let help = "sweep an area that leaves the zone out (split it into parts around the zone): a sweep's lanes are not routed around a zone".to_owned();
            self.report_with(Code::IntoNoFlyZone, message, help, call, site, file);
            return;
        }
        if let Some(&first) = lanes.first() {
            self.reachable(first, at, call, values, site, file);
        }
    }
}
