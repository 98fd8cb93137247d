//! `[fleets.NAME]`: many drones described at once. They share every key of a drone's
//! table and differ in their names (a pattern with the drone's number in it), their homes
//! (a grid or a ring) and their number, which each holds as its `index` attribute. A fleet
//! may also give each drone an area of its own, placed about its home.
//!
//! Fleets are how large worlds are written: 100,000 drones are a few lines. A fleet's own
//! keys ([`FLEET_KEYS`]) are read here, its `count` checked against [`MAX_DRONES`] before
//! anything is made; every other key is read once, by the same code as a drone's table
//! (`Drones::read_keys`), into a template that each drone copies with its name, home and
//! `index`. So a problem with a fleet's key is reported once, at the key, not per drone.

use std::fmt::Write;
use std::ops::Range;

use aviary_diagnostics::Span;

use super::drone::{Drones, KeyOf, Owner};
use super::get;
use crate::node::{Entry, Node, Value};
use crate::read::{count, is_identifier, toml_text, Ctx};
use crate::{Area, AttributeValue, Backend, Drone};

/// The most drones a world may have, fleets and tables together: about 3 GB of world and
/// simulator. A count beyond it is a mistake (or an attack), not a fleet to allocate.
pub(crate) const MAX_DRONES: usize = 10_000_000;
/// The largest `first`: numbers stay exact as attributes (far below 2^53) and short.
const MAX_FIRST: i64 = 1_000_000_000;
/// The widest zero-padded number in a pattern (`{i:020}`: every `u64`).
const MAX_WIDTH: usize = 20;
/// A fleet's own keys; the others are a drone's, for every drone of the fleet.
pub(super) const FLEET_KEYS: &[&str] = &["count", "names", "first", "homes", "areas"];
const HOMES_KEYS: &[&str] = &["grid", "spacing", "columns", "ring", "radius"];
const AREAS_KEYS: &[&str] = &["names", "polygon"];
/// The MAVLink system ids of one address.
const MAX_ON_ONE_ADDRESS: usize = 255;

pub(super) const HELP: &str = "write one table per fleet: `[fleets.NAME]` followed by `count = 10` and `homes = { grid = [0, 0], spacing = 10 }`";
const HOMES_HELP: &str = "write `homes = { grid = [0, 0], spacing = 10 }` (rows of homes from the south-west corner; add `columns = 8` for the row's length) or `homes = { ring = [0, 0], radius = 50 }`";
const AREAS_HELP: &str = "write `areas = { names = \"Cell_{i}\", polygon = [[0, 0], [80, 0], [80, 80], [0, 80]] }`: each drone's own area, its corners in metres from the drone's home";

/// Where a fleet's drones are in the world, for messages about them.
pub(crate) struct FleetInfo {
    pub name: String,
    /// Indices into the world's drones.
    pub drones: Range<usize>,
    /// The `homes` value (the key's span when it has none).
    pub homes_span: Span,
}

/// A name with a drone's number in it: `"uav_{i:03}"` gives `uav_007` for number 7.
struct Pattern(Vec<Piece>);

enum Piece {
    Text(String),
    /// The number, zero-padded to at least this many digits.
    Number(usize),
}

impl Pattern {
    /// The pattern of `text`, or what is wrong with it.
    fn parse(text: &str) -> Result<Pattern, String> {
        let mut pieces = Vec::new();
        let mut rest = text;
        let mut literal = String::new();
        while let Some(at) = rest.find(['{', '}']) {
            literal.push_str(&rest[..at]);
            rest = &rest[at..];
            let Some(close) = rest.find('}').filter(|_| rest.starts_with('{')) else {
                return Err("has a `}` that closes nothing".into());
            };
            let inside = &rest[1..close];
            let width = match inside {
                "i" => 0,
                _ => match inside.strip_prefix("i:0").map(str::parse::<usize>) {
                    Some(Ok(w)) if (1..=MAX_WIDTH).contains(&w) => w,
                    _ => {
                        return Err(format!(
                            "has `{{{inside}}}`, which is not `{{i}}` or `{{i:03}}`"
                        ))
                    }
                },
            };
            if !literal.is_empty() {
                pieces.push(Piece::Text(std::mem::take(&mut literal)));
            }
            pieces.push(Piece::Number(width));
            rest = &rest[close + 1..];
        }
        literal.push_str(rest);
        if !literal.is_empty() {
            pieces.push(Piece::Text(literal));
        }
        if !pieces.iter().any(|p| matches!(p, Piece::Number(_))) {
            return Err("has no `{i}`, so every name would be the same".into());
        }
        Ok(Pattern(pieces))
    }

