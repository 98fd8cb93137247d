//! `[no_fly.NAME]`: the no-fly zones (docs/WORLD.md), and the homes they must leave free.

use aviary_api::geometry::contains;

use super::{get, home_spans};
use crate::node::Node;
use crate::read::{shown, Ctx};
use crate::{Drone, NoFly, World};

use super::fleet::FleetInfo;

pub(super) const ZONE_KEYS: &[&str] = &["polygon", "up_to"];

const HELP: &str = "write one table per zone: `[no_fly.Fire_Front]` followed by `polygon = [[x, y], [x, y], [x, y], ...]` and, if it holds only near the ground, `up_to = 60`";

pub(super) fn zones(cx: &mut Ctx, node: &Node) -> Vec<NoFly> {
    let Some(entries) = cx.table(&"`no_fly`", node, HELP) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for e in entries {
        let name = &e.key;
        // Any name: missions do not name zones, people read them (`[no_fly."Power line"]`).
        let Some(keys) = cx.table(&format!("no-fly zone `{name}`"), &e.node, HELP) else {
            continue;
        };
        cx.known_keys(keys, ZONE_KEYS, &format!("[no_fly.{name}]"));
        let what = format!("no-fly zone `{name}`");
        let polygon = match get(keys, "polygon") {
            Some(p) => cx.polygon(&what, &p.node).filter(|poly| cx.outline(&what, &p.node, poly)),
            None => {
                let msg = format!("no-fly zone `{name}` has no `polygon`");
                cx.error(e.key_span, msg, "add `polygon = [[x, y], [x, y], [x, y], ...]`: the zone's corners in metres, in order around it");
                None
            }
        };
        let up_to = match get(keys, "up_to") {
            Some(u) => cx.positive(&format!("`up_to` of no-fly zone `{name}`"), &u.node).map(Some),
            None => Some(None),
        };
        if let (Some(polygon), Some(up_to)) = (polygon, up_to) {
            out.push(NoFly { name: name.clone(), polygon, up_to, span: e.key_span });
        }
    }
    out
}

/// A drone takes off and lands at its home, from the ground, where every zone holds: a
/// home inside a zone (its line counts as inside) could never be left nor come back to.
/// Reported at the `home` value, or once per fleet at its `homes`, as for the geofence.
pub(super) fn homes_outside_zones(cx: &mut Ctx, world: &World, fleets: &[FleetInfo]) {
    if world.no_fly.is_empty() {
        return;
    }
    let zone_of =
        |d: &Drone| world.no_fly.iter().find(|z| contains(&z.polygon, [d.home[0], d.home[1]]));
    let help = "move the home out of the zone, or draw the zone's `polygon` around it: a drone takes off and lands at its home";
    let mut in_fleets = vec![false; world.drones.len()];
    for f in fleets {
        let drones = &world.drones[f.drones.clone()];
        in_fleets[f.drones.clone()].iter_mut().for_each(|b| *b = true);
        let mut inside = drones.iter().filter_map(|d| zone_of(d).map(|z| (d, z)));
        let Some((first, zone)) = inside.next() else { continue };
        let at = shown([first.home[0], first.home[1]]);
        let msg = match inside.count() {
            0 => format!("drone `{}` of fleet `{}` has its home {at} inside the no-fly zone `{}`", first.name, f.name, zone.name),
            more => format!(
                "{} drones of fleet `{}` have their homes inside no-fly zones, the first `{}` at {at} inside `{}`",
                more + 1,
                f.name,
                first.name,
                zone.name
            ),
        };
        cx.error(f.homes_span, msg, help);
    }
    let inside: Vec<(&Drone, &NoFly)> = (world.drones.iter().enumerate())
        .filter(|(i, _)| !in_fleets[*i])
        .filter_map(|(_, d)| zone_of(d).map(|z| (d, z)))
        .collect();
    if inside.is_empty() {
        return;
    }
    let spans = home_spans(cx.text);
    for (d, zone) in inside {
        let at = spans.get(d.name.as_str()).copied().unwrap_or(d.span);
        let msg = format!(
            "drone `{}`'s home {} is inside the no-fly zone `{}`",
            d.name,
            shown([d.home[0], d.home[1]]),
            zone.name
        );
        cx.error(at, msg, help);
    }
}
