//! `[air]`: wind, radio, GPS noise, detection's fall with range, the spread of battery
//! capacities and random faults (docs/WORLD.md), and a drone's own `air` table. Each part
//! is off unless declared; every key is checked here, and a mistake is located.

use aviary_api::show::number;

use super::drone::{KeyOf, Owner};
use super::get;
use crate::node::{Entry, Node, Value};
use crate::read::{quoted, suggest, Ctx};
use crate::{Air, DroneAir, Falloff, FaultKind, Gps, Radio, RandomFault, Wind, World};

const AIR_KEYS: &[&str] = &["wind", "radio", "gps", "detection", "battery", "faults"];
const WIND_KEYS: &[&str] = &["speed", "from", "turbulence", "drain"];
const RADIO_KEYS: &[&str] = &["station", "range", "every"];
const GPS_KEYS: &[&str] = &["error", "correlation"];
const DETECTION_KEYS: &[&str] = &["falloff"];
const BATTERY_KEYS: &[&str] = &["capacity_spread"];
const RATE_KEYS: &[&str] = &["rate", "duration"];
const DRONE_AIR_KEYS: &[&str] = &["relay", "range", "gps_error", "faults"];
/// MIL-F-8785C's light, moderate and severe turbulence: the wind at 20 ft, 15, 30 and 45
/// knots, in m/s.
const TURBULENCE: &[(&str, f64)] =
    &[("light", 15.0 * 0.514_444), ("moderate", 30.0 * 0.514_444), ("severe", 45.0 * 0.514_444)];
/// A duration kind's outage when `[air.faults]` gives only its rate, s.
pub(crate) const DEFAULT_OUTAGE: f64 = 10.0;

const HELP: &str = "write `[air.wind]`, `[air.radio]`, `[air.gps]`, `[air.detection]`, `[air.battery]` or `[air.faults]`, each with its keys (docs/WORLD.md)";

pub(super) fn air(cx: &mut Ctx, node: &Node) -> Air {
    let mut air = Air::default();
    let Some(entries) = cx.table(&"`air`", node, HELP) else { return air };
    cx.known_keys(entries, AIR_KEYS, "[air]");
    for e in entries {
        let n = &e.node;
        match e.key.as_str() {
            "wind" => air.wind = wind(cx, e),
            "radio" => air.radio = radio(cx, e),
            "gps" => air.gps = gps(cx, n),
            "detection" => air.detection = detection(cx, n),
            "battery" => {
                let help = "write `[air.battery]` followed by `capacity_spread = 0.05`";
                if let Some(keys) = cx.table(&"`[air.battery]`", n, help) {
                    cx.known_keys(keys, BATTERY_KEYS, "[air.battery]");
                    air.capacity_spread = get(keys, "capacity_spread").and_then(|s| {
                        cx.within(&"`capacity_spread` in [air.battery]", &s.node, 0.0, 0.3)
                    });
                }
            }
            "faults" => air.faults = faults(cx, n, "[air.faults]"),
            _ => {}
        }
    }
    air
}

fn wind(cx: &mut Ctx, e: &Entry) -> Option<Wind> {
    let help = "write `[air.wind]` followed by `speed = 6` (m/s) and `from = 270` (degrees)";
    let keys = cx.table(&"`[air.wind]`", &e.node, help)?;
    cx.known_keys(keys, WIND_KEYS, "[air.wind]");
    let Some(s) = get(keys, "speed") else {
        cx.error(
            cx.header(e.node.span),
            "`[air.wind]` has no `speed`",
            "add `speed = 6`: the mean wind, in m/s",
        );
        return None;
    };
    let speed = cx.non_negative(&"`speed` in [air.wind]", &s.node);
    let from = match get(keys, "from") {
        Some(f) => cx.within(&"`from` in [air.wind]", &f.node, 0.0, 360.0),
        None if speed.is_some_and(|v| v > 0.0) => {
            let msg = "`[air.wind]` has a `speed` but no `from`";
            cx.error(s.key_span, msg, "add `from = 270`: where the wind blows from, in degrees clockwise from north (270: a west wind)");
            None
        }
        None => Some(0.0),
    };
    let turbulence = match get(keys, "turbulence") {
        None => Some(None),
        Some(t) => turbulence(cx, &t.node).map(Some),
    };
    let drain = match get(keys, "drain") {
        None => Some(0.5),
        Some(d) => cx.within(&"`drain` in [air.wind]", &d.node, 0.0, 10.0),
    };
    Some(Wind {
        speed: speed?,
        from: from?,
        turbulence: turbulence?,
        drain: drain?,
        span: s.node.span,
    })
}

