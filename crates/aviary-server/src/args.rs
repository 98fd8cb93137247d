//! An operator's arguments, checked against the kinds the checker inferred before the
//! mission hears them: a leash section's parameters and a signal's values. A wrong one
//! is refused here (400, with the kind expected) instead of failing the mission later.
//!
//! The JSON forms of a value: a number (in SI units: metres, seconds, m/s, degrees, a
//! fraction for a ratio), `{"number": 200, "unit": "m"}` (a number as the language
//! writes it; `aviary ctl` sends this form), a string (a symbol or text), `true`/`false`,
//! and a position: `[x, y]` or `[x, y, z]` in metres, or `{"lat": 47.45, "lon": 13.1}`
//! (with `"alt"` above sea level: `GEO(lat, lon, alt)` as the language writes it),
//! placed by the world's one projection (`aviary_api::geo`) about the mission's origin.
//! A position, however written, must lie where the world lets a drone fly (`bounds.rs`).

use std::sync::Arc;

use aviary_api::geo::Origin;
use aviary_api::{Kind, Point, Value};
use aviary_engine::{Control, Directory, DroneAction};
use aviary_ir::{CapId, SignalId, TiVec};
use aviary_syntax::ast::Unit;
use serde_json::{Map, Value as JsonValue};

/// Larger SI magnitudes are refused: a million kilometres, thirty years. No mission means
/// them, and past them the middle layer's arithmetic (a circle's length, a square of a
/// distance) stops meaning anything or overflows to infinity.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// What an operator's request names and what its values must be, from the compiled
/// mission: the names resolve to the mission's ids ([`Directory`]), and each value is
/// checked against the kind the checker inferred.
#[derive(Clone, Debug, Default)]
pub struct Kinds {
    directory: Directory,
    /// By capability id: the kind of each parameter, in order (`None`: any).
    params: TiVec<CapId, Vec<Option<Kind>>>,
    /// By signal id: the kind of each value the signal carries.
    signals: TiVec<SignalId, Vec<Option<Kind>>>,
    /// The world's `origin`, which places a `{"lat", "lon"}` position; `None` without one.
    origin: Option<Origin>,
    /// Where a position may be; `None`: anywhere (no world was given).
    bounds: Option<Arc<crate::Bounds>>,
}

/// Why a request was refused: a value it gives (400), or a name the mission does not
/// have (409, as the engine refuses what it cannot do now).
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Refusal {
    Value(String),
    Name(String),
}

impl Kinds {
    /// What a compiled mission's requests may name, and the kinds the checker inferred
    /// for leash arguments and signal values, which the mission keeps.
    pub fn of(mission: &aviary_ir::Mission) -> Kinds {
        Kinds {
            directory: Directory::of(mission),
            params: mission.capabilities.iter().map(|c| c.param_kinds.clone()).collect(),
            signals: mission.signal_values.clone(),
            origin: mission.origin,
            bounds: None,
        }
    }

    /// These kinds, with positions held to the world's limits.
    pub fn within(mut self, bounds: crate::Bounds) -> Kinds {
        self.bounds = Some(Arc::new(bounds));
        self
    }

    /// Places `{"lat", "lon"}` positions about `origin` (the mission's, from its world).
    pub fn with_origin(mut self, origin: Origin) -> Kinds {
        self.origin = Some(origin);
        self
    }

    /// The signals an operator may raise, in the order the mission declares them.
    pub fn operator_signals(&self) -> Vec<String> {
        self.directory.operator_signals().map(|(_, name)| name.to_string()).collect()
    }

    /// The kinds of the values each operator signal carries, in its order (`None`: any
    /// value), as the ground station's Raise form reads them.
    pub fn operator_signal_values(&self) -> impl Iterator<Item = (&str, &[Option<Kind>])> {
        self.directory
            .operator_signals()
            .map(|(id, name)| (name, self.signals.get(id).map_or(&[][..], Vec::as_slice)))
    }

