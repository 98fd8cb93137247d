//! An operator's arguments, checked against the kinds the checker inferred before the
//! mission hears them: a leash section's parameters and a signal's values. A wrong one
//! is refused here (400, with the kind expected) instead of failing the mission later.
//!
//! The JSON forms of a value: a number (in SI units: metres, seconds, m/s, degrees, a
//! fraction for a ratio), `{"number": 200, "unit": "m"}` (a number as the language
//! writes it; `aviary ctl` sends this form), a string (a symbol or text), `true`/`false`,
//! and `[x, y]` or `[x, y, z]` (a position in metres).

use std::collections::HashMap;

use aviary_api::{Kind, Point, Value};
use aviary_syntax::ast::Unit;
use serde_json::{Map, Value as JsonValue};

/// Larger SI magnitudes are refused: a million kilometres, thirty years. No mission means
/// them, and past them the middle layer's arithmetic (a circle's length, a square of a
/// distance) stops meaning anything or overflows to infinity.
pub const MAX_MAGNITUDE: f64 = 1e9;

/// What the mission's operator-facing arguments must be, from the compiled mission.
#[derive(Clone, Debug, Default)]
pub struct Kinds {
    capabilities: HashMap<String, Vec<(String, Option<Kind>)>>,
    signals: HashMap<String, Vec<Option<Kind>>>,
    /// The signals the mission declares with `OPERATOR SIGNAL`, in the order written: the
    /// only ones an operator may raise.
    operator: Vec<String>,
}

impl Kinds {
    /// What a compiled mission's leash arguments and signal values must be: the kinds the
    /// checker inferred, which the mission keeps.
    pub fn of(mission: &aviary_ir::Mission) -> Kinds {
        let mut kinds = Kinds::default();
        for c in &mission.capabilities {
            kinds.capability(
                &c.name,
                c.params.iter().cloned().zip(c.param_kinds.iter().copied()).collect(),
            );
        }
        for (name, values) in mission.signals.iter().zip(&mission.signal_values) {
            kinds.signal(name, values.clone());
        }
        for &id in &mission.operator_signals {
            if let Some(name) = mission.signals.get(id) {
                kinds.operator_signal(name);
            }
        }
        kinds
    }

    /// A capability's parameters, in order, with each one's kind (`None`: any).
    pub fn capability(&mut self, name: &str, params: Vec<(String, Option<Kind>)>) {
        self.capabilities.insert(name.to_string(), params);
    }
    /// The values a signal carries, in order, with each one's kind (`None`: any).
    pub fn signal(&mut self, name: &str, values: Vec<Option<Kind>>) {
        self.signals.insert(name.to_string(), values);
    }

    /// Lets the operator raise `name` (`OPERATOR SIGNAL name` in the mission).
    pub fn operator_signal(&mut self, name: &str) {
        if !self.operator.iter().any(|n| n == name) {
            self.operator.push(name.to_string());
        }
    }

    /// The signals an operator may raise, in the order the mission declares them.
    pub fn operator_signals(&self) -> &[String] {
        &self.operator
    }

    /// Whether the operator may raise `name`; if not, why, with the signals the mission
    /// declares and the one meant when one is close.
    pub(crate) fn may_raise(&self, name: &str) -> Result<(), String> {
        if self.operator.iter().any(|n| n == name) {
            return Ok(());
        }
        let declared: Vec<&str> = self.operator.iter().map(String::as_str).collect();
        let why = aviary_ir::undeclared_signal(name, &declared);
        Err(match declared.is_empty() {
            true => format!("{why}: it would need `OPERATOR SIGNAL {name}` in its MISSION body"),
            false => why,
        })
    }

    /// A leash's arguments as the engine takes them. A capability the mission does not
    /// have is left to the engine to refuse (409), as it refuses an unknown tag.
    pub(crate) fn leash_args(
        &self,
        capability: &str,
        action: &str,
        args: &Map<String, JsonValue>,
    ) -> Result<Vec<(String, Value)>, String> {
        if matches!(action, "PAUSE" | "RESUME" | "ABORT") {
            return match args.is_empty() {
                true => Ok(Vec::new()),
                false => Err(format!("{action} takes no arguments; only a PERFORM section does")),
            };
        }
        let params = self.capabilities.get(capability);
        let mut out = Vec::new();
        for (name, v) in args {
            let kind = match params {
                Some(params) => match params.iter().find(|(p, _)| p == name) {
                    Some((_, kind)) => *kind,
                    None => {
                        let names: Vec<&str> = params.iter().map(|(p, _)| p.as_str()).collect();
                        return Err(format!(
                            "{capability} has no parameter `{name}`; its parameters are: {}",
                            names.join(", ")
                        ));
                    }
                },
                None => None,
            };
            out.push((name.clone(), value(v, kind, &format!("`{name}` of {capability}"))?));
        }
        Ok(out)
    }