/// `turbulence = "light"` (or moderate, severe), or the wind at 20 ft in m/s.
fn turbulence(cx: &mut Ctx, node: &Node) -> Option<f64> {
    let names: Vec<&str> = TURBULENCE.iter().map(|(n, _)| *n).collect();
    let help = format!(
        "write {} (MIL-F-8785C), or the wind at 6 m (20 ft) in m/s, e.g. `turbulence = 8`",
        quoted(&names)
    );
    match &node.value {
        Value::Str(s) => {
            let found = TURBULENCE.iter().find(|(n, _)| n == s).map(|(_, w)| *w);
            if found.is_none() {
                let msg = format!("unknown turbulence `{s}` in [air.wind]");
                let help = match suggest(s, names.iter().copied()) {
                    Some(m) => format!("did you mean `{m}`? Or {help}"),
                    None => help,
                };
                cx.error(node.span, msg, help);
            }
            found
        }
        _ => cx.non_negative(&"`turbulence` in [air.wind]", node),
    }
}

fn radio(cx: &mut Ctx, e: &Entry) -> Option<Radio> {
    let help = "write `[air.radio]` followed by `station = [x, y]` and `range = 800` (m)";
    let keys = cx.table(&"`[air.radio]`", &e.node, help)?;
    cx.known_keys(keys, RADIO_KEYS, "[air.radio]");
    let head = cx.header(e.node.span);
    let station = match get(keys, "station") {
        Some(s) => cx.point(&"`station` in [air.radio]", &s.node).map(|(p, _)| [p[0], p[1]]),
        None => {
            cx.error(
                head,
                "`[air.radio]` has no `station`",
                "add `station = [x, y]`: where the ground station's radio stands, in metres",
            );
            None
        }
    };
    let range = match get(keys, "range") {
        Some(r) => cx.positive(&"`range` in [air.radio]", &r.node),
        None => {
            cx.error(
                head,
                "`[air.radio]` has no `range`",
                "add `range = 800`: how far the station's radio reaches, in metres",
            );
            None
        }
    };
    let every = match get(keys, "every") {
        Some(r) => cx.positive(&"`every` in [air.radio]", &r.node),
        None => Some(0.5),
    };
    Some(Radio { station: station?, range: range?, every: every? })
}

fn gps(cx: &mut Ctx, node: &Node) -> Option<Gps> {
    let help = "write `[air.gps]` followed by `error = 2.5` (m, 1-sigma)";
    let keys = cx.table(&"`[air.gps]`", node, help)?;
    cx.known_keys(keys, GPS_KEYS, "[air.gps]");
    let error = match get(keys, "error") {
        Some(e) => cx.non_negative(&"`error` in [air.gps]", &e.node),
        None => {
            cx.error(
                cx.header(node.span),
                "`[air.gps]` has no `error`",
                "add `error = 2.5`: the 1-sigma error of each horizontal axis, in metres",
            );
            None
        }
    };
    let correlation = match get(keys, "correlation") {
        Some(c) => cx.positive(&"`correlation` in [air.gps]", &c.node),
        None => Some(60.0),
    };
    Some(Gps { error: error?, correlation: correlation? })
}