    fn write(&self, n: u64, out: &mut String) {
        for piece in &self.0 {
            match piece {
                Piece::Text(text) => out.push_str(text),
                Piece::Number(width) => {
                    let _ = write!(out, "{n:0width$}");
                }
            }
        }
    }

    fn name(&self, n: u64) -> String {
        let mut out = String::new();
        self.write(n, &mut out);
        out
    }
}

/// Where the drones of a fleet stand, by their place in it (0 for the first).
enum Homes {
    /// Rows of `columns` homes, from `corner` east (`step[0]` apart), rows `step[1]`
    /// apart to the north.
    Grid { corner: [f64; 3], step: [f64; 2], columns: usize },
    /// Evenly around a circle, the first east of the centre, then counter-clockwise.
    Ring { center: [f64; 3], radius: f64 },
}

impl Homes {
    fn at(&self, k: usize, count: usize) -> [f64; 3] {
        match *self {
            Homes::Grid { corner, step, columns } => [
                corner[0] + (k % columns) as f64 * step[0],
                corner[1] + (k / columns) as f64 * step[1],
                corner[2],
            ],
            Homes::Ring { center, radius } => {
                let angle = std::f64::consts::TAU * k as f64 / count as f64;
                [center[0] + radius * angle.cos(), center[1] + radius * angle.sin(), center[2]]
            }
        }
    }

    /// The box of every home of a fleet of `count`: its south-west and north-east corners.
    fn bounds(&self, count: usize) -> ([f64; 2], [f64; 2]) {
        match *self {
            Homes::Grid { corner, step, columns } => {
                let far = [
                    corner[0] + (columns.min(count) - 1) as f64 * step[0],
                    corner[1] + ((count - 1) / columns) as f64 * step[1],
                ];
                ([corner[0], corner[1]], far)
            }
            Homes::Ring { center, radius } => {
                ([center[0] - radius, center[1] - radius], [center[0] + radius, center[1] + radius])
            }
        }
    }
}

