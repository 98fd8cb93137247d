//! What the operator API's `GET /api/state` returns (docs/OPERATOR_API.md), typed: the
//! server writes an [`OperatorState`], `aviary ctl state` reads one back, and the schema
//! of docs/openapi.yaml is generated from these types. Its JSON is the document the API
//! has always returned: the same keys in the same order, and a drone without telemetry
//! has no telemetry keys.

use std::fmt;

use schemars::JsonSchema;
use serde::de::{MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::trace::{shown, Params, Status};
use crate::{FlightState, Kind};

/// The mission's state, folded from its trace, and the signals the operator may raise.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct OperatorState {
    /// The mission's name; null before it starts.
    pub mission: Option<String>,
    /// Mission time, s: the last event's.
    pub t: f64,
    pub status: MissionStatus,
    /// Why the mission ended as it did, when it says.
    pub reason: Option<String>,
    /// The operator paused the whole mission.
    pub paused: bool,
    /// The blocks running, outermost first.
    pub blocks: Vec<String>,
    /// The running activities, in the order they started.
    pub activities: Vec<Activity>,
    /// Each drone with its last telemetry, in the order first seen, then the drones the
    /// operator steered before their first telemetry.
    pub drones: Vec<Drone>,
    /// The signals the mission declares with OPERATOR SIGNAL, in the order written; the
    /// only ones POST /api/signal takes.
    #[serde(default)]
    pub operator_signals: Vec<String>,
    /// For each operator signal, the kinds of the values it carries, in order (null for
    /// any value).
    #[serde(default)]
    pub operator_signal_values: SignalValues,
}

/// Where the mission is: empty before it starts, `running`, then its outcome.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum MissionStatus {
    /// Not started yet.
    #[default]
    #[serde(rename = "")]
    NotStarted,
    Running,
    Ok,
    Failed,
    Aborted,
}

impl From<Status> for MissionStatus {
    fn from(status: Status) -> Self {
        match status {
            Status::Ok => MissionStatus::Ok,
            Status::Failed => MissionStatus::Failed,
            Status::Aborted => MissionStatus::Aborted,
        }
    }
}

impl MissionStatus {
    /// As the document writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            MissionStatus::NotStarted => "",
            MissionStatus::Running => "running",
            MissionStatus::Ok => "ok",
            MissionStatus::Failed => "failed",
            MissionStatus::Aborted => "aborted",
        }
    }
}

/// A running activity: who does what, since when, and whether it is paused.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Activity {
    pub capability: String,
    /// Its tag, which a leash names (`FlyCircle-C1`).
    pub tag: Option<String>,
    /// The drone, or the drones, that fly it.
    pub actor: String,
    /// Its arguments as the trace writes them.
    pub args: Params<'static>,
    /// When it started, s of mission time.
    #[serde(deserialize_with = "shown::number")]
    #[schemars(with = "Option<f64>")]
    pub since: f64,
    /// Paused by a leash.
    pub paused: bool,
}

/// A drone: its last telemetry, if any came, and what the operator did to it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Drone {
    /// Absent (no key at all) before the drone's first telemetry.
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub telemetry: Option<Telemetry>,
    pub name: String,
    /// The operator holds it (POST /api/drone).
    pub held: bool,
    /// The operator took it out of the mission, sending it home or landing it.
    pub withdrawn: Option<Withdrawn>,
}

/// A drone's last telemetry, as the trace's `telemetry` event gave it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct Telemetry {
    /// [x, y, z], m, in the world's local frame; a coordinate not known is null.
    #[serde(deserialize_with = "shown::coordinates")]
    #[schemars(with = "[Option<f64>; 3]")]
    pub position: [f64; 3],
    /// The fraction of its battery left; null when not known.
    #[serde(deserialize_with = "shown::number")]
    #[schemars(with = "Option<f64>")]
    pub battery: f64,
    pub state: FlightState,
    /// When it was reported, s of mission time.
    #[serde(deserialize_with = "shown::number")]
    #[schemars(with = "Option<f64>")]
    pub t: f64,
}

/// How the operator took a drone out of the mission.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum Withdrawn {
    /// Sent home.
    Home,
    /// Landed where it was.
    Land,
}

/// A kind of value, as the state names it (`operator_signal_values`): one word, stable.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "lowercase")]
pub enum KindName {
    Length,
    Duration,
    Speed,
    Angle,
    Ratio,
    Number,
    String,
    Bool,
    Position,
    Area,
    Symbol,
    Actor,
    Remainder,
    Line,
    Path,
}

