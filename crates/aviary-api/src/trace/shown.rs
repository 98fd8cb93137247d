//! Values as the trace shows them, and reading them back.

use std::borrow::Cow;
use std::fmt;

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::ser::{SerializeMap, SerializeSeq, Serializer};
use serde::{Deserialize, Serialize};

use crate::{Names, Point, Remainder, Value};

/// A value as the trace shows it (docs/TRACE.md): SI numbers; text for strings, symbols
/// and drones (by name); booleans; a position as `[x, y]` or `[x, y, z]`; an area as its
/// corners `[[x, y], …]`; what a Sweep or FollowPath left as an object, `{"lanes": …,
/// "spacing": …}` or `{"points": …}` ([`crate::Remainder`]). A number that is not finite is written `null`, as is a drone
/// the fleet does not have and a value a drone does not have ([`Value::Absent`]); `null`
/// reads back as [`Shown::Null`], and `null` inside a
/// position or an area as NaN.
#[derive(Clone, Debug, PartialEq)]
pub enum Shown<'a> {
    Number(f64),
    Text(Cow<'a, str>),
    Bool(bool),
    Position(Point),
    Area(Cow<'a, [[f64; 2]]>),
    Remainder(Cow<'a, Remainder>),
    Null,
}

impl<'a> Shown<'a> {
    /// How the trace shows `value`, borrowing its text; a drone is shown by its name.
    pub fn of(value: &'a Value, drones: &'a Names) -> Shown<'a> {
        match value {
            Value::Number(n) => Shown::Number(*n),
            Value::Text(s) | Value::Symbol(s) => Shown::Text(Cow::Borrowed(s)),
            Value::Bool(b) => Shown::Bool(*b),
            Value::Position(p) => Shown::Position(*p),
            Value::Area(corners) => Shown::Area(Cow::Borrowed(corners)),
            Value::Actor(d) => drones.get(*d).map_or(Shown::Null, |n| Shown::Text(n.into())),
            Value::Remainder(left) => Shown::Remainder(Cow::Borrowed(left)),
            Value::Absent => Shown::Null,
        }
    }

    /// Values in order, as `args` lists them.
    pub fn all(values: &'a [Value], drones: &'a Names) -> Vec<Shown<'a>> {
        values.iter().map(|v| Shown::of(v, drones)).collect()
    }

    pub fn as_str(&self) -> Option<&str> {
        match self {
            Shown::Text(s) => Some(s),
            _ => None,
        }
    }

    pub fn as_number(&self) -> Option<f64> {
        match self {
            Shown::Number(n) => Some(*n),
            _ => None,
        }
    }
}

impl Serialize for Shown<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            // serde_json writes a number that is not finite as `null`.
            Shown::Number(n) => s.serialize_f64(*n),
            Shown::Text(t) => s.serialize_str(t),
            Shown::Bool(b) => s.serialize_bool(*b),
            Shown::Position(p) => {
                let mut seq = s.serialize_seq(Some(if p.z.is_some() { 3 } else { 2 }))?;
                seq.serialize_element(&p.x)?;
                seq.serialize_element(&p.y)?;
                if let Some(z) = &p.z {
                    seq.serialize_element(z)?;
                }
                seq.end()
            }
            Shown::Area(corners) => corners.serialize(s),
            Shown::Remainder(left) => left.serialize(s),
            Shown::Null => s.serialize_unit(),
        }
    }
}

impl<'de, 'a> Deserialize<'de> for Shown<'a> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ShownVisitor)
    }
}

struct ShownVisitor;

impl<'de> Visitor<'de> for ShownVisitor {
    type Value = Shown<'static>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number, a string, a boolean, a position, an area, a remainder or null")
    }
    /// An object is what a Sweep or FollowPath left.
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
        let left = Remainder::deserialize(de::value::MapAccessDeserializer::new(map))?;
        Ok(Shown::Remainder(Cow::Owned(left)))
    }
    fn visit_bool<E>(self, b: bool) -> Result<Self::Value, E> {
        Ok(Shown::Bool(b))
    }
    fn visit_i64<E>(self, n: i64) -> Result<Self::Value, E> {
        Ok(Shown::Number(n as f64))
    }
    fn visit_u64<E>(self, n: u64) -> Result<Self::Value, E> {
        Ok(Shown::Number(n as f64))
    }
    fn visit_f64<E>(self, n: f64) -> Result<Self::Value, E> {
        Ok(Shown::Number(n))
    }
    fn visit_str<E>(self, s: &str) -> Result<Self::Value, E> {
        Ok(Shown::Text(Cow::Owned(s.to_owned())))
    }
    fn visit_string<E>(self, s: String) -> Result<Self::Value, E> {
        Ok(Shown::Text(Cow::Owned(s)))
    }
    fn visit_unit<E>(self) -> Result<Self::Value, E> {
        Ok(Shown::Null)
    }
    fn visit_none<E>(self) -> Result<Self::Value, E> {
        Ok(Shown::Null)
    }
    /// A list of coordinates is a position; a list of corners is an area.
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut coordinates = Vec::new();
        let mut corners = Vec::new();
        while let Some(item) = seq.next_element::<Item>()? {
            match item {
                Item::Coordinate(c) if corners.is_empty() => coordinates.push(c),
                Item::Corner(c) if coordinates.is_empty() => corners.push(c),
                _ => return Err(de::Error::custom("a list mixes coordinates and corners")),
            }
        }
        match coordinates[..] {
            [] => Ok(Shown::Area(Cow::Owned(corners))),
            [x, y] => Ok(Shown::Position(Point { x, y, z: None })),
            [x, y, z] => Ok(Shown::Position(Point { x, y, z: Some(z) })),
            _ => Err(de::Error::invalid_length(coordinates.len(), &"2 or 3 coordinates")),
        }
    }
}