impl Drones {
    /// One entry of `[fleets]`: its drones, in the order of their numbers, and their areas.
    pub fn fleet(&mut self, cx: &mut Ctx, e: &Entry) {
        let fleet = e.key.as_str();
        let Some(keys) = cx.table(&Owner::Fleet(fleet), &e.node, HELP) else { return };
        let count = fleet_count(cx, fleet, e.key_span, keys, self.out.len());
        let first = match get(keys, "first") {
            Some(f) => whole(cx, &KeyOf("first", Owner::Fleet(fleet)), &f.node, 0, MAX_FIRST),
            None => Some(0),
        };
        let names = names(cx, fleet, e.key_span, keys, first);
        let homes = homes(cx, fleet, e.key_span, keys, count);
        let areas = areas(cx, fleet, keys, first);
        for k in keys {
            let why = match k.key.as_str() {
                "home" => "each drone of a fleet has a home of its own: give them with `homes`",
                "index" => "each drone of a fleet has its number as its `index`",
                "system_id" => "each drone of a fleet on one `mavlink` address has its own system id: 1 + its place among the drones of that address",
                _ => continue,
            };
            let msg = format!("a fleet cannot set `{}` for all its drones", k.key);
            cx.error(k.key_span, msg, format!("remove it; {why}"));
        }
        let rest: Vec<Entry> = keys
            .iter()
            .filter(|k| !FLEET_KEYS.contains(&k.key.as_str()))
            .filter(|k| !["home", "index", "system_id"].contains(&k.key.as_str()))
            .cloned()
            .collect();
        let start = self.out.len();
        let (mut template, group) =
            self.read_keys(cx, Owner::Fleet(fleet), e.key_span, &rest, start);
        if let (Backend::Mavlink(_), Some(n), Some(c)) =
            (&template.backend, count.filter(|&n| n > MAX_ON_ONE_ADDRESS), get(keys, "count"))
        {
            let msg = format!(
                "fleet `{fleet}` has {n} drones on one `mavlink` address, which has system ids for {MAX_ON_ONE_ADDRESS}"
            );
            cx.error(c.node.span, msg, "give the fleet 255 drones or fewer, or split it into fleets on addresses of their own");
        }
        // Without a count or names there are no drones; without homes they stand at the
        // origin, so that what names them (faults, the mission) is not wrong as well.
        let (Some(count), Some(first), Some(names)) = (count, first, names) else { return };
        let first = first as u64;
        let index = self.key("index");
        let attributes = std::mem::take(&mut template.attributes);
        let (homes, homes_span) = match homes {
            Some((homes, span)) => (Some(homes), span),
            None => (None, get(keys, "homes").map_or(e.key_span, |h| h.node.span)),
        };
        self.out.reserve(count);
        for k in 0..count {
            let number = first + k as u64;
            let mut d: Drone = template.clone();
            d.name = names.name(number);
            if let Some(homes) = &homes {
                d.home = homes.at(k, count);
            }
            let mut own = Vec::with_capacity(attributes.len() + 1);
            own.push((index.clone(), AttributeValue::Number(number as f64)));
            own.extend(attributes.iter().cloned());
            d.attributes = own.into();
            self.out.push(d);
        }
        let drones = start..self.out.len();
        if let Some(g) = group {
            self.groups[g].members.extend(drones.clone());
        }
        let areas = areas.flatten().filter(|(_, polygon, span)| {
            let Some(homes) = &homes else { return false };
            let (lo, hi) = homes.bounds(count);
            let reach = polygon
                .iter()
                .flat_map(|p| [lo[0] + p[0], lo[1] + p[1], hi[0] + p[0], hi[1] + p[1]]);
            let finite = reach.into_iter().all(f64::is_finite);
            if !finite {
                let msg = format!(
                    "the areas of fleet `{fleet}` reach beyond the numbers a world can hold"
                );
                cx.error(*span, msg, "write corners nearer the homes, in metres");
            }
            finite
        });
        if let (Some((pattern, polygon, span)), Some(homes)) = (areas, &homes) {
            self.areas.reserve(count);
            for k in 0..count {
                let home = homes.at(k, count);
                let polygon = polygon.iter().map(|p| [home[0] + p[0], home[1] + p[1]]).collect();
                self.areas.push(Area { name: pattern.name(first + k as u64), polygon, span });
            }
        }
        self.fleets.push(FleetInfo { name: fleet.to_owned(), drones, homes_span });
    }
}

/// `count`: at least 1, and with the `before` drones already read at most [`MAX_DRONES`].
fn fleet_count(
    cx: &mut Ctx,
    fleet: &str,
    key_span: Span,
    keys: &[Entry],
    before: usize,
) -> Option<usize> {
    let Some(c) = get(keys, "count") else {
        cx.error(
            key_span,
            format!("fleet `{fleet}` has no `count`"),
            "add `count = 10`: how many drones it has",
        );
        return None;
    };
    let n = whole(cx, &KeyOf("count", Owner::Fleet(fleet)), &c.node, 1, i64::MAX)?;
    let room = MAX_DRONES.saturating_sub(before);
    match usize::try_from(n) {
        Ok(n) if n <= room => Some(n),
        _ => {
            let others = match before {
                0 => String::new(),
                _ => format!(", and {} come before this fleet", count(before, "drone")),
            };
            let msg = format!(
                "fleet `{fleet}` has {n} drones, more than a world may have: at most {MAX_DRONES}{others}"
            );
            cx.error(c.node.span, msg, format!("write a count of at most {room}"));
            None
        }
    }
}

