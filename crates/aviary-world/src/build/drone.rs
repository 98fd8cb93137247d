//! `[drones.NAME]`: the known keys, the backend, and every other key as an attribute.
//! A fleet's keys other than its own (`fleet.rs`) are read here too, once for all its
//! drones.

use aviary_diagnostics::Span;

use super::get;
use std::sync::Arc;

use crate::hash::{QuickMap, QuickSet};
use crate::node::{Entry, Node, Value};
use crate::read::{quoted, suggest, toml_text, Ctx};
use crate::{AttributeValue, Backend, Drone, Group, Mavlink, BUILTIN_SENSORS};

const BACKEND_KEYS: &[&str] = &["backend", "mavlink", "system_id", "signing_key"];
/// Every key `read_keys` reads (the backend's too): a key a small edit from one of these
/// is taken for a misspelling of it, not for an attribute (docs/WORLD.md).
const DRONE_KEYS: &[&str] = &[
    "home",
    "group",
    "sensors",
    "payload",
    "max_speed",
    "max_airspeed",
    "climb_rate",
    "descent_rate",
    "acceleration",
    "land_speed",
    "land_speed_below",
    "return_altitude",
    "return_loiter",
    "takeoff_speed",
    "return_speed",
    "battery",
    "endurance",
    "battery_capacity",
    "flight_current",
    "air",
    "backend",
    "mavlink",
    "system_id",
    "signing_key",
];
const SCHEMES: &[&str] =
    &["tcp", "tcpin", "tcpout", "udp", "udpin", "udpout", "udpbcast", "serial"];
/// Telemetry fields: `d.speed` reads these, so no attribute may take their names.
const TELEMETRY: &[&str] = &["position", "altitude", "speed", "heading", "state", "link", "wind"];
const ADDRESS_HELP: &str =
    "write `mavlink = \"udp:127.0.0.1:14550\"`, `\"tcp:HOST:PORT\"` or `\"agent:NAME\"` (schemes: tcp, tcpin, tcpout, udp, udpin, udpout, udpbcast, serial, agent)";

/// The drones of `[drones.NAME]` and `[fleets.NAME]`, in file order. What needs other
/// tables (the sensors' kinds) waits for [`Drones::finish`].
#[derive(Default)]
pub(super) struct Drones {
    pub out: Vec<Drone>,
    /// The fleets, each with the range of its drones in `out`.
    pub fleets: Vec<super::fleet::FleetInfo>,
    /// The areas of fleets that give each drone one, in order.
    pub areas: Vec<crate::Area>,
    /// In order of first appearance, members in the drones' file order.
    pub groups: Vec<Group>,
    /// Each group's index and shared name.
    group_index: QuickMap<String, (usize, Arc<str>)>,
    /// Attribute keys, each kept once.
    keys: QuickSet<Arc<str>>,
    /// (drone, its sensor's index, span) of every sensor a drone's table names.
    sensors: Vec<(usize, usize, Span)>,
    /// (fleet, sensor, span) of every sensor a fleet names.
    pub(super) fleet_sensors: Vec<(String, String, Span)>,
    /// Entries that are not tables, each with the number of drones before it.
    others: Vec<(usize, String)>,
}

pub(super) const HELP: &str =
    "write one table per drone: `[drones.NAME]` followed by `home = [x, y]`";

impl Drones {
    /// One entry of `[drones]`; its table is dropped once read.
    pub fn entry(&mut self, cx: &mut Ctx, e: Entry) {
        cx.identifier("drone", &e.key, e.key_span);
        if !matches!(e.node.value, Value::Table(_)) {
            cx.table(&Owner::Drone(&e.key), &e.node, HELP);
            self.others.push((self.out.len(), e.key));
            return;
        }
        let Entry { key, key_span, node: Node { value: Value::Table(keys), .. } } = e else {
            return;
        };
        if get(&keys, "home").is_none() {
            let msg = format!("drone `{key}` has no `home`");
            cx.error(
                key_span,
                msg,
                "add `home = [x, y]`: where the drone starts and lands, in metres",
            );
        }
        let index = self.out.len();
        let (mut d, group) = self.read_keys(cx, Owner::Drone(&key), key_span, &keys, index);
        if let Some(g) = group {
            self.groups[g].members.push(index);
        }
        d.name = key;
        self.out.push(d);
    }

