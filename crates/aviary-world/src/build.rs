//! From the spanned tree to a [`World`]: the top level, `[site]`, `[places]`, `[areas]`,
//! and the checks across tables (one name, one meaning); `[no_fly.NAME]` is
//! `build/no_fly.rs`.

use aviary_diagnostics::{Code, Diagnostic, FileId, Span};

use crate::hash::QuickMap;
use crate::node::{Entry, Node, Value};
use crate::read::{suggest, Ctx};
use crate::{Area, Geo, Line, Place, Site, World};

mod air;
mod drone;
mod expect;
mod fleet;
mod imports;
mod no_fly;
mod sim;

use drone::Drones;
use fleet::FleetInfo;

const TABLES: &[&str] = &[
    "site", "places", "areas", "lines", "no_fly", "drones", "fleets", "sensors", "targets",
    "faults", "air", "expect", "imports",
];
const SITE_KEYS: &[&str] = &[
    "name",
    "origin",
    "geofence",
    "max_altitude",
    "min_separation",
    "link_loss_rtl_after",
    "separation_timeout",
    "tiles",
    "tiles_attribution",
];
const ORIGIN_KEYS: &[&str] = &["lat", "lon", "alt"];

pub(crate) fn parse(
    file: FileId,
    text: &str,
    files: &dyn crate::WorldFiles,
) -> (Option<World>, Vec<Diagnostic>) {
    let (world, mut diags) = match read(file, text, files) {
        Ok(read) => read,
        Err(e) => return (None, vec![syntax_error(file, text, &e)]),
    };
    aviary_diagnostics::sort(&mut diags);
    if diags.iter().any(Diagnostic::is_error) {
        (None, diags)
    } else {
        (Some(world), diags)
    }
}

/// The world and its diagnostics (unsorted), or the TOML parser's error.
pub(crate) fn read(
    file: FileId,
    text: &str,
    files: &dyn crate::WorldFiles,
) -> Result<(World, Vec<Diagnostic>), toml::de::Error> {
    Ok(read_tree(file, text, Node::parse_serde(text)?, files))
}

/// The world of the spanned tree of `text`.
pub(crate) fn read_tree(
    file: FileId,
    text: &str,
    mut root: Node,
    files: &dyn crate::WorldFiles,
) -> (World, Vec<Diagnostic>) {
    let mut cx = Ctx { file, text, diags: Vec::new() };
    let mut drones = Drones::default();
    if let Value::Table(top) = &mut root.value {
        let mut take = |name: &str| match top.iter_mut().find(|e| e.key == name) {
            Some(Entry { node: Node { value: Value::Table(entries), .. }, .. }) => {
                std::mem::take(entries)
            }
            _ => Vec::new(),
        };
        let tables = take("drones");
        let mut fleets = take("fleets").into_iter().peekable();
        // In file order: a fleet's drones stand where its table does.
        for e in tables {
            while let Some(f) = fleets.next_if(|f| f.key_span.start < e.key_span.start) {
                drones.fleet(&mut cx, &f);
            }
            drones.entry(&mut cx, e);
        }
        for f in fleets {
            drones.fleet(&mut cx, &f);
        }
    }
    build(cx, root, drones, files)
}

fn syntax_error(file: FileId, text: &str, e: &toml::de::Error) -> Diagnostic {
    let range = e.span().unwrap_or(0..0);
    let start = range.start.min(text.len());
    let span = Span::new(start, range.end.clamp(start, text.len()));
    let detail = e.message().trim().replace('\n', ": ");
    let help = if detail.contains("duplicate key") {
        "write each key once per table, and each `[table]` header once"
    } else {
        "the world file is TOML: `[table]` headers, then `key = value` lines (see https://toml.io)"
    };
    Diagnostic::new(
        Code::WorldFile,
        file,
        span,
        format!("the world file is not valid TOML: {detail}"),
    )
    .with_help(help)
}

/// Looks a key up in a table.
pub(crate) fn get<'n>(entries: &'n [Entry], key: &str) -> Option<&'n Entry> {
    entries.iter().find(|e| e.key == key)
}