fn detection(cx: &mut Ctx, node: &Node) -> Option<Falloff> {
    let help = "write `[air.detection]` followed by `falloff = \"linear\"` or `falloff = [[0, 1], [0.5, 0.9], [1, 0]]`";
    let keys = cx.table(&"`[air.detection]`", node, help)?;
    cx.known_keys(keys, DETECTION_KEYS, "[air.detection]");
    let Some(f) = get(keys, "falloff") else {
        cx.error(cx.header(node.span), "`[air.detection]` has no `falloff`", help);
        return None;
    };
    let n = &f.node;
    match &n.value {
        Value::Str(s) if s == "linear" => Some(Falloff::Linear),
        Value::Array(items) => curve(cx, n, items, help).map(Falloff::Curve),
        _ => {
            let msg = format!(
                "`falloff` in [air.detection] must be \"linear\" or a list of points, found {}",
                n.describe()
            );
            cx.error(n.span, msg, help);
            None
        }
    }
}

/// `[[fraction, factor], ...]`: from fraction 0 to 1, rising; factors within 0 to 1,
/// never rising.
fn curve(cx: &mut Ctx, node: &Node, items: &[Node], help: &str) -> Option<Vec<[f64; 2]>> {
    let what = "a point of `falloff` in [air.detection]";
    let mut points = Vec::new();
    for item in items {
        let pair = match &item.value {
            Value::Array(xy) if xy.len() == 2 => {
                let x = cx.within(&what, &xy[0], 0.0, 1.0);
                let y = cx.within(&what, &xy[1], 0.0, 1.0);
                x.zip(y).map(|(x, y)| [x, y])
            }
            _ => {
                let msg = format!(
                    "{what} must be `[fraction of the range, factor]`, found {}",
                    item.describe()
                );
                cx.error(item.span, msg, help);
                None
            }
        };
        points.push((pair?, item.span));
    }
    let bad = |cx: &mut Ctx, span, msg: &str| {
        cx.error(span, msg.to_string(), "start at `[0, f]`, end at `[1, f]`, with fractions rising and factors never rising, e.g. `[[0, 1], [0.5, 0.9], [1, 0]]`");
        None::<()>
    };
    if points.len() < 2 || points[0].0[0] != 0.0 || points.last().is_some_and(|p| p.0[0] != 1.0) {
        bad(
            cx,
            node.span,
            "the curve `falloff` must run from fraction 0 to fraction 1 of the range",
        );
        return None;
    }
    for w in points.windows(2) {
        let ((a, _), (b, span)) = (w[0], w[1]);
        if b[0] <= a[0] {
            bad(cx, span, "the fractions of the range of `falloff` must rise from point to point");
            return None;
        }
        if b[1] > a[1] {
            bad(cx, span, "a chance of detection may not grow with range: the factors of `falloff` must never rise");
            return None;
        }
    }
    Some(points.into_iter().map(|(p, _)| p).collect())
}