    /// Checks every drone's sensors against `[sensors]`.
    pub fn finish(&self, cx: &mut Ctx, sensor_kinds: &[String]) {
        for &(d, i, span) in &self.sensors {
            let drone = &self.out[d];
            check_sensor(cx, Owner::Drone(&drone.name), &drone.sensors[i], span, sensor_kinds);
        }
        for (fleet, kind, span) in &self.fleet_sensors {
            check_sensor(cx, Owner::Fleet(fleet), kind, *span, sensor_kinds);
        }
    }

    /// Every key of `[drones]`, in file order, tables or not.
    pub fn names(&self) -> Vec<&str> {
        let mut others = self.others.iter().peekable();
        let mut names = Vec::with_capacity(self.out.len() + self.others.len());
        for (i, d) in self.out.iter().enumerate() {
            while let Some((_, name)) = others.next_if(|(before, _)| *before == i) {
                names.push(name.as_str());
            }
            names.push(d.name.as_str());
        }
        names.extend(others.map(|(_, name)| name.as_str()));
        names
    }

    /// The attribute key `key`, shared with every drone that has it.
    pub(super) fn key(&mut self, key: &str) -> Arc<str> {
        match self.keys.get(key) {
            Some(shared) => shared.clone(),
            None => {
                let shared: Arc<str> = key.into();
                self.keys.insert(shared.clone());
                shared
            }
        }
    }

    /// A drone as `keys` describe it, without its name, and the index of its group (the
    /// caller makes it a member). `index`: where the drone (or a fleet's first) goes in
    /// `out`. A fleet's own keys are not among `keys`.
    pub(super) fn read_keys(
        &mut self,
        cx: &mut Ctx,
        owner: Owner,
        key_span: Span,
        keys: &[Entry],
        index: usize,
    ) -> (Drone, Option<usize>) {
        let mut d = defaults(key_span);
        let mut group_index = None;
        let mut attributes = Vec::new();
        for k in keys {
            // Said only in a message: not formatted unless one is written.
            let what = KeyOf(&k.key, owner);
            let n = &k.node;
            match k.key.as_str() {
                "home" => {
                    d.home = cx
                        .point(&what, n)
                        .filter(|(p, _)| cx.above_ground(&what, n, p[2]))
                        .map_or(d.home, |(p, _)| p)
                }
                "group" => {
                    if let Some((g, shared)) = self.group(cx, &what, n) {
                        group_index = Some(g);
                        d.group = Some(shared);
                    }
                }
                "sensors" => d.sensors = self.sensors(cx, &what, n, index),
                "payload" => {
                    let mut payload = Vec::new();
                    for (kind, span) in cx.strings(&what, n).unwrap_or_default() {
                        cx.identifier("payload kind", &kind, span);
                        payload.push(kind);
                    }
                    d.payload = payload.into();
                }
                "max_speed" => d.max_speed = cx.positive(&what, n).unwrap_or(d.max_speed),
                "climb_rate" => d.climb_rate = cx.positive(&what, n).unwrap_or(d.climb_rate),
                "acceleration" => d.acceleration = cx.positive(&what, n).unwrap_or(d.acceleration),
                "endurance" => d.endurance = cx.positive(&what, n).unwrap_or(d.endurance),
                "battery" => d.battery = cx.within(&what, n, 0.0, 100.0).unwrap_or(d.battery),
                "descent_rate" => d.descent_rate = cx.positive(&what, n).unwrap_or(d.descent_rate),
                "land_speed" => d.land_speed = cx.positive(&what, n).unwrap_or(d.land_speed),
                "land_speed_below" => {
                    d.land_speed_below = cx.non_negative(&what, n).unwrap_or(d.land_speed_below)
                }
                "return_altitude" => {
                    d.return_altitude = cx.non_negative(&what, n).unwrap_or(d.return_altitude)
                }
                "return_loiter" => {
                    d.return_loiter = cx.non_negative(&what, n).unwrap_or(d.return_loiter)
                }
                "takeoff_speed" => {
                    d.takeoff_speed = cx.positive(&what, n).unwrap_or(d.takeoff_speed)
                }
                "return_speed" => d.return_speed = cx.positive(&what, n).unwrap_or(d.return_speed),
                "max_airspeed" => d.max_airspeed = cx.positive(&what, n).unwrap_or(d.max_airspeed),
                "battery_capacity" => {
                    d.battery_capacity = cx.positive(&what, n).or(d.battery_capacity)
                }
                "flight_current" => d.flight_current = cx.positive(&what, n).or(d.flight_current),
                "air" => d.air = super::air::drone_air(cx, owner, n).map(Box::new),
                key if BACKEND_KEYS.contains(&key) => {}
                _ => {
                    if let Some((key, value)) = attribute(cx, owner, k) {
                        attributes.push((self.key(key), value));
                    }
                }
            }
        }
        follow_other_keys(&mut d);
        d.backend = backend(cx, owner, keys);
        d.attributes = attributes.into();
        (d, group_index)
    }