    /// A leash, `capability-tag action` with a section's arguments, as the engine takes
    /// it. A capability or a tag the mission does not have is left to the engine to refuse
    /// (409), since it says what runs now.
    pub(crate) fn leash(
        &self,
        capability: &str,
        tag: &str,
        action: &str,
        args: &Map<String, JsonValue>,
    ) -> Result<Control, Refusal> {
        let values = self.leash_args(capability, action, args).map_err(Refusal::Value)?;
        self.directory.leash(capability, tag, action, values).map_err(Refusal::Name)
    }

    /// A signal the mission declares for the operator (or 409, with the ones it declares
    /// and the one meant), with its values.
    pub(crate) fn signal(&self, name: &str, args: &[JsonValue]) -> Result<Control, Refusal> {
        let signal = self.directory.operator_signal(name).map_err(Refusal::Name)?;
        let args = self.signal_args(signal, name, args).map_err(Refusal::Value)?;
        Ok(Control::Signal { signal, args })
    }

    /// Steers the drone called `name` (or 409, with the name meant or the fleet).
    pub(crate) fn drone(&self, name: &str, action: DroneAction) -> Result<Control, Refusal> {
        self.directory.drone(name, action).map_err(Refusal::Name)
    }

    /// A leash's arguments, by parameter index, each name resolved once
    /// ([`Directory::param`]). A capability the mission does not have takes any value here
    /// and keeps none: the engine refuses it by name, after a value that is wrong (400)
    /// has been refused.
    fn leash_args(
        &self,
        capability: &str,
        action: &str,
        args: &Map<String, JsonValue>,
    ) -> Result<Vec<(usize, Value)>, String> {
        if aviary_api::BuiltinLeash::parse(action).is_some() {
            return match args.is_empty() {
                true => Ok(Vec::new()),
                false => Err(format!("{action} takes no arguments; only a PERFORM section does")),
            };
        }
        let cap = self.directory.capability(capability);
        let mut out = Vec::new();
        for (name, v) in args {
            let param = cap.map(|c| self.directory.param(c, name)).transpose()?;
            let kind = cap.zip(param).and_then(|(c, p)| self.params.get(c)?.get(p).copied()?);
            let value = self.value(v, kind, &format!("`{name}` of {capability}"))?;
            out.extend(param.map(|p| (p, value)));
        }
        Ok(out)
    }

    /// A signal's values as the engine takes them: as many as the signal carries.
    fn signal_args(
        &self,
        signal: SignalId,
        name: &str,
        args: &[JsonValue],
    ) -> Result<Vec<Value>, String> {
        let kinds = self.signals.get(signal).map_or(&[][..], Vec::as_slice);
        if args.len() != kinds.len() {
            let wanted: Vec<&str> =
                kinds.iter().map(|k| k.map_or("any value", Kind::describe)).collect();
            let wanted =
                if wanted.is_empty() { String::new() } else { format!(": {}", wanted.join("; ")) };
            return Err(format!(
                "{name} carries {} value(s), and {} were given{wanted}",
                kinds.len(),
                args.len()
            ));
        }
        args.iter()
            .zip(kinds)
            .enumerate()
            .map(|(i, (v, kind))| self.value(v, *kind, &format!("value {} of {name}", i + 1)))
            .collect()
    }

    /// `what` (such as "`radius` of FlyCircle") takes `kind`: the engine's value, or why
    /// not. A position must also lie where the world lets a drone fly.
    fn value(&self, v: &JsonValue, kind: Option<Kind>, what: &str) -> Result<Value, String> {
        let given = read(v).map_err(|why| format!("{what}: {why}"))?;
        let (value, shown) = convert(v, kind, given, what, self.origin)?;
        if let (Value::Position(p), Some(shown), Some(bounds)) = (&value, shown, &self.bounds) {
            if let Some(why) = bounds.refusal(*p, &shown) {
                return Err(format!("{what}: {why}"));
            }
        }
        Ok(value)
    }
}