/// Everything but the drones' own tables, which `drones` has read (`[drones]` is left
/// without its entries).
fn build<'t>(
    mut cx: Ctx<'t>,
    root: Node,
    mut drones: Drones,
    files: &dyn crate::WorldFiles,
) -> (World, Vec<Diagnostic>) {
    let cx = &mut cx;
    let mut world = World::default();
    let Value::Table(top) = &root.value else {
        return (world, std::mem::take(&mut cx.diags));
    };
    for e in top.iter().filter(|e| !TABLES.contains(&e.key.as_str())) {
        let what = match e.node.value {
            Value::Table(_) => format!("unknown table `[{}]` in the world file", e.key),
            _ => format!("unknown key `{}` at the top of the world file", e.key),
        };
        let list = TABLES.iter().map(|t| format!("`[{t}]`")).collect::<Vec<_>>().join(", ");
        let help = match suggest(&e.key, TABLES.iter().copied()) {
            Some(s) => format!("did you mean `[{s}]`? The world file's tables are {list}"),
            None => format!("remove it; the world file's tables are {list}"),
        };
        cx.error(e.key_span, what, help);
    }
    let table = |name: &str| get(top, name);
    if let Some(e) = table("site") {
        world.site = site(cx, &e.node);
    }
    if let Some(e) = table("places") {
        world.places = places(cx, &e.node);
    }
    if let Some(e) = table("areas") {
        world.areas = areas(cx, &e.node);
    }
    if let Some(e) = table("lines") {
        world.lines = lines(cx, &e.node);
    }
    if let Some(e) = table("no_fly") {
        world.no_fly = no_fly::zones(cx, &e.node);
    }
    if let Some(e) = table("imports") {
        let imported = imports::imports(cx, &e.node, &world.site, files);
        world.places.extend(imported.places);
        world.lines.extend(imported.lines);
        world.areas.extend(imported.areas);
        world.no_fly.extend(imported.no_fly);
    }
    let sensor_kinds = keys_of(table("sensors"));
    if let Some(e) = table("sensors") {
        world.sensors = sim::sensors(cx, &e.node);
    }
    // Each drone of a fleet may have an area of its own.
    world.areas.extend(std::mem::take(&mut drones.areas));
    if let Some(e) = table("drones") {
        cx.table(&"`drones`", &e.node, drone::HELP);
    }
    if let Some(e) = table("fleets") {
        cx.table(&"`fleets`", &e.node, fleet::HELP);
    }
    drones.finish(cx, &sensor_kinds);
    if let Some(e) = table("targets") {
        world.targets = sim::targets(cx, &e.node, world.site.geofence.as_deref());
    }
    if let Some(e) = table("faults") {
        world.faults = sim::faults(cx, &e.node, &drones.names());
    }
    if let Some(e) = table("air") {
        world.air = air::air(cx, &e.node);
    }
    if let Some(e) = table("expect") {
        world.expect = expect::expectations(cx, &e.node, &world.targets);
    }
    world.groups = std::mem::take(&mut drones.groups);
    world.drones = std::mem::take(&mut drones.out);
    one_name_per_drone(cx, &world.drones, &drones.fleets);
    homes_in_fence(cx, &world, &drones.fleets);
    no_fly::homes_outside_zones(cx, &world, &drones.fleets);
    unique_names(cx, &world);
    air::wind_within_reach(cx, &world);
    (world, std::mem::take(&mut cx.diags))
}

/// The keys of a table, whatever their values: what the file defines, even with errors.
fn keys_of(entry: Option<&Entry>) -> Vec<String> {
    match entry.map(|e| &e.node.value) {
        Some(Value::Table(entries)) => entries.iter().map(|e| e.key.clone()).collect(),
        _ => Vec::new(),
    }
}