    /// `group = "NAME"`: the group's index and shared name; a group is made when it is
    /// first named.
    fn group(&mut self, cx: &mut Ctx, what: &KeyOf, n: &Node) -> Option<(usize, Arc<str>)> {
        // Read in place: most drones name a group that exists already.
        let Value::Str(group) = &n.value else {
            cx.string(what, n);
            return None;
        };
        if !cx.identifier("group", group, n.span) {
            return None;
        }
        let (g, shared) = match self.group_index.get(group.as_str()) {
            Some((g, shared)) => (*g, shared.clone()),
            None => {
                let shared: Arc<str> = group.as_str().into();
                self.group_index.insert(group.clone(), (self.groups.len(), shared.clone()));
                self.groups.push(Group {
                    name: group.clone(),
                    members: Vec::new(),
                    spans: Vec::new(),
                });
                (self.groups.len() - 1, shared)
            }
        };
        // A fleet's drones share its one `group` string.
        let spans = &mut self.groups[g].spans;
        if !spans.contains(&n.span) {
            spans.push(n.span);
        }
        Some((g, shared))
    }

    /// `sensors = [...]`, each kept to be checked against `[sensors]` once that is read
    /// (`index`: the drone's, or its fleet's first drone's, in `out`).
    fn sensors(&mut self, cx: &mut Ctx, what: &KeyOf, n: &Node, index: usize) -> Box<[String]> {
        let mut sensors = Vec::new();
        for (kind, span) in cx.strings(what, n).unwrap_or_default() {
            match what.1 {
                Owner::Drone(_) => self.sensors.push((index, sensors.len(), span)),
                Owner::Fleet(fleet) => {
                    self.fleet_sensors.push((fleet.to_owned(), kind.clone(), span))
                }
            }
            sensors.push(kind);
        }
        sensors.into()
    }
}

/// A drone with the figures of a drone whose table gives none (its span: its table's).
/// NaN: follows another key (see [`follow_other_keys`]).
fn defaults(span: Span) -> Drone {
    Drone {
        name: String::new(),
        home: [0.0; 3],
        group: None,
        sensors: Box::default(),
        payload: Box::default(),
        max_speed: 10.0,
        climb_rate: 3.0,
        acceleration: 3.0,
        battery: 100.0,
        endurance: 1800.0,
        descent_rate: f64::NAN,
        land_speed: f64::NAN,
        land_speed_below: 10.0,
        return_altitude: 10.0,
        return_loiter: 0.0,
        takeoff_speed: f64::NAN,
        return_speed: f64::NAN,
        max_airspeed: f64::NAN,
        battery_capacity: None,
        flight_current: None,
        backend: Backend::Sim,
        attributes: Box::default(),
        air: None,
        span,
    }
}

/// Defaults that follow other keys of the same drone.
fn follow_other_keys(d: &mut Drone) {
    if d.descent_rate.is_nan() {
        d.descent_rate = d.climb_rate;
    }
    if d.land_speed.is_nan() {
        d.land_speed = d.descent_rate;
    }
    if d.takeoff_speed.is_nan() {
        d.takeoff_speed = d.climb_rate;
    }
    if d.return_speed.is_nan() {
        d.return_speed = d.max_speed;
    }
    if d.max_airspeed.is_nan() {
        d.max_airspeed = d.max_speed;
    }
    if let Some(endurance) = Drone::endurance_from_battery(d.battery_capacity, d.flight_current) {
        d.endurance = endurance;
    }
}