/// A value as read from JSON, before its kind is checked.
enum Given {
    /// In SI units; with the kind its unit gives when it was written with one (or
    /// `Number` when written as `{"number": n}` with no unit).
    Number(f64, Option<Kind>),
    Word(String),
    Bool(bool),
    Position(Point),
    /// `{"lat": .., "lon": .., "alt": ..}`: degrees, and metres above sea level.
    Geo {
        lat: f64,
        lon: f64,
        alt: Option<f64>,
    },
}

fn read(v: &JsonValue) -> Result<Given, String> {
    let form = "write a number in SI units, {\"number\": 20, \"unit\": \"m\"}, a string, true or false, [x, y] or {\"lat\": 47.45, \"lon\": 13.1}";
    match v {
        JsonValue::Object(o) if o.contains_key("lat") || o.contains_key("lon") => geo(o),
        JsonValue::Number(n) => n
            .as_f64()
            .map(|x| Given::Number(x, None))
            .ok_or_else(|| format!("{n} is not a number that can be used")),
        JsonValue::Object(o) => {
            let (Some(number), true) = (
                o.get("number").and_then(JsonValue::as_f64),
                o.keys().all(|k| k == "number" || k == "unit"),
            ) else {
                return Err(format!("{v} is not a value: {form}"));
            };
            match o.get("unit") {
                None | Some(JsonValue::Null) => Ok(Given::Number(number, Some(Kind::Number))),
                Some(JsonValue::String(u)) => match Unit::parse(u) {
                    Some(unit) => Ok(Given::Number(number * unit.to_si(), Some(unit_kind(unit)))),
                    None => Err(format!(
                        "`{u}` is not a unit; the units are {}",
                        Unit::ALL.iter().map(|u| u.as_str()).collect::<Vec<_>>().join(" ")
                    )),
                },
                Some(other) => Err(format!("the unit {other} is not a string such as \"m\"")),
            }
        }
        JsonValue::String(s) => Ok(Given::Word(s.clone())),
        JsonValue::Bool(b) => Ok(Given::Bool(*b)),
        JsonValue::Array(a) if (2..=3).contains(&a.len()) && a.iter().all(JsonValue::is_number) => {
            let n: Vec<f64> = a.iter().filter_map(JsonValue::as_f64).collect();
            Ok(Given::Position(Point { x: n[0], y: n[1], z: n.get(2).copied() }))
        }
        JsonValue::Array(_) => {
            Err(format!("{v} is not a position: write [x, y] or [x, y, z] in metres"))
        }
        JsonValue::Null => Err(format!("null is not a value: {form}")),
    }
}

/// `{"lat": 47.45, "lon": 13.1}`, or with `"alt"`: `GEO(lat, lon[, alt])` in JSON.
fn geo(o: &serde_json::Map<String, JsonValue>) -> Result<Given, String> {
    let form = "write {\"lat\": 47.45, \"lon\": 13.1} in degrees, with \"alt\" in metres above sea level if the height matters";
    if let Some(k) = o.keys().find(|k| !matches!(k.as_str(), "lat" | "lon" | "alt")) {
        return Err(format!("a position by latitude and longitude has no `{k}`: {form}"));
    }
    let degrees = |key: &str, limit: f64| match o.get(key) {
        Some(JsonValue::Number(n)) => match n.as_f64() {
            Some(d) if d.abs() <= limit => Ok(d),
            _ => Err(format!("`{key}` is {n}, and must be within ±{limit} degrees")),
        },
        Some(other) => Err(format!("`{key}` must be a number of degrees, not {other}: {form}")),
        None => Err(format!("`{key}` is missing: {form}")),
    };
    let (lat, lon) = (degrees("lat", 90.0)?, degrees("lon", 180.0)?);
    let alt = match o.get("alt") {
        None | Some(JsonValue::Null) => None,
        Some(JsonValue::Number(n)) => match n.as_f64() {
            Some(a) if a.abs() <= MAX_MAGNITUDE => Some(a),
            _ => {
                return Err(format!(
                    "`alt` is {n}: give metres above sea level, at most {MAX_MAGNITUDE:e}"
                ))
            }
        },
        Some(other) => {
            return Err(format!("`alt` must be a number of metres above sea level, not {other}"))
        }
    };
    Ok(Given::Geo { lat, lon, alt })
}

