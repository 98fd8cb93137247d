//! From the spanned tree to a [`World`]: the top level, `[site]`, `[places]`, `[areas]`,
//! and the checks across tables (one name, one meaning).

use std::collections::HashMap;

use aviary_diagnostics::{Code, Diagnostic, FileId, Span};

use crate::node::{Entry, Node, Value};
use crate::read::{suggest, Ctx};
use crate::{Area, Geo, Group, Place, Site, World};

mod drone;
mod sim;

const TABLES: &[&str] = &[
    "site", "places", "areas", "drones", "sensors", "targets", "faults",
];
const SITE_KEYS: &[&str] = &[
    "name",
    "origin",
    "geofence",
    "max_altitude",
    "min_separation",
    "link_loss_rtl_after",
    "separation_timeout",
];
const ORIGIN_KEYS: &[&str] = &["lat", "lon", "alt"];

pub(crate) fn parse(file: FileId, text: &str) -> (Option<World>, Vec<Diagnostic>) {
    let root = match Node::parse(text) {
        Ok(root) => root,
        Err(e) => return (None, vec![syntax_error(file, text, &e)]),
    };
    let mut cx = Ctx {
        file,
        text,
        diags: Vec::new(),
    };
    let world = build(&mut cx, root);
    let mut diags = cx.diags;
    aviary_diagnostics::sort(&mut diags);
    if diags.iter().any(Diagnostic::is_error) {
        (None, diags)
    } else {
        (Some(world), diags)
    }
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

fn build(cx: &mut Ctx, mut root: Node) -> World {
    let mut world = World::default();
    // The drones' tables are read (and freed) one by one below: for a large fleet the
    // tree and the drones built from it need not be in memory whole at once.
    let drone_names = keys_of(match &root.value {
        Value::Table(top) => get(top, "drones"),
        _ => None,
    });
    let drones_table = match &mut root.value {
        Value::Table(top) => top.iter_mut().find(|e| e.key == "drones").map(|e| {
            let empty = Node { span: e.node.span, value: Value::Table(Vec::new()) };
            std::mem::replace(&mut e.node, empty)
        }),
        _ => None,
    };
    let Value::Table(top) = &root.value else {
        return world;
    };
    for e in top.iter().filter(|e| !TABLES.contains(&e.key.as_str())) {
        let what = match e.node.value {
            Value::Table(_) => format!("unknown table `[{}]` in the world file", e.key),
            _ => format!("unknown key `{}` at the top of the world file", e.key),
        };
        let list = TABLES
            .iter()
            .map(|t| format!("`[{t}]`"))
            .collect::<Vec<_>>()
            .join(", ");
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
    let sensor_kinds = keys_of(table("sensors"));
    if let Some(e) = table("sensors") {
        world.sensors = sim::sensors(cx, &e.node);
    }
    let mut group_spans = Vec::new();
    if let Some(node) = drones_table {
        world.drones = drone::drones(cx, node, &sensor_kinds, &mut group_spans);
    }
    world.groups = groups(&world, &group_spans);
    if let Some(e) = table("targets") {
        world.targets = sim::targets(cx, &e.node);
    }
    if let Some(e) = table("faults") {
        world.faults = sim::faults(cx, &e.node, &drone_names);
    }
    unique_names(cx, &world, &group_spans);
    world
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
            "geofence" => site.geofence = cx.polygon(&"the geofence", n),
            "max_altitude" => site.max_altitude = cx.positive(&"`max_altitude`", n),
            "min_separation" => match cx.number(&"`min_separation`", n) {
                Some(v) if v < 0.0 => {
                    let msg = format!("`min_separation` must be zero or more metres, found {v}");
                    cx.error(
                        n.span,
                        msg,
                        "write a distance in metres, e.g. `min_separation = 5`",
                    );
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
            _ => {}
        }
    }
    site
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
    Some(Geo {
        lat: lat?,
        lon: lon?,
        alt: alt?,
    })
}

fn places(cx: &mut Ctx, node: &Node) -> Vec<Place> {
    let help = "write `[places]` followed by lines `NAME = [x, y]` or `NAME = [x, y, z]`";
    let Some(entries) = cx.table(&"`places`", node, help) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for e in entries {
        cx.identifier("place", &e.key, e.key_span);
        if let Some((at, has_z)) = cx.point(&format!("place `{}`", e.key), &e.node) {
            out.push(Place {
                name: e.key.clone(),
                at,
                has_z,
                span: e.key_span,
            });
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
        if let Some(polygon) = cx.polygon(&format!("area `{}`", e.key), &e.node) {
            out.push(Area {
                name: e.key.clone(),
                polygon,
                span: e.key_span,
            });
        }
    }
    out
}

/// Groups in order of first appearance, members in the drones' file order.
fn groups(world: &World, group_spans: &[(String, Span)]) -> Vec<Group> {
    let mut out: Vec<Group> = Vec::new();
    for (name, _) in group_spans {
        if out.iter().all(|g| &g.name != name) {
            out.push(Group {
                name: name.clone(),
                members: Vec::new(),
            });
        }
    }
    for d in &world.drones {
        let Some(name) = &d.group else { continue };
        if let Some(g) = out.iter_mut().find(|g| &g.name == name) {
            g.members.push(d.name.clone());
        }
    }
    out
}

/// A name stands for one drone, group, place or area: mission code names them alike.
fn unique_names(cx: &mut Ctx, world: &World, group_spans: &[(String, Span)]) {
    let mut all: Vec<(&str, &str, Span)> = Vec::new();
    all.extend(
        world
            .drones
            .iter()
            .map(|d| (d.name.as_str(), "a drone", d.span)),
    );
    all.extend(
        world
            .places
            .iter()
            .map(|p| (p.name.as_str(), "a place", p.span)),
    );
    all.extend(
        world
            .areas
            .iter()
            .map(|a| (a.name.as_str(), "an area", a.span)),
    );
    let mut first_group: HashMap<&str, Span> = HashMap::new();
    for (name, span) in group_spans {
        first_group.entry(name.as_str()).or_insert(*span);
    }
    all.extend(
        first_group
            .iter()
            .map(|(name, span)| (*name, "a group", *span)),
    );
    all.sort_by_key(|(_, _, span)| (span.start, span.end));
    let mut seen: HashMap<&str, (&str, Span)> = HashMap::new();
    for (name, what, span) in all {
        let Some(&(first, first_span)) = seen.get(name) else {
            seen.insert(name, (what, span));
            continue;
        };
        let msg = format!(
            "the name `{name}` is used for {first} and for {what}, so mission code could not tell which is meant"
        );
        let help = "rename one of them: drones, groups, places and areas share one set of names";
        let d = Diagnostic::new(Code::WorldFile, cx.file, span, msg)
            .with_help(help)
            .also(
                cx.file,
                first_span,
                format!("{first} `{name}` is defined here"),
            );
        cx.push(d);
    }
}