fn check_sensor(cx: &mut Ctx, owner: Owner, kind: &str, span: Span, defined: &[String]) {
    if defined.iter().any(|k| k == kind) || BUILTIN_SENSORS.contains(&kind) {
        return;
    }
    let known: Vec<&str> =
        defined.iter().map(String::as_str).chain(BUILTIN_SENSORS.iter().copied()).collect();
    let msg = format!("{owner} has sensor `{kind}`, but no `[sensors.{kind}]` defines it");
    let help = match suggest(kind, known.iter().copied()) {
        Some(s) => format!("did you mean `{s}`?"),
        None => format!(
            "add a `[sensors.{kind}]` table with `detects` and `range`, or use one of {}",
            quoted(&known)
        ),
    };
    cx.error(span, msg, help);
}

fn attribute<'e>(cx: &mut Ctx, owner: Owner, e: &'e Entry) -> Option<(&'e str, AttributeValue)> {
    let key = &e.key;
    if TELEMETRY.contains(&key.as_str()) {
        let msg = match owner {
            Owner::Drone(drone) => format!(
                "attribute `{key}` of drone `{drone}` has the name of a telemetry field, so `{drone}.{key}` could not read it"
            ),
            Owner::Fleet(fleet) => format!(
                "attribute `{key}` of fleet `{fleet}` has the name of a telemetry field, so `.{key}` of its drones could not read it"
            ),
        };
        let help = format!("rename the attribute; the telemetry fields are {}", quoted(TELEMETRY));
        cx.error(e.key_span, msg, help);
        return None;
    }
    if let Some(known) = misspelt_key(key, owner) {
        let msg = format!("unknown key `{key}` in {owner}: too close to the key `{known}` to be taken for an attribute");
        let help = format!(
            "did you mean `{known}`? An attribute of a drone must not be a small edit away from a key of its table; rename it if it is meant as one"
        );
        cx.error(e.key_span, msg, help);
        return None;
    }
    if !cx.identifier("attribute", key, e.key_span) {
        return None;
    }
    let value = match &e.node.value {
        Value::Int(_) | Value::Float(_) => {
            AttributeValue::Number(cx.number(&Named("attribute", key), &e.node)?)
        }
        Value::Str(s) => AttributeValue::Text(s.clone()),
        Value::Bool(b) => AttributeValue::Bool(*b),
        _ => AttributeValue::Other(toml_text(&e.node)),
    };
    Some((key, value))
}

/// The known key that `key`, unknown in `owner`'s table, is likely a misspelling of: a
/// drone's keys, and a fleet's own too for a fleet.
fn misspelt_key(key: &str, owner: Owner) -> Option<&'static str> {
    let fleet_keys = match owner {
        Owner::Drone(_) => &[][..],
        Owner::Fleet(_) => super::fleet::FLEET_KEYS,
    };
    suggest(key, DRONE_KEYS.iter().chain(fleet_keys).copied())
}