/// `[air.faults]` (or a drone's `faults`): `KIND = rate` or `KIND = { rate, duration }`.
fn faults(cx: &mut Ctx, node: &Node, place: &str) -> Vec<RandomFault> {
    let help = "write one line per fault kind: `gps_loss = 0.1` (per flight hour), or `link_loss = { rate = 0.2, duration = 15 }`";
    let Some(keys) = cx.table(&format!("`{place}`"), node, help) else { return Vec::new() };
    let kinds: Vec<&str> = FaultKind::ALL.iter().map(|k| k.as_str()).collect();
    let mut out = Vec::new();
    for e in keys {
        let Some(kind) = FaultKind::from_name(&e.key) else {
            let msg = format!("unknown fault kind `{}` in {place}", e.key);
            let help = match suggest(&e.key, kinds.iter().copied()) {
                Some(s) => format!("did you mean `{s}`? The fault kinds are {}", quoted(&kinds)),
                None => format!("write one of {}", quoted(&kinds)),
            };
            cx.error(e.key_span, msg, help);
            continue;
        };
        let what = format!("the rate of `{}` in {place}", e.key);
        let (rate, duration) = match &e.node.value {
            Value::Table(t) => {
                cx.known_keys(t, RATE_KEYS, &format!("`{}` of {place}", e.key));
                let rate = match get(t, "rate") {
                    Some(r) => rate_of(cx, &what, &r.node),
                    None => {
                        cx.error(
                            e.key_span,
                            format!("`{}` in {place} has no `rate`", e.key),
                            "add `rate = 0.1`: how many per hour of flight",
                        );
                        None
                    }
                };
                let duration = match get(t, "duration") {
                    Some(d) if !kind.has_duration() => {
                        let msg = format!(
                            "`duration` applies only to `link_loss` and `gps_loss`, not to `{}`",
                            e.key
                        );
                        cx.error(d.key_span, msg, "remove `duration`");
                        None
                    }
                    Some(d) => {
                        cx.positive(&format!("`duration` of `{}` in {place}", e.key), &d.node)
                    }
                    None => None,
                };
                (rate, duration)
            }
            _ => (rate_of(cx, &what, &e.node), None),
        };
        let duration = kind.has_duration().then(|| duration.unwrap_or(DEFAULT_OUTAGE));
        if let Some(rate) = rate {
            out.push(RandomFault { kind, rate, duration });
        }
    }
    out.sort_by_key(|f| FaultKind::ALL.iter().position(|&k| k == f.kind));
    out
}

fn rate_of(cx: &mut Ctx, what: &str, node: &Node) -> Option<f64> {
    let rate = cx.number(&what, node)?;
    if rate < 0.0 {
        let msg = format!("{what} must be zero or more per flight hour, found {}", number(rate));
        cx.error(node.span, msg, "write how many times per hour of flight it happens, e.g. `0.1`");
        return None;
    }
    Some(rate)
}

/// A drone's (or a fleet's) `air = { relay = true, range = 600, gps_error = 1, faults = { ... } }`.
pub(super) fn drone_air(cx: &mut Ctx, owner: Owner, node: &Node) -> Option<DroneAir> {
    let what = KeyOf("air", owner);
    let help =
        "write `air = { relay = true, range = 600 }`, or `[drones.NAME.air]` followed by its keys";
    let keys = cx.table(&what, node, help)?;
    cx.known_keys(keys, DRONE_AIR_KEYS, &format!("`air` of {owner}"));
    let mut air = DroneAir::default();
    for e in keys {
        let n = &e.node;
        let what = format!("`{}` in `air` of {owner}", e.key);
        match e.key.as_str() {
            "relay" => match n.value {
                Value::Bool(b) => air.relay = b,
                _ => {
                    let msg = format!("{what} must be `true` or `false`, found {}", n.describe());
                    cx.error(n.span, msg, "write `relay = true`: the drone relays the link");
                }
            },
            "range" => air.range = cx.positive(&what, n),
            "gps_error" => air.gps_error = cx.non_negative(&what, n),
            "faults" => air.faults = faults(cx, n, &format!("`faults` in `air` of {owner}")),
            _ => {}
        }
    }
    Some(air)
}

/// A mean wind at least as fast as a drone's `max_airspeed` would blow it away: an error
/// at the wind's speed, naming the drones.
pub(super) fn wind_within_reach(cx: &mut Ctx, world: &World) {
    let Some(wind) = &world.air.wind else { return };
    let mut slow = world.drones.iter().filter(|d| d.max_airspeed <= wind.speed);
    let Some(first) = slow.next() else { return };
    let more = slow.count();
    let who = match more {
        0 => format!("drone `{}` (max_airspeed {} m/s)", first.name, number(first.max_airspeed)),
        n => format!(
            "{} drones, the first `{}` (max_airspeed {} m/s)",
            n + 1,
            first.name,
            number(first.max_airspeed)
        ),
    };
    let msg = format!(
        "a wind of {} m/s is as fast as {who} or faster: it could not fly against it",
        number(wind.speed)
    );
    cx.error(
        wind.span,
        msg,
        "lower the wind's `speed`, or give the drones a higher `max_airspeed` (it defaults to `max_speed`)",
    );
}