/// The kind a unit gives a number, as the checker reads it (`aviary_check`'s `unit_kind`).
fn unit_kind(unit: Unit) -> Kind {
    match unit {
        Unit::Metre | Unit::Kilometre => Kind::Length,
        Unit::Second | Unit::Minute | Unit::Hour => Kind::Duration,
        Unit::MetrePerSecond | Unit::KilometrePerHour => Kind::Speed,
        Unit::Degree => Kind::Angle,
        Unit::Percent => Kind::Ratio,
    }
}

fn numeric(kind: Kind) -> bool {
    matches!(
        kind,
        Kind::Length | Kind::Duration | Kind::Speed | Kind::Angle | Kind::Ratio | Kind::Number
    )
}

/// `given` as the engine's value for `kind`, or why not; a position with how to show it
/// to the operator. `origin` places a position by latitude and longitude.
fn convert(
    v: &JsonValue,
    kind: Option<Kind>,
    given: Given,
    what: &str,
    origin: Option<Origin>,
) -> Result<(Value, Option<String>), String> {
    let value = match (kind, given) {
        (Some(Kind::Position) | None, Given::Position(p)) => {
            for c in [Some(p.x), Some(p.y), p.z].into_iter().flatten() {
                number(c, v, what)?;
            }
            return Ok((Value::Position(p), Some(aviary_api::show::point(&p))));
        }
        (Some(Kind::Position) | None, Given::Geo { lat, lon, alt }) => {
            let Some(origin) = origin else {
                return Err(format!(
                    "{what}: a position by latitude and longitude needs the world's `origin`, and this world has none: send [x, y] in metres"
                ));
            };
            let [x, y, z] = origin.place(lat, lon, alt);
            let p = Point { x, y, z: alt.map(|_| z) };
            // Where it lands, to the decimetre, so that a refusal shows the local figures.
            let near = |c: f64| (c * 10.0).round() / 10.0;
            let local =
                aviary_api::show::point(&Point { x: near(x), y: near(y), z: p.z.map(near) });
            let written = match alt {
                Some(alt) => format!("GEO({lat}, {lon}, {alt})"),
                None => format!("GEO({lat}, {lon})"),
            };
            return Ok((Value::Position(p), Some(format!("{written}, at {local},"))));
        }
        (Some(k), Given::Number(x, written)) if numeric(k) => {
            match written {
                Some(Kind::Number) if k != Kind::Number => {
                    return Err(format!(
                        "{what} is {}, and {v} has no unit: {}",
                        k.describe(),
                        example(k)
                    ))
                }
                Some(w) if w != k => {
                    return Err(format!(
                        "{what} is {}, and {v} is {}: {}",
                        k.describe(),
                        w.describe(),
                        example(k)
                    ))
                }
                _ => {}
            }
            // The middle layer takes no negative length, duration or speed (an altitude,
            // a radius, a spacing, a time to hover): it would refuse the call mid-mission.
            if matches!(k, Kind::Length | Kind::Duration | Kind::Speed) && x < 0.0 {
                return Err(format!("{what} is {} and cannot be negative, not {v}", k.describe()));
            }
            number(x, v, what).map(Value::Number)
        }
        (None, Given::Number(x, _)) => number(x, v, what).map(Value::Number),
        (Some(Kind::Symbol) | None, Given::Word(s)) => Ok(Value::Symbol(s)),
        (Some(Kind::Text), Given::Word(s)) => Ok(Value::Text(s)),
        (Some(Kind::Bool) | None, Given::Bool(b)) => Ok(Value::Bool(b)),
        (Some(k @ (Kind::Area | Kind::Actor | Kind::Remainder | Kind::Line | Kind::Path)), _) => {
            Err(format!("{what} is {}, which the operator API cannot send", k.describe()))
        }
        (Some(k), _) => Err(format!("{what} is {}, and {v} is not: {}", k.describe(), example(k))),
    };
    value.map(|value| (value, None))
}

