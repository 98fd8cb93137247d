//! Trace events as the engine makes them: a kind, a time and fields borrowed from the
//! run, in the order they are written. A sink that keeps JSON gets the same object as
//! always (`Event::to_json`, or serialised straight from the event, byte for byte the
//! same); a sink that only looks at a field or two reads it without building a map,
//! hashing its keys or copying its strings.

use serde::ser::{Serialize, SerializeMap, Serializer};
use serde_json::{Map, Value as Json};

/// The kinds of trace event (docs/TRACE.md), so that what a sink wants is asked once per
/// kind when the run starts, not at every event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    MissionStart,
    MissionEnd,
    BlockStart,
    BlockEnd,
    CapabilityStart,
    CapabilityEnd,
    HandlerStart,
    HandlerEnd,
    ApiCall,
    ApiDone,
    Signal,
    Exception,
    Leash,
    Detection,
    Telemetry,
}

impl Kind {
    pub const ALL: [Kind; 15] = [
        Kind::MissionStart,
        Kind::MissionEnd,
        Kind::BlockStart,
        Kind::BlockEnd,
        Kind::CapabilityStart,
        Kind::CapabilityEnd,
        Kind::HandlerStart,
        Kind::HandlerEnd,
        Kind::ApiCall,
        Kind::ApiDone,
        Kind::Signal,
        Kind::Exception,
        Kind::Leash,
        Kind::Detection,
        Kind::Telemetry,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            Kind::MissionStart => "mission_start",
            Kind::MissionEnd => "mission_end",
            Kind::BlockStart => "block_start",
            Kind::BlockEnd => "block_end",
            Kind::CapabilityStart => "capability_start",
            Kind::CapabilityEnd => "capability_end",
            Kind::HandlerStart => "handler_start",
            Kind::HandlerEnd => "handler_end",
            Kind::ApiCall => "api_call",
            Kind::ApiDone => "api_done",
            Kind::Signal => "signal",
            Kind::Exception => "exception",
            Kind::Leash => "leash",
            Kind::Detection => "detection",
            Kind::Telemetry => "telemetry",
        }
    }
}

/// One event: `{"t": …, "event": kind, fields…}`.
pub struct Event<'a> {
    pub t: f64,
    pub kind: &'static str,
    pub fields: &'a [(&'static str, Field<'a>)],
}

/// A field's value.
pub enum Field<'a> {
    Str(&'a str),
    Text(String),
    Null,
    Bool(bool),
    Number(f64),
    Json(Json),
}

impl<'a> Field<'a> {
    /// A name, or `null` when there is none.
    pub fn name(name: Option<&'a str>) -> Field<'a> {
        name.map_or(Field::Null, Field::Str)
    }

    pub fn as_str(&self) -> Option<&str> {
        match self {
            Field::Str(s) => Some(s),
            Field::Text(s) => Some(s),
            Field::Json(Json::String(s)) => Some(s),
            _ => None,
        }
    }

    pub fn as_json(&self) -> Option<&Json> {
        match self {
            Field::Json(j) => Some(j),
            _ => None,
        }
    }

    pub fn to_json(&self) -> Json {
        match self {
            Field::Str(s) => Json::from(*s),
            Field::Text(s) => Json::from(s.as_str()),
            Field::Null => Json::Null,
            Field::Bool(b) => Json::from(*b),
            // As `json!` makes it: not finite is `null`.
            Field::Number(n) => Json::from(*n),
            Field::Json(j) => j.clone(),
        }
    }
}

impl Event<'_> {
    /// The field `key`, if the event has it.
    pub fn get(&self, key: &str) -> Option<&Field<'_>> {
        self.fields.iter().find(|(k, _)| *k == key).map(|(_, v)| v)
    }

    /// The JSON object of the trace format (docs/TRACE.md): `t`, `event`, then the fields.
    pub fn to_json(&self) -> Json {
        let mut object = Map::with_capacity(self.fields.len() + 2);
        object.insert("t".into(), Json::from(self.t));
        object.insert("event".into(), Json::from(self.kind));
        for (key, value) in self.fields {
            object.insert((*key).into(), value.to_json());
        }
        Json::Object(object)
    }
}

impl Serialize for Field<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Field::Str(v) => s.serialize_str(v),
            Field::Text(v) => s.serialize_str(v),
            Field::Null => s.serialize_unit(),
            Field::Bool(b) => s.serialize_bool(*b),
            Field::Number(n) => Json::from(*n).serialize(s),
            Field::Json(j) => j.serialize(s),
        }
    }
}

impl Serialize for Event<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.fields.len() + 2))?;
        map.serialize_entry("t", &Json::from(self.t))?;
        map.serialize_entry("event", self.kind)?;
        for (key, value) in self.fields {
            map.serialize_entry(key, value)?;
        }
        map.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn sample<'a>(fields: &'a [(&'static str, Field<'a>)]) -> Event<'a> {
        Event { t: 1.25, kind: "api_done", fields }
    }

    #[test]
    fn serialised_straight_or_through_json_the_bytes_are_the_same() {
        let fields = [
            ("actor", Field::Str("d\"1\n")),
            ("owned", Field::Text("é\u{1}".into())),
            ("tag", Field::Null),
            ("handled", Field::Bool(true)),
            ("battery", Field::Number(0.1 + 0.2)),
            ("nan", Field::Number(f64::NAN)),
            ("position", Field::Json(json!([1.5, -0.0, 1e300]))),
            ("args", Field::Json(json!({ "b": 1, "a": [null, "x"] }))),
        ];
        let event = sample(&fields);
        let direct = serde_json::to_string(&event).unwrap();
        let through = serde_json::to_string(&event.to_json()).unwrap();
        assert_eq!(direct, through);
        assert!(direct.starts_with(r#"{"t":1.25,"event":"api_done","actor":"d\"1\n""#), "{direct}");
        assert_eq!(event.to_json()["nan"], Json::Null);
    }

    #[test]
    fn fields_are_found_by_key() {
        let fields = [("name", Field::Str("Done")), ("args", Field::Json(json!([3])))];
        let event = sample(&fields);
        assert_eq!(event.get("name").and_then(Field::as_str), Some("Done"));
        assert_eq!(event.get("args").and_then(Field::as_json), Some(&json!([3])));
        assert!(event.get("missing").is_none());
    }

    #[test]
    fn every_kind_is_listed_once_at_its_own_index() {
        for (i, kind) in Kind::ALL.iter().enumerate() {
            assert_eq!(*kind as usize, i, "{kind:?}");
        }
        let mut names: Vec<&str> = Kind::ALL.iter().map(|k| k.as_str()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Kind::ALL.len());
    }
}