/// A whole number from `min` to `max`.
fn whole(
    cx: &mut Ctx,
    what: &dyn std::fmt::Display,
    node: &Node,
    min: i64,
    max: i64,
) -> Option<i64> {
    match node.value {
        Value::Int(n) if (min..=max).contains(&n) => Some(n),
        Value::Int(n) if n < min => {
            let msg = format!("{what} must be at least {min}, found {n}");
            cx.error(node.span, msg, format!("write a whole number from {min}"));
            None
        }
        Value::Int(n) => {
            let msg = format!("{what} must be at most {max}, found {n}");
            cx.error(node.span, msg, format!("write a whole number from {min} to {max}"));
            None
        }
        _ => {
            let msg = format!("{what} must be a whole number, found {}", toml_text(node));
            cx.error(node.span, msg, format!("write a whole number such as `{}`", min.max(10)));
            None
        }
    }
}

/// The pattern of `names`, by default the fleet's name followed by the number.
fn names(
    cx: &mut Ctx,
    fleet: &str,
    key_span: Span,
    keys: &[Entry],
    first: Option<i64>,
) -> Option<Pattern> {
    let (text, span) = match get(keys, "names") {
        Some(n) => (cx.string(&KeyOf("names", Owner::Fleet(fleet)), &n.node)?, Some(n.node.span)),
        None => (format!("{fleet}{{i}}"), None),
    };
    let at = span.unwrap_or(key_span);
    let pattern = match Pattern::parse(&text) {
        Ok(p) => p,
        Err(problem) => {
            let msg = format!("`names` of fleet `{fleet}` (`{text}`) {problem}");
            cx.error(at, msg, "write a name with `{i}` where the drone's number goes, e.g. `names = \"scout{i}\"` (or `{i:03}` for three digits: `scout007`)");
            return None;
        }
    };
    let sample = pattern.name(first.unwrap_or(0) as u64);
    if !is_identifier(&sample) {
        let msg = match span {
            Some(_) => format!("the drones of fleet `{fleet}` would be named `{sample}` and so on, which mission code could not refer to"),
            None => format!("fleet `{fleet}` names its drones `{sample}` and so on, which mission code could not refer to"),
        };
        let help = match span {
            Some(_) => "use letters, digits and `_` around `{i}`, not starting with a digit, e.g. `names = \"scout{i}\"`",
            None => "give the fleet a name of letters, digits and `_` that does not start with a digit, or its drones a `names` pattern such as `names = \"scout{i}\"`",
        };
        cx.error(at, msg, help);
        return None;
    }
    Some(pattern)
}