fn site(cx: &mut Ctx, node: &Node) -> Site {
    let mut site = Site::default();
    let help = "write `[site]` followed by lines such as `name = \"...\"` and `max_altitude = 120`";
    let Some(entries) = cx.table(&"`site`", node, help) else {
        return site;
    };
    cx.known_keys(entries, SITE_KEYS, "[site]");
    for e in entries {
        let n = &e.node;
        match e.key.as_str() {
            "name" => site.name = cx.string(&"`name` in [site]", n),
            "origin" => site.origin = origin(cx, e),
            "geofence" => {
                site.geofence = cx
                    .polygon(&"the geofence", n)
                    .filter(|fence| cx.outline(&"the geofence", n, fence))
            }
            "max_altitude" => site.max_altitude = cx.positive(&"`max_altitude`", n),
            "min_separation" => match cx.number(&"`min_separation`", n) {
                Some(v) if v < 0.0 => {
                    let msg = format!(
                        "`min_separation` must be zero or more metres, found {}",
                        aviary_api::show::number(v)
                    );
                    cx.error(n.span, msg, "write a distance in metres, e.g. `min_separation = 5`");
                }
                Some(v) => site.min_separation = v,
                None => {}
            },
            "link_loss_rtl_after" => {
                if let Some(v) = cx.positive(&"`link_loss_rtl_after`", n) {
                    site.link_loss_rtl_after = v;
                }
            }
            "separation_timeout" => {
                if let Some(v) = cx.positive(&"`separation_timeout`", n) {
                    site.separation_timeout = v;
                }
            }
            "tiles" => site.tiles = tiles(cx, n),
            "tiles_attribution" => {
                site.tiles_attribution = cx.string(&"`tiles_attribution` in [site]", n)
            }
            _ => {}
        }
    }
    if site.origin.is_none() {
        if let Some(e) = entries.iter().find(|e| e.key == "tiles") {
            cx.error(
                e.key_span,
                "a base map (`tiles`) needs the site's `origin`, to place the local frame on it",
                "add `origin = { lat = ..., lon = ..., alt = ... }` to [site], or leave `tiles` out",
            );
        }
    }
    site
}

/// `tiles`: an XYZ tile server's address, with `{z}`, `{x}` and `{y}` where the zoom and
/// the tile's column and row go (Leaflet's form; `{s}` for a server's subdomains too).
fn tiles(cx: &mut Ctx, node: &Node) -> Option<String> {
    let url = cx.string(&"`tiles` in [site]", node)?;
    let help = "write the tile server's address with {z}, {x} and {y}, e.g. \
                `tiles = \"https://tile.openstreetmap.org/{z}/{x}/{y}.png\"`";
    if !(url.starts_with("https://") || url.starts_with("http://")) {
        cx.error(
            node.span,
            format!("`tiles` must be an http:// or https:// address, found `{url}`"),
            help,
        );
        return None;
    }
    if let Some(missing) = ["{z}", "{x}", "{y}"].into_iter().find(|p| !url.contains(p)) {
        cx.error(node.span, format!("`tiles` has no `{missing}` in `{url}`"), help);
        return None;
    }
    Some(url)
}

fn origin(cx: &mut Ctx, e: &Entry) -> Option<Geo> {
    let help = "write `origin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }` (degrees, metres)";
    let entries = cx.table(&"`origin`", &e.node, help)?;
    cx.known_keys(entries, ORIGIN_KEYS, "`origin`");
    let mut read = |key: &str, min: f64, max: f64| match get(entries, key) {
        Some(v) => cx.within(&format!("`{key}` of `origin`"), &v.node, min, max),
        None if key == "alt" => Some(0.0),
        None => {
            cx.error(e.key_span, format!("`origin` has no `{key}`"), help);
            None
        }
    };
    let lat = read("lat", -90.0, 90.0);
    let lon = read("lon", -180.0, 180.0);
    let alt = read("alt", -1e6, 1e6);
    Some(Geo { lat: lat?, lon: lon?, alt: alt? })
}

fn places(cx: &mut Ctx, node: &Node) -> Vec<Place> {
    let help = "write `[places]` followed by lines `NAME = [x, y]` or `NAME = [x, y, z]`";
    let Some(entries) = cx.table(&"`places`", node, help) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for e in entries {
        cx.identifier("place", &e.key, e.key_span);
        let what = format!("place `{}`", e.key);
        if let Some((at, has_z)) =
            cx.point(&what, &e.node).filter(|(at, _)| cx.above_ground(&what, &e.node, at[2]))
        {
            out.push(Place { name: e.key.clone(), at, has_z, span: e.key_span });
        }
    }
    out
}

fn areas(cx: &mut Ctx, node: &Node) -> Vec<Area> {
    let help = "write `[areas]` followed by lines `NAME = [[x, y], [x, y], [x, y], ...]`";
    let Some(entries) = cx.table(&"`areas`", node, help) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for e in entries {
        cx.identifier("area", &e.key, e.key_span);
        let what = format!("area `{}`", e.key);
        if let Some(polygon) = cx.polygon(&what, &e.node).filter(|p| cx.outline(&what, &e.node, p))
        {
            out.push(Area { name: e.key.clone(), polygon, span: e.key_span });
        }
    }
    out
}