impl From<Kind> for KindName {
    fn from(kind: Kind) -> Self {
        match kind {
            Kind::Length => KindName::Length,
            Kind::Duration => KindName::Duration,
            Kind::Speed => KindName::Speed,
            Kind::Angle => KindName::Angle,
            Kind::Ratio => KindName::Ratio,
            Kind::Number => KindName::Number,
            Kind::Text => KindName::String,
            Kind::Bool => KindName::Bool,
            Kind::Position => KindName::Position,
            Kind::Area => KindName::Area,
            Kind::Symbol => KindName::Symbol,
            Kind::Actor => KindName::Actor,
            Kind::Remainder => KindName::Remainder,
            Kind::Line => KindName::Line,
            Kind::Path => KindName::Path,
        }
    }
}

/// Each operator signal's kinds of values, in the order the mission declares them;
/// written as a JSON object (`{"Redirect": ["position"], "Stop": []}`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SignalValues(pub Vec<(String, Vec<Option<KindName>>)>);

impl Serialize for SignalValues {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (name, kinds) in &self.0 {
            map.serialize_entry(name, kinds)?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for SignalValues {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct SignalsVisitor;
        impl<'de> Visitor<'de> for SignalsVisitor {
            type Value = SignalValues;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object of signals and the kinds of their values")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut out = Vec::new();
                while let Some(entry) = map.next_entry::<String, Vec<Option<KindName>>>()? {
                    out.push(entry);
                }
                Ok(SignalValues(out))
            }
        }
        d.deserialize_map(SignalsVisitor)
    }
}

impl JsonSchema for SignalValues {
    fn schema_name() -> std::borrow::Cow<'static, str> {
        "SignalValues".into()
    }

    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let kinds = generator.subschema_for::<Vec<Option<KindName>>>();
        schemars::json_schema!({
            "description": "For each operator signal, the kinds of the values it carries, in order (null for any value)",
            "type": "object",
            "additionalProperties": kinds
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drone_without_telemetry_has_no_telemetry_keys_and_reads_back() {
        let state = OperatorState {
            mission: Some("M".into()),
            t: 2.0,
            status: MissionStatus::Running,
            drones: vec![
                Drone {
                    telemetry: Some(Telemetry {
                        position: [1.0, f64::NAN, 3.0],
                        battery: 0.5,
                        state: FlightState::Flying,
                        t: 2.0,
                    }),
                    name: "a".into(),
                    held: true,
                    withdrawn: None,
                },
                Drone {
                    telemetry: None,
                    name: "c".into(),
                    held: false,
                    withdrawn: Some(Withdrawn::Land),
                },
            ],
            operator_signal_values: SignalValues(vec![
                ("Stop".into(), vec![]),
                ("Go".into(), vec![Some(KindName::Position), None]),
            ]),
            ..OperatorState::default()
        };
        let json = serde_json::to_string(&state).unwrap();
        assert_eq!(
            json,
            r#"{"mission":"M","t":2.0,"status":"running","reason":null,"paused":false,"blocks":[],"activities":[],"drones":[{"position":[1.0,null,3.0],"battery":0.5,"state":"Flying","t":2.0,"name":"a","held":true,"withdrawn":null},{"name":"c","held":false,"withdrawn":"land"}],"operator_signals":[],"operator_signal_values":{"Stop":[],"Go":["position",null]}}"#
        );
        let back: OperatorState = serde_json::from_str(&json).unwrap();
        assert_eq!(serde_json::to_string(&back).unwrap(), json);
        assert!(back.drones[1].telemetry.is_none());
        let before: OperatorState = serde_json::from_str(
            r#"{"mission":null,"t":0.0,"status":"","reason":null,"paused":false,"blocks":[],"activities":[],"drones":[]}"#,
        )
        .unwrap();
        assert_eq!(before.status, MissionStatus::NotStarted);
    }
}

/// A control call's answer when the mission took it: `{"ok": true}`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct Accepted {
    #[schemars(extend("const" = true))]
    pub ok: bool,
}

impl Accepted {
    pub const YES: Accepted = Accepted { ok: true };
}

/// Every refusal, with its status: `{"error": "..."}`, in words that say what to do.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub struct ApiError {
    pub error: String,
}

/// A line of the event stream that is not an event: what the stream left out.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum StreamNote {
    /// Before the history (`?from=start`): how many of its oldest events were let go.
    HistoryDropped(u64),
    /// The stream fell behind the mission: how many events it missed.
    Lagged(u64),
    /// In a batch (`?batch=`): how many events the batch left out.
    Dropped(u64),
}