/// `homes`, and where it is written.
fn homes(
    cx: &mut Ctx,
    fleet: &str,
    key_span: Span,
    keys: &[Entry],
    count: Option<usize>,
) -> Option<(Homes, Span)> {
    let Some(h) = get(keys, "homes") else {
        cx.error(key_span, format!("fleet `{fleet}` has no `homes`"), HOMES_HELP);
        return None;
    };
    let what = KeyOf("homes", Owner::Fleet(fleet));
    let entries = cx.table(&what, &h.node, HOMES_HELP)?;
    cx.known_keys(entries, HOMES_KEYS, &format!("`homes` of fleet `{fleet}`"));
    let part = |key: &str| format!("`{key}` of `homes` of fleet `{fleet}`");
    let corner = |cx: &mut Ctx, e: &Entry| {
        let what = part(&e.key);
        cx.point(&what, &e.node)
            .filter(|(p, _)| cx.above_ground(&what, &e.node, p[2]))
            .map(|(p, _)| p)
    };
    let only = |cx: &mut Ctx, keys: &[&str], form: &str| {
        for key in keys {
            if let Some(e) = get(entries, key) {
                let msg = format!(
                    "`{key}` is for homes on a {}, not on a {form}",
                    if form == "grid" { "ring" } else { "grid" }
                );
                cx.error(e.key_span, msg, HOMES_HELP);
            }
        }
    };
    let homes = match (get(entries, "grid"), get(entries, "ring")) {
        (Some(g), None) => {
            only(cx, &["radius"], "grid");
            let corner = corner(cx, g);
            let step = match get(entries, "spacing") {
                Some(s) => spacing(cx, &part("spacing"), &s.node),
                None => {
                    let msg = format!("`homes` of fleet `{fleet}` has a `grid` but no `spacing`");
                    cx.error(h.node.span, msg, "add `spacing = 10` (metres between neighbours), or `spacing = [10, 20]` (east, north)");
                    None
                }
            };
            let columns = match get(entries, "columns") {
                Some(c) => whole(cx, &part("columns"), &c.node, 1, i64::MAX)
                    .map(|c| usize::try_from(c).unwrap_or(usize::MAX)),
                // As many columns as rows, or one more.
                None => Some(count.map_or(1, square_side)),
            };
            Homes::Grid { corner: corner?, step: step?, columns: columns? }
        }
        (None, Some(r)) => {
            only(cx, &["spacing", "columns"], "ring");
            let center = corner(cx, r);
            let radius = match get(entries, "radius") {
                Some(r) => cx.positive(&part("radius"), &r.node),
                None => {
                    let msg = format!("`homes` of fleet `{fleet}` has a `ring` but no `radius`");
                    cx.error(
                        h.node.span,
                        msg,
                        "add `radius = 50`: metres from the centre to each home",
                    );
                    None
                }
            };
            Homes::Ring { center: center?, radius: radius? }
        }
        (Some(_), Some(r)) => {
            let msg = format!("`homes` of fleet `{fleet}` has both a `grid` and a `ring`");
            cx.error(r.key_span, msg, "keep one of them: the homes lie on a grid or on a ring");
            return None;
        }
        (None, None) => {
            let msg = format!("`homes` of fleet `{fleet}` has neither a `grid` nor a `ring`");
            cx.error(h.node.span, msg, HOMES_HELP);
            return None;
        }
    };
    if let Some(count) = count {
        let (lo, hi) = homes.bounds(count);
        if !lo.iter().chain(&hi).all(|v| v.is_finite()) {
            let msg =
                format!("the homes of fleet `{fleet}` reach beyond the numbers a world can hold");
            cx.error(h.node.span, msg, "write a smaller spacing or radius, in metres");
            return None;
        }
    }
    Some((homes, h.node.span))
}

/// The smallest side of a square of at least `n` cells.
fn square_side(n: usize) -> usize {
    let mut side = (n as f64).sqrt().ceil() as usize;
    while side.saturating_mul(side) < n {
        side += 1;
    }
    while side > 1 && (side - 1) * (side - 1) >= n {
        side -= 1;
    }
    side.max(1)
}

/// `spacing`: a number (the same east and north) or `[east, north]`, in metres, above 0.
fn spacing(cx: &mut Ctx, what: &str, node: &Node) -> Option<[f64; 2]> {
    match &node.value {
        Value::Array(items) if items.len() == 2 => {
            let east = cx.positive(&what, &items[0]);
            let north = cx.positive(&what, &items[1]);
            Some([east?, north?])
        }
        Value::Array(items) => {
            let msg = format!(
                "{what} must be a number or 2 numbers [east, north], found {}",
                count(items.len(), "number")
            );
            cx.error(
                node.span,
                msg,
                "write `spacing = 10`, or `spacing = [10, 20]` for 10 m east and 20 m north",
            );
            None
        }
        _ => cx.positive(&what, node).map(|s| [s, s]),
    }
}