/// `[lines]`: `NAME = [[x, y], [x, y, z], ...]`, at least two points. A line outside the
/// geofence is allowed, as a place or an area is: a mission that flies it is told where.
fn lines(cx: &mut Ctx, node: &Node) -> Vec<Line> {
    let help = "write `[lines]` followed by lines `NAME = [[x, y], [x, y], ...]` (a point may be `[x, y, z]`)";
    let Some(entries) = cx.table(&"`lines`", node, help) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for e in entries {
        cx.identifier("line", &e.key, e.key_span);
        let what = format!("line `{}`", e.key);
        let Value::Array(items) = &e.node.value else {
            let msg = format!(
                "{what} must be a list of points [[x, y], ...], found {}",
                e.node.describe()
            );
            cx.error(e.node.span, msg, help);
            continue;
        };
        if items.len() < 2 {
            let msg = format!(
                "{what} has {}; a line needs at least 2",
                crate::read::count(items.len(), "point")
            );
            cx.error(e.node.span, msg, help);
            continue;
        }
        let mut points = Some(Vec::with_capacity(items.len()));
        for item in items {
            let point = cx
                .point(&format!("a point of {what}"), item)
                .filter(|(at, _)| cx.above_ground(&format!("a point of {what}"), item, at[2]));
            match (point, points.as_mut()) {
                (Some(p), Some(points)) => points.push(p),
                (None, _) => points = None,
                _ => {}
            }
        }
        if let Some(points) = points {
            out.push(Line { name: e.key.clone(), points, span: e.key_span });
        }
    }
    out
}

/// Every drone starts and lands at its home: one outside the geofence (its line counts as
/// inside, as for a flight) would take off outside it (and the simulator would fly it back
/// in from there). Reported at the `home` value, or once per fleet at its `homes`; the
/// place of a table's `home` is looked up again only when one is outside, so a valid world
/// keeps no span per home.
fn homes_in_fence(cx: &mut Ctx, world: &World, fleets: &[FleetInfo]) {
    let Some(fence) = world.site.geofence.as_deref() else { return };
    let outside =
        |d: &&crate::Drone| !aviary_api::geometry::contains(fence, [d.home[0], d.home[1]]);
    let mut in_fleets = 0;
    for f in fleets {
        let drones = &world.drones[f.drones.clone()];
        in_fleets += drones.len();
        let mut out = drones.iter().filter(outside);
        let Some(first) = out.next() else { continue };
        let at = crate::read::shown([first.home[0], first.home[1]]);
        let msg = match out.count() {
            0 => format!("drone `{}` of fleet `{}` has its home {at} outside the geofence", first.name, f.name),
            more => format!(
                "{} drones of fleet `{}` have their homes outside the geofence, the first `{}` at {at}",
                more + 1,
                f.name,
                first.name
            ),
        };
        cx.error(f.homes_span, msg, "move the homes inside the geofence, or widen `geofence` in [site]: a drone takes off and lands at its home");
    }
    if in_fleets == world.drones.len() {
        return;
    }
    let in_fleet = |i: usize| fleets.iter().any(|f| f.drones.contains(&i));
    let outside: Vec<&crate::Drone> = world
        .drones
        .iter()
        .enumerate()
        .filter(|(i, d)| outside(d) && !in_fleet(*i))
        .map(|(_, d)| d)
        .collect();
    if outside.is_empty() {
        return;
    }
    let spans = home_spans(cx.text);
    for d in outside {
        let at = spans.get(d.name.as_str()).copied().unwrap_or(d.span);
        let msg = format!(
            "drone `{}`'s home {} is outside the geofence",
            d.name,
            crate::read::shown([d.home[0], d.home[1]])
        );
        cx.error(at, msg, "move the home inside the geofence, or widen `geofence` in [site]: a drone takes off and lands at its home");
    }
}