    /// A signal's values as the engine takes them: as many as the signal carries.
    pub(crate) fn signal_args(&self, name: &str, args: &[JsonValue]) -> Result<Vec<Value>, String> {
        let Some(kinds) = self.signals.get(name) else {
            // Unknown to the mission: the engine refuses it by name (409).
            return args
                .iter()
                .enumerate()
                .map(|(i, v)| value(v, None, &format!("value {} of {name}", i + 1)))
                .collect();
        };
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
            .map(|(i, (v, kind))| value(v, *kind, &format!("value {} of {name}", i + 1)))
            .collect()
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
}

fn read(v: &JsonValue) -> Result<Given, String> {
    let form = "write a number in SI units, {\"number\": 20, \"unit\": \"m\"}, a string, true or false, or [x, y]";
    match v {
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

/// `what` (such as "`radius` of FlyCircle") takes `kind`: the engine's value, or why not.
pub(crate) fn value(v: &JsonValue, kind: Option<Kind>, what: &str) -> Result<Value, String> {
    let given = read(v).map_err(|why| format!("{what}: {why}"))?;
    match (kind, given) {
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
        (Some(Kind::Position) | None, Given::Position(p)) => {
            for c in [Some(p.x), Some(p.y), p.z].into_iter().flatten() {
                number(c, v, what)?;
            }
            Ok(Value::Position(p))
        }
        (Some(Kind::Symbol) | None, Given::Word(s)) => Ok(Value::Symbol(s)),
        (Some(Kind::Text), Given::Word(s)) => Ok(Value::Text(s)),
        (Some(Kind::Bool) | None, Given::Bool(b)) => Ok(Value::Bool(b)),
        (Some(k @ (Kind::Area | Kind::Actor | Kind::Remainder)), _) => {
            Err(format!("{what} is {}, which the operator API cannot send", k.describe()))
        }
        (Some(k), _) => Err(format!("{what} is {}, and {v} is not: {}", k.describe(), example(k))),
    }
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
        Kind::Position => return "write [x, y] or [x, y, z] in metres".into(),
        Kind::Symbol | Kind::Text => return "write a string such as \"Body\"".into(),
        Kind::Bool => return "write true or false".into(),
        Kind::Area | Kind::Actor | Kind::Remainder => return String::new(),
    };
    let si = if kind == Kind::Ratio { "a fraction such as 0.25" } else { "a number in SI units" };
    format!("write {si}, or {{\"number\": 20, \"unit\": \"{unit}\"}}")
}

#[cfg(test)]
mod tests {
    use super::Kinds;

    #[test]
    fn only_a_declared_signal_may_be_raised_and_a_refusal_lists_them() {
        let mut kinds = Kinds::default();
        kinds.signal("Hold_Position", vec![]);
        kinds.signal("Found", vec![None]);
        assert_eq!(
            kinds.may_raise("Hold_Position"),
            Err("the mission declares no signal an operator may raise, so not Hold_Position: it would need `OPERATOR SIGNAL Hold_Position` in its MISSION body".into())
        );
        kinds.operator_signal("Hold_Position");
        kinds.operator_signal("Carry_On");
        kinds.operator_signal("Hold_Position");
        assert_eq!(kinds.operator_signals(), ["Hold_Position", "Carry_On"], "each once, in order");
        assert_eq!(kinds.may_raise("Hold_Position"), Ok(()));
        assert_eq!(
            kinds.may_raise("Hold_Postion"),
            Err("the mission does not declare Hold_Postion as an operator signal: did you mean `Hold_Position`? It declares Hold_Position, Carry_On".into())
        );
        assert_eq!(
            kinds.may_raise("Found"),
            Err("the mission does not declare Found as an operator signal: it declares Hold_Position, Carry_On".into()),
            "heard by the mission, raised by it, and still not the operator's"
        );
    }
}