/// A finite number within [`MAX_MAGNITUDE`].
fn number(x: f64, v: &JsonValue, what: &str) -> Result<f64, String> {
    match x.is_finite() && x.abs() <= MAX_MAGNITUDE {
        true => Ok(x),
        false => Err(format!(
            "{what} must be a finite number of at most {MAX_MAGNITUDE:e} in SI units, not {v}"
        )),
    }
}

/// How to write a value of `kind` in JSON.
fn example(kind: Kind) -> String {
    let unit = match kind {
        Kind::Length => "m",
        Kind::Duration => "s",
        Kind::Speed => "m/s",
        Kind::Angle => "deg",
        Kind::Ratio => "%",
        Kind::Number => return "write a number such as 2".into(),
        Kind::Position => {
            return "write [x, y] or [x, y, z] in metres, or {\"lat\": 47.45, \"lon\": 13.1} in degrees".into()
        }
        Kind::Symbol | Kind::Text => return "write a string such as \"Body\"".into(),
        Kind::Bool => return "write true or false".into(),
        Kind::Area | Kind::Actor | Kind::Remainder | Kind::Line | Kind::Path => {
            return String::new()
        }
    };
    let si = if kind == Kind::Ratio { "a fraction such as 0.25" } else { "a number in SI units" };
    format!("write {si}, or {{\"number\": 20, \"unit\": \"{unit}\"}}")
}

#[cfg(test)]
mod tests {
    use super::{Kinds, Refusal};
    use aviary_test_support::harness;

    fn kinds(mission: &str) -> Kinds {
        Kinds::of(&harness::compile(mission, harness::WORLD).0)
    }

    fn refusal(kinds: &Kinds, name: &str) -> Option<String> {
        match kinds.signal(name, &[]) {
            Err(Refusal::Name(why)) => Some(why),
            Ok(_) | Err(Refusal::Value(_)) => None,
        }
    }

    #[test]
    fn only_a_declared_signal_may_be_raised_and_a_refusal_lists_them() {
        let none = kinds("MISSION M:\n    ON Hold_Position:\n        a Hover WITH 1s\n");
        assert_eq!(
            refusal(&none, "Hold_Position"),
            Some("the mission declares no signal an operator may raise, so not Hold_Position: it would need `OPERATOR SIGNAL Hold_Position` in its MISSION body".into())
        );
        let two = kinds("MISSION M:\n    OPERATOR SIGNAL Hold_Position, Carry_On\n    PARALLEL:\n        ON Hold_Position:\n            a Hover WITH 1s\n        ON Found WITH what:\n            a Hover WITH 1s\n        ON Carry_On:\n            SIGNAL Found WITH 1\n");
        assert_eq!(two.operator_signals(), ["Hold_Position", "Carry_On"], "in order");
        assert_eq!(refusal(&two, "Hold_Position"), None);
        assert_eq!(
            refusal(&two, "Hold_Postion"),
            Some("the mission does not declare Hold_Postion as an operator signal: did you mean `Hold_Position`? It declares Hold_Position, Carry_On".into())
        );
        assert_eq!(
            refusal(&two, "Found"),
            Some("the mission does not declare Found as an operator signal: it declares Hold_Position, Carry_On".into()),
            "heard by the mission, raised by it, and still not the operator's"
        );
    }
}
