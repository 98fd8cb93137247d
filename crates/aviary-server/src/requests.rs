//! The bodies of the control calls, typed: `aviary ctl` sends them, the server reads them,
//! and docs/openapi.yaml's request schemas are generated from them. A body that is not
//! one is refused (400) in words that say what to send (`routes.rs`).

use std::borrow::Cow;
use std::collections::BTreeMap;

use aviary_syntax::ast::Unit;
use schemars::{json_schema, JsonSchema, Schema, SchemaGenerator};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// `POST /api/leash`: `{"activity": "FlyCircle-C1", "action": "PAUSE"}`, or with
/// `capability` and `tag` apart; a section's arguments by parameter name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct LeashRequest {
    /// `Capability-Tag`, as a mission writes it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(example = &"FlyCircle-C1")]
    pub activity: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capability: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tag: Option<String>,
    /// `PAUSE`, `RESUME`, `ABORT`, or a `PERFORM` section's name.
    #[schemars(example = &"PAUSE", example = &"Widen")]
    pub action: String,
    /// A section's arguments, by parameter name.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub args: Option<BTreeMap<String, Argument>>,
}

/// `POST /api/signal`: a signal the mission declares for the operator, with its values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SignalRequest {
    pub name: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub args: Option<Vec<Argument>>,
}

/// `POST /api/drone`: `{"drone": "scout1", "action": "hold"}`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct DroneRequest {
    #[schemars(example = &"scout1")]
    pub drone: String,
    pub action: DroneVerb,
}

/// What the operator tells one drone.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DroneVerb {
    Hold,
    Resume,
    /// Home, out of the mission; `return_home` as the trace writes it.
    #[serde(alias = "return_home")]
    Home,
    Land,
}

impl DroneVerb {
    /// The verbs a body may give, as the refusal of another lists them.
    pub const WORDS: &str = "\"action\": \"hold\", \"resume\", \"home\" or \"land\"";
}

/// An argument or a signal value as JSON: read against the kind the mission gives it
/// (`args.rs`), where a wrong one is refused with the kind expected.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Argument(pub Value);

/// `{"number": 10, "unit": "s"}`.
#[derive(Serialize)]
struct Quantity {
    number: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    unit: Option<&'static str>,
}

/// `{"lat": 47.45, "lon": 13.1, "alt": 520}`.
#[derive(Serialize)]
struct Geo {
    lat: f64,
    lon: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    alt: Option<f64>,
}

impl Argument {
    /// A number as the language writes it, its unit kept, so that the server can refuse
    /// `10s` where a length is expected.
    pub fn number(number: f64, unit: Option<Unit>) -> Argument {
        Argument::of(Quantity { number, unit: unit.map(Unit::as_str) })
    }

    /// A symbol or a text.
    pub fn word(word: &str) -> Argument {
        Argument(Value::String(word.to_string()))
    }

    pub fn truth(truth: bool) -> Argument {
        Argument(Value::Bool(truth))
    }

    /// A position in metres: `[x, y]` or `[x, y, z]`.
    pub fn metres(parts: &[f64]) -> Argument {
        Argument::of(parts)
    }

    /// A position on Earth, `GEO(lat, lon[, alt])`: placed about the world's origin.
    pub fn geo(lat: f64, lon: f64, alt: Option<f64>) -> Argument {
        Argument::of(Geo { lat, lon, alt })
    }

    fn of(value: impl Serialize) -> Argument {
        Argument(serde_json::to_value(value).unwrap_or(Value::Null))
    }
}

impl JsonSchema for Argument {
    fn schema_name() -> Cow<'static, str> {
        "Argument".into()
    }

    fn json_schema(_: &mut SchemaGenerator) -> Schema {
        // The units as the language writes them, which `args.rs` reads (`Unit::parse`).
        let units: Vec<&str> = Unit::ALL.iter().map(|u| u.as_str()).collect();
        json_schema!({
            "description": "An argument or a signal value, checked against the kind the mission gives it (docs/OPERATOR_API.md#values). Numbers are finite, at most 1e9 in SI units; a length, duration or speed is not negative.",
            "oneOf": [
                { "type": "number", "description": "a number in SI units (m, s, m/s, deg; a ratio as a fraction)" },
                {
                    "type": "object",
                    "description": "a number as the language writes it; without unit, a plain number",
                    "required": ["number"],
                    "additionalProperties": false,
                    "properties": {
                        "number": { "type": "number" },
                        "unit": { "type": "string", "enum": units }
                    }
                },
                { "type": "string", "description": "a symbol or text" },
                { "type": "boolean" },
                { "type": "array", "items": { "type": "number" }, "minItems": 2, "maxItems": 3, "description": "a position [x, y] or [x, y, z], metres" },
                {
                    "type": "object",
                    "description": "a position on Earth, GEO(lat, lon[, alt]): degrees, and metres above sea level; placed about the world's origin",
                    "required": ["lat", "lon"],
                    "additionalProperties": false,
                    "properties": {
                        "lat": { "type": "number", "minimum": -90, "maximum": 90 },
                        "lon": { "type": "number", "minimum": -180, "maximum": 180 },
                        "alt": { "type": "number" }
                    }
                }
            ]
        })
    }
}
