//! `[sensors.KIND]`, and the simulator's `[[targets]]` and `[[faults]]`.

use super::get;
use crate::node::{Entry, Node, Value};
use crate::read::{quoted, suggest, Ctx};
use crate::{Fault, FaultKind, Sensor, Target};

const SENSOR_KEYS: &[&str] = &["detects", "range", "probability"];
const TARGET_KEYS: &[&str] = &["kind", "at"];
const FAULT_KEYS: &[&str] = &["drone", "at", "kind", "duration"];

pub(super) fn sensors(cx: &mut Ctx, node: &Node) -> Vec<Sensor> {
    let help = "write one table per sensor kind: `[sensors.thermal]` followed by `detects = [\"Body\"]` and `range = 20`";
    let Some(entries) = cx.table(&"`sensors`", node, help) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for e in entries {
        let kind = &e.key;
        let Some(keys) = cx.table(&format!("sensor `{kind}`"), &e.node, help) else {
            continue;
        };
        cx.known_keys(keys, SENSOR_KEYS, &format!("[sensors.{kind}]"));
        let detects = match get(keys, "detects") {
            Some(d) => cx.strings(&format!("`detects` of sensor `{kind}`"), &d.node).map(|kinds| {
                for (name, span) in &kinds {
                    cx.identifier("target kind", name, *span);
                }
                kinds.into_iter().map(|(name, _)| name).collect()
            }),
            None => {
                let msg = format!("sensor `{kind}` has no `detects`");
                cx.error(
                    e.key_span,
                    msg,
                    "add `detects = [\"Body\"]`: the kinds of target it finds",
                );
                None
            }
        };
        let range = match get(keys, "range") {
            Some(r) => cx.positive(&format!("`range` of sensor `{kind}`"), &r.node),
            None => {
                let msg = format!("sensor `{kind}` has no `range`");
                cx.error(e.key_span, msg, "add `range = 20`: metres from the drone's ground point");
                None
            }
        };
        let probability = match get(keys, "probability") {
            Some(p) => cx.within(&format!("`probability` of sensor `{kind}`"), &p.node, 0.0, 1.0),
            None => Some(1.0),
        };
        if let (Some(detects), Some(range), Some(probability)) = (detects, range, probability) {
            out.push(Sensor { kind: kind.clone(), detects, range, probability, span: e.key_span });
        }
    }
    out
}

/// The tables of a `[[name]]` list, each with the span of its header.
fn entries<'n>(
    cx: &mut Ctx,
    name: &str,
    node: &'n Node,
    help: &str,
) -> Vec<(&'n [Entry], aviary_diagnostics::Span)> {
    let Value::Array(items) = &node.value else {
        let msg = format!("`{name}` must be a list of tables, found {}", node.describe());
        cx.error(node.span, msg, help);
        return Vec::new();
    };
    let mut out = Vec::new();
    for item in items {
        let what = format!("an entry of `{name}`");
        if let Some(keys) = cx.table(&what, item, help) {
            out.push((keys, cx.header(item.span)));
        }
    }
    out
}

/// `fence`: the site's geofence; a target outside it can never be flown to.
pub(super) fn targets(cx: &mut Ctx, node: &Node, fence: Option<&[[f64; 2]]>) -> Vec<Target> {
    let help = "write each target as `[[targets]]` followed by `kind = \"Body\"` and `at = [x, y]`";
    let mut out = Vec::new();
    for (keys, head) in entries(cx, "targets", node, help) {
        cx.known_keys(keys, TARGET_KEYS, "[[targets]]");
        let kind = match get(keys, "kind") {
            Some(k) => cx
                .string(&"`kind` of a target", &k.node)
                .filter(|kind| cx.identifier("target kind", kind, k.node.span)),
            None => {
                cx.error(
                    head,
                    "a target has no `kind`",
                    "add `kind = \"Body\"`: what a sensor can find",
                );
                None
            }
        };
        let at = match get(keys, "at") {
            Some(a) => cx.point(&"`at` of a target", &a.node).filter(|(p, _)| {
                let (inside, grounded) = (fence.is_none_or(|f| aviary_api::geometry::contains(f, [p[0], p[1]])), cx.above_ground(&"a target", &a.node, p[2]));
                if !inside {
                    let msg = format!("the target at {} is outside the geofence, where no drone may fly to find it", crate::read::shown([p[0], p[1]]));
                    cx.error(a.node.span, msg, "move the target inside the geofence, or remove it");
                }
                inside && grounded
            }),
            None => {
                cx.error(
                    head,
                    "a target has no `at`",
                    "add `at = [x, y]`: where it is, in metres",
                );
                None
            }
        };
        if let (Some(kind), Some((at, _))) = (kind, at) {
            out.push(Target { kind, at });
        }
    }
    out
}