/// `areas`: the pattern of their names, the polygon about each home, and where it is
/// written. `Some(None)` when the fleet has none.
#[allow(clippy::type_complexity)]
fn areas(
    cx: &mut Ctx,
    fleet: &str,
    keys: &[Entry],
    first: Option<i64>,
) -> Option<Option<(Pattern, Vec<[f64; 2]>, Span)>> {
    let Some(a) = get(keys, "areas") else { return Some(None) };
    let entries = cx.table(&KeyOf("areas", Owner::Fleet(fleet)), &a.node, AREAS_HELP)?;
    cx.known_keys(entries, AREAS_KEYS, &format!("`areas` of fleet `{fleet}`"));
    let missing = |cx: &mut Ctx, key: &str| {
        let msg = format!("`areas` of fleet `{fleet}` has no `{key}`");
        cx.error(a.node.span, msg, AREAS_HELP);
    };
    let pattern = match get(entries, "names") {
        Some(n) => {
            let text = cx.string(&format!("`names` of `areas` of fleet `{fleet}`"), &n.node);
            match text.as_deref().map(Pattern::parse) {
                Some(Ok(p)) => {
                    let sample = p.name(first.unwrap_or(0) as u64);
                    if is_identifier(&sample) {
                        Some(p)
                    } else {
                        let msg = format!("the areas of fleet `{fleet}` would be named `{sample}` and so on, which mission code could not refer to");
                        cx.error(n.node.span, msg, "use letters, digits and `_` around `{i}`, not starting with a digit, e.g. `names = \"Cell_{i}\"`");
                        None
                    }
                }
                Some(Err(problem)) => {
                    let msg = format!(
                        "`names` of `areas` of fleet `{fleet}` (`{}`) {problem}",
                        text.unwrap_or_default()
                    );
                    cx.error(n.node.span, msg, "write a name with `{i}` where the drone's number goes, e.g. `names = \"Cell_{i}\"`");
                    None
                }
                None => None,
            }
        }
        None => {
            missing(cx, "names");
            None
        }
    };
    let polygon = match get(entries, "polygon") {
        Some(p) => {
            let what = format!("`polygon` of `areas` of fleet `{fleet}`");
            cx.polygon(&what, &p.node).filter(|poly| cx.outline(&what, &p.node, poly))
        }
        None => {
            missing(cx, "polygon");
            None
        }
    };
    Some(Some((pattern?, polygon?, a.node.span)))
}

#[cfg(test)]
mod tests {
    use aviary_diagnostics::FileId;

    use super::*;

    /// Fleets together may not pass the limit either (not built here: ten million drones).
    #[test]
    fn the_drones_before_a_fleet_count_towards_the_limit() {
        let text = "count = 5000000";
        let entry = |n: i64| Entry {
            key: "count".into(),
            key_span: Span::new(0, 5),
            node: Node { span: Span::new(8, 15), value: Value::Int(n) },
        };
        let mut cx = Ctx { file: FileId(0), text, diags: Vec::new() };
        assert_eq!(
            fleet_count(&mut cx, "g", Span::new(0, 0), &[entry(5_000_000)], 5_000_000),
            Some(5_000_000)
        );
        assert!(cx.diags.is_empty());
        assert_eq!(
            fleet_count(&mut cx, "g", Span::new(0, 0), &[entry(5_000_000)], 6_000_000),
            None
        );
        assert_eq!(
            cx.diags[0].message,
            "fleet `g` has 5000000 drones, more than a world may have: at most 10000000, and 6000000 drones come before this fleet"
        );
        assert_eq!(cx.diags[0].help.as_deref(), Some("write a count of at most 4000000"));
        assert_eq!(square_side(1), 1);
        assert_eq!(square_side(2), 2);
        assert_eq!(square_side(100_000), 317);
        assert_eq!(square_side(10_000), 100);
    }
}