/// Drone names are unique among the tables (TOML keys) and within a fleet (its numbers
/// differ); a fleet's may still meet a table's or another fleet's. Reported at each
/// table drone whose name was taken before, and once per fleet (with how many).
fn one_name_per_drone(cx: &mut Ctx, drones: &[crate::Drone], fleets: &[FleetInfo]) {
    if fleets.is_empty() || (fleets.len() == 1 && fleets[0].drones.len() == drones.len()) {
        return;
    }
    let fleet_of = |i: usize| fleets.iter().position(|f| f.drones.contains(&i));
    let described = |i: usize| match fleet_of(i) {
        Some(f) => format!("a drone of fleet `{}`", fleets[f].name),
        None => format!("`[drones.{}]`", drones[i].name),
    };
    let mut seen: QuickMap<&str, usize> = QuickMap::default();
    seen.reserve(drones.len());
    let mut taken: Vec<(usize, usize)> = Vec::new();
    for (i, d) in drones.iter().enumerate() {
        match seen.entry(d.name.as_str()) {
            std::collections::hash_map::Entry::Occupied(first) => taken.push((i, *first.get())),
            std::collections::hash_map::Entry::Vacant(v) => {
                v.insert(i);
            }
        }
    }
    let mut fleet_told = vec![false; fleets.len()];
    let help =
        "rename one of them, or change a fleet's `names`: every drone needs a name of its own";
    for &(i, first) in &taken {
        let name = &drones[i].name;
        let more = match fleet_of(i) {
            Some(f) if fleet_told[f] => continue,
            Some(f) => {
                fleet_told[f] = true;
                match taken.iter().filter(|(j, _)| fleet_of(*j) == Some(f)).count() - 1 {
                    0 => String::new(),
                    1 => " (1 more of its drones has a name taken as well)".to_owned(),
                    n => format!(" ({n} more of its drones have names taken as well)"),
                }
            }
            None => String::new(),
        };
        let msg = format!(
            "the name `{name}` is used for two drones: {} and {}{more}",
            described(first),
            described(i)
        );
        let d = Diagnostic::new(Code::WorldFile, cx.file, drones[i].span, msg)
            .with_help(help)
            .also(cx.file, drones[first].span, format!("{} is defined here", described(first)));
        cx.push(d);
    }
}

/// Where each drone's `home` value is written, by drone name (the file parses: its world
/// was built).
pub(super) fn home_spans(text: &str) -> std::collections::HashMap<String, Span> {
    let mut out = std::collections::HashMap::new();
    let Ok(root) = Node::parse_serde(text) else { return out };
    let Value::Table(top) = &root.value else { return out };
    let Some(Entry { node: Node { value: Value::Table(drones), .. }, .. }) = get(top, "drones")
    else {
        return out;
    };
    for d in drones {
        let Value::Table(keys) = &d.node.value else { continue };
        if let Some(home) = get(keys, "home") {
            out.insert(d.key.clone(), home.node.span);
        }
    }
    out
}

/// A name stands for one drone, group, place, area or line: mission code names them alike.
/// Within each kind names are unique already (TOML keys, one group per name), so only
/// names of two kinds can clash: the drones, the many, are looked up among the others.
fn unique_names(cx: &mut Ctx, world: &World) {
    let mut named: QuickMap<&str, Vec<(&str, Span)>> = QuickMap::default();
    let places = world.places.iter().map(|p| (p.name.as_str(), "a place", p.span));
    let areas = world.areas.iter().map(|a| (a.name.as_str(), "an area", a.span));
    let lines = world.lines.iter().map(|l| (l.name.as_str(), "a line", l.span));
    // Where each group is first named.
    let groups =
        world.groups.iter().filter_map(|g| Some((g.name.as_str(), "a group", *g.spans.first()?)));
    for (name, what, span) in places.chain(areas).chain(lines).chain(groups) {
        named.entry(name).or_default().push((what, span));
    }
    for d in &world.drones {
        if let Some(uses) = named.get_mut(d.name.as_str()) {
            uses.push(("a drone", d.span));
        }
    }
    let mut clashes: Vec<(&str, Vec<(&str, Span)>)> =
        named.into_iter().filter(|(_, uses)| uses.len() > 1).collect();
    clashes.sort_by_key(|(_, uses)| uses.iter().map(|(_, s)| (s.start, s.end)).min());
    for (name, mut uses) in clashes {
        uses.sort_by_key(|(_, span)| (span.start, span.end));
        let (first, first_span) = uses[0];
        for &(what, span) in &uses[1..] {
            // Two of one kind: a file of `[imports]` names one the world file has too.
            let msg = if what == first {
                let plural = match what {
                    "a place" => "places",
                    "an area" => "areas",
                    "a line" => "lines",
                    _ => "groups",
                };
                format!("the name `{name}` is used for two {plural}, so mission code could not tell which is meant")
            } else {
                format!("the name `{name}` is used for {first} and for {what}, so mission code could not tell which is meant")
            };
            let help =
                "rename one of them: drones, groups, places, areas and lines share one set of names";
            let d = Diagnostic::new(Code::WorldFile, cx.file, span, msg).with_help(help).also(
                cx.file,
                first_span,
                format!("{first} `{name}` is defined here"),
            );
            cx.push(d);
        }
    }
}