pub(super) fn faults(cx: &mut Ctx, node: &Node, drones: &[&str]) -> Vec<Fault> {
    let help = "write each fault as `[[faults]]` followed by `drone = \"NAME\"`, `at = 60` (seconds) and `kind = \"crash\"`";
    let kinds: Vec<&str> = FaultKind::ALL.iter().map(|k| k.as_str()).collect();
    let mut out = Vec::new();
    for (keys, head) in entries(cx, "faults", node, help) {
        cx.known_keys(keys, FAULT_KEYS, "[[faults]]");
        let missing = |cx: &mut Ctx, key: &str, help: String| {
            cx.error(head, format!("a fault has no `{key}`"), help);
        };
        let drone = match get(keys, "drone") {
            Some(d) => cx.string(&"`drone` of a fault", &d.node).filter(|name| {
                let known = drones.contains(&name.as_str());
                if !known {
                    fault_drone(cx, name, d, drones);
                }
                known
            }),
            None => {
                missing(cx, "drone", "add `drone = \"NAME\"`: the drone it happens to".into());
                None
            }
        };
        let at = match get(keys, "at") {
            Some(a) => fault_time(cx, &a.node),
            None => {
                missing(cx, "at", "add `at = 60`: when it happens, in mission seconds".into());
                None
            }
        };
        let kind = match get(keys, "kind") {
            Some(k) => cx.string(&"`kind` of a fault", &k.node).and_then(|name| {
                let kind = FaultKind::from_name(&name);
                if kind.is_none() {
                    let msg = format!("unknown fault kind `{name}`");
                    let help = match suggest(&name, kinds.iter().copied()) {
                        Some(s) => {
                            format!("did you mean `{s}`? The fault kinds are {}", quoted(&kinds))
                        }
                        None => format!("write one of {}", quoted(&kinds)),
                    };
                    cx.error(k.node.span, msg, help);
                }
                kind.map(|kind| (kind, k))
            }),
            None => {
                missing(
                    cx,
                    "kind",
                    format!("add `kind = \"crash\"`; the fault kinds are {}", quoted(&kinds)),
                );
                None
            }
        };
        let duration = get(keys, "duration");
        let seconds = duration.and_then(|d| cx.positive(&"`duration` of a fault", &d.node));
        match (kind, duration) {
            (Some((kind, k)), None) if kind.has_duration() => {
                let msg = format!("a `{}` fault needs a `duration`", kind.as_str());
                cx.error(k.node.span, msg, "add `duration = 10`: how many seconds it lasts");
            }
            (Some((kind, _)), Some(d)) if !kind.has_duration() => {
                let msg = format!(
                    "`duration` applies only to `link_loss` and `gps_loss` faults, not to `{}`",
                    kind.as_str()
                );
                cx.error(d.key_span, msg, "remove `duration`");
            }
            _ => {}
        }
        if let (Some(drone), Some((at, latest)), Some((kind, _))) = (drone, at, kind) {
            out.push(Fault { drone, at, latest, kind, duration: seconds, span: head });
        }
    }
    out
}

/// `at`: a time, or a range `[earliest, latest]` to draw it from; seconds, 0 or more.
fn fault_time(cx: &mut Ctx, node: &Node) -> Option<(f64, Option<f64>)> {
    let help = "write the mission time in seconds, e.g. `at = 60`, or a range to draw it from, e.g. `at = [30, 90]`";
    let seconds = |cx: &mut Ctx, node: &Node| {
        cx.number(&"`at` of a fault", node).filter(|&t| {
            if t < 0.0 {
                let msg = format!(
                    "`at` of a fault must be zero or more seconds, found {}",
                    aviary_api::show::number(t)
                );
                cx.error(node.span, msg, help);
            }
            t >= 0.0
        })
    };
    let Value::Array(items) = &node.value else { return seconds(cx, node).map(|t| (t, None)) };
    if items.len() != 2 {
        let msg = format!(
            "`at` of a fault must be a time or a range [earliest, latest], found {}",
            crate::read::count(items.len(), "number")
        );
        cx.error(node.span, msg, help);
        return None;
    }
    let (earliest, latest) = (seconds(cx, &items[0]), seconds(cx, &items[1]));
    let (earliest, latest) = (earliest?, latest?);
    if earliest > latest {
        let msg = format!(
            "the range `at` of a fault runs from {} back to {}",
            aviary_api::show::number(earliest),
            aviary_api::show::number(latest)
        );
        cx.error(node.span, msg, "write the earlier time first, e.g. `at = [30, 90]`");
        return None;
    }
    Some((earliest, Some(latest)))
}

fn fault_drone(cx: &mut Ctx, name: &str, e: &Entry, drones: &[&str]) {
    let msg = format!("the fault names drone `{name}`, which is not in `[drones]`");
    let help = match suggest(name, drones.iter().copied()) {
        Some(s) => format!("did you mean `{s}`?"),
        None if drones.is_empty() => format!("define it as `[drones.{name}]`"),
        None if drones.len() <= 10 => format!("name one of the drones: {}", quoted(drones)),
        None => format!(
            "name one of the drones, such as {}, ... ({} in all)",
            quoted(&drones[..10]),
            drones.len()
        ),
    };
    cx.error(e.node.span, msg, help);
}