fn backend(cx: &mut Ctx, owner: Owner, keys: &[Entry]) -> Backend {
    let what = |key: &str| format!("{}", KeyOf(key, owner));
    let chosen =
        get(keys, "backend").and_then(|b| Some((cx.string(&what("backend"), &b.node)?, b)));
    let address =
        get(keys, "mavlink").and_then(|m| Some((cx.string(&what("mavlink"), &m.node)?, m)));
    if let Some((address, m)) = &address {
        check_address(cx, owner, address, m.node.span);
    }
    let system_id = get(keys, "system_id").and_then(|s| system_id(cx, owner, s));
    let signing_key =
        get(keys, "signing_key").and_then(|s| cx.string(&what("signing_key"), &s.node));
    let mavlink = match (&chosen, &address) {
        (Some((b, e)), _) if !["sim", "mavlink"].contains(&b.as_str()) => {
            let msg = format!("unknown backend `{b}` for {owner}");
            let help = "write `backend = \"sim\"` (the default), or give a `mavlink = \"udp:HOST:PORT\"` address";
            cx.error(e.node.span, msg, help);
            false
        }
        (Some((b, e)), Some(_)) if b == "sim" => {
            let msg = format!("{owner} has `backend = \"sim\"` and a `mavlink` address");
            let help = "remove `backend = \"sim\"` to fly it over MAVLink, or remove `mavlink` to simulate it";
            cx.error(e.node.span, msg, help);
            false
        }
        (Some((b, e)), None) if b == "mavlink" => {
            let msg = format!("{owner} has `backend = \"mavlink\"` but no `mavlink` address");
            cx.error(e.node.span, msg, ADDRESS_HELP);
            false
        }
        (_, address) => address.is_some() || get(keys, "mavlink").is_some(),
    };
    if !mavlink {
        for key in ["system_id", "signing_key"] {
            let Some(e) = get(keys, key) else { continue };
            let msg = format!("{} applies only to a MAVLink drone", KeyOf(key, owner));
            let help = "add a `mavlink = \"udp:HOST:PORT\"` address, or remove this key";
            cx.error(e.key_span, msg, help);
        }
        return Backend::Sim;
    }
    let address = address.map(|(a, _)| a).unwrap_or_default();
    Backend::Mavlink(Box::new(Mavlink { address, system_id, signing_key }))
}

fn system_id(cx: &mut Ctx, owner: Owner, e: &Entry) -> Option<u8> {
    match e.node.value {
        Value::Int(i) if (1..=255).contains(&i) => u8::try_from(i).ok(),
        _ => {
            let msg = format!(
                "{} must be a whole number from 1 to 255, found {}",
                KeyOf("system_id", owner),
                toml_text(&e.node)
            );
            cx.error(e.node.span, msg, "write the MAVLink system id, e.g. `system_id = 1`");
            None
        }
    }
}

/// `SCHEME:HOST:PORT` (for `serial`, `serial:DEVICE:BAUD`), or `agent:NAME`.
fn check_address(cx: &mut Ctx, owner: Owner, address: &str, span: Span) {
    if let Some(name) = address.strip_prefix("agent:") {
        if let Err(why) = crate::agent_name(name) {
            let msg = format!("the `mavlink` address `{address}` of {owner}: {why}");
            cx.error(
                span,
                msg,
                "write the name `aviary agent --name NAME` was given, e.g. `agent:field-1`",
            );
        }
        return;
    }
    let parts = address.split_once(':').and_then(|(scheme, rest)| {
        let (host, port) = rest.rsplit_once(':')?;
        Some((scheme, host, port))
    });
    let problem = match parts {
        None => "is not `SCHEME:HOST:PORT`".to_owned(),
        Some((scheme, _, _)) if !SCHEMES.contains(&scheme) => {
            format!("has unknown scheme `{scheme}`")
        }
        Some((_, "", _)) => "has no host".to_owned(),
        Some(("serial", _, baud)) if baud.parse::<u32>().is_err() => {
            format!("has `{baud}` where the baud rate belongs")
        }
        Some((scheme, _, port)) if scheme != "serial" && port.parse::<u16>().is_err() => {
            format!("has `{port}` where the port number (0 to 65535) belongs")
        }
        Some(_) => return,
    };
    let msg = format!("the `mavlink` address `{address}` of {owner} {problem}");
    cx.error(span, msg, ADDRESS_HELP);
}

/// Whose keys are read, for messages: "drone `NAME`" or "fleet `NAME`".
#[derive(Clone, Copy)]
pub(super) enum Owner<'a> {
    Drone(&'a str),
    Fleet(&'a str),
}

impl std::fmt::Display for Owner<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Owner::Drone(name) => write!(f, "drone `{name}`"),
            Owner::Fleet(name) => write!(f, "fleet `{name}`"),
        }
    }
}

/// "`KEY` of drone `NAME`", for messages.
pub(super) struct KeyOf<'a>(pub &'a str, pub Owner<'a>);

impl std::fmt::Display for KeyOf<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "`{}` of {}", self.0, self.1)
    }
}

/// "attribute `NAME`", for messages.
pub(super) struct Named<'a>(pub &'static str, pub &'a str);

impl std::fmt::Display for Named<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} `{}`", self.0, self.1)
    }
}