/// An element of a list value: a coordinate of a position, or a corner of an area.
enum Item {
    Coordinate(f64),
    Corner([f64; 2]),
}

impl<'de> Deserialize<'de> for Item {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ItemVisitor;
        impl<'de> Visitor<'de> for ItemVisitor {
            type Value = Item;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a coordinate or a corner [x, y]")
            }
            fn visit_i64<E>(self, n: i64) -> Result<Item, E> {
                Ok(Item::Coordinate(n as f64))
            }
            fn visit_u64<E>(self, n: u64) -> Result<Item, E> {
                Ok(Item::Coordinate(n as f64))
            }
            fn visit_f64<E>(self, n: f64) -> Result<Item, E> {
                Ok(Item::Coordinate(n))
            }
            fn visit_unit<E>(self) -> Result<Item, E> {
                Ok(Item::Coordinate(f64::NAN))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Item, A::Error> {
                let mut corner = [0.0; 2];
                for (i, c) in corner.iter_mut().enumerate() {
                    *c = seq
                        .next_element::<Number>()?
                        .ok_or_else(|| de::Error::invalid_length(i, &"a corner [x, y]"))?
                        .0;
                }
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(de::Error::invalid_length(3, &"a corner [x, y]"));
                }
                Ok(Item::Corner(corner))
            }
        }
        d.deserialize_any(ItemVisitor)
    }
}

/// A number as the trace writes it: `null` when it was not finite (read back as NaN).
struct Number(f64);

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Ok(Number(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN)))
    }
}

/// `t`, `battery`: a number, or `null` (not finite) as NaN.
pub(crate) fn number<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Number::deserialize(d)?.0)
}

/// `position`, `location`: `[x, y, z]`, a `null` coordinate as NaN.
pub(crate) fn coordinates<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
    let [x, y, z] = <[Number; 3]>::deserialize(d)?;
    Ok([x.0, y.0, z.0])
}

/// A capability's parameters and their values, in the order it declares them; written as
/// a JSON object (`{"center": [200.0, 300.0], "radius": 40.0}`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Params<'a>(pub Vec<(Cow<'a, str>, Shown<'a>)>);

impl<'a> Params<'a> {
    /// The value of parameter `name`, if the activity has it.
    pub fn get(&self, name: &str) -> Option<&Shown<'a>> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }
}

impl Serialize for Params<'_> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for (name, value) in &self.0 {
            map.serialize_entry(name.as_ref(), value)?;
        }
        map.end()
    }
}

impl<'de, 'a> Deserialize<'de> for Params<'a> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ParamsVisitor;
        impl<'de> Visitor<'de> for ParamsVisitor {
            type Value = Params<'static>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object of parameters and their values")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut out = Vec::new();
                while let Some((name, value)) = map.next_entry::<String, Shown<'static>>()? {
                    out.push((Cow::Owned(name), value));
                }
                Ok(Params(out))
            }
        }
        d.deserialize_map(ParamsVisitor)
    }
}

/// A value in the trace's JSON Schema: what [`Shown`]'s `Serialize` writes.
impl schemars::JsonSchema for Shown<'_> {
    fn schema_name() -> Cow<'static, str> {
        "Value".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let coordinate = schemars::json_schema!({ "type": ["number", "null"] });
        schemars::json_schema!({
            "description": "A value as the trace shows it: a number in SI units (null when not finite), text (a string, a symbol, a drone's name), a boolean, a position [x, y] or [x, y, z], an area's corners [[x, y], ...], what a Sweep or FollowPath left ({\"lanes\": ..., \"spacing\": ...} or {\"points\": ...}), or null (a drone the fleet does not have)",
            "anyOf": [
                { "type": ["number", "string", "boolean", "null"] },
                { "type": "array", "items": coordinate, "minItems": 2, "maxItems": 3 },
                { "type": "array", "items": { "type": "array", "items": coordinate, "minItems": 2, "maxItems": 2 } },
                { "type": "object" }
            ]
        })
    }
}

/// A capability's values by parameter name, in the trace's JSON Schema.
impl schemars::JsonSchema for Params<'_> {
    fn schema_name() -> Cow<'static, str> {
        "Params".into()
    }

    fn json_schema(generator: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let value = generator.subschema_for::<Shown>();
        schemars::json_schema!({
            "description": "The capability's values by parameter name, in the order of its signature",
            "type": "object",
            "additionalProperties": value
        })
    }
}

impl Shown<'_> {
    /// The same value, owning its text.
    pub fn into_owned(self) -> Shown<'static> {
        match self {
            Shown::Number(n) => Shown::Number(n),
            Shown::Text(t) => Shown::Text(Cow::Owned(t.into_owned())),
            Shown::Bool(b) => Shown::Bool(b),
            Shown::Position(p) => Shown::Position(p),
            Shown::Area(corners) => Shown::Area(Cow::Owned(corners.into_owned())),
            Shown::Remainder(left) => Shown::Remainder(Cow::Owned(left.into_owned())),
            Shown::Null => Shown::Null,
        }
    }
}

impl Params<'_> {
    /// The same values, owning their text.
    pub fn into_owned(self) -> Params<'static> {
        Params(
            self.0.into_iter().map(|(n, v)| (Cow::Owned(n.into_owned()), v.into_owned())).collect(),
        )
    }
}
