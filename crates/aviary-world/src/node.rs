//! A TOML document as a tree in which every key and every value knows where it was
//! written.
//!
//! `toml` hands out spans through `toml::Spanned`, but that type fails on the values the
//! parser has no span for (implicit tables such as `[drones]` when only `[drones.x]` is
//! written, or some keys). So this module speaks the same serde protocol as `Spanned`
//! itself and accepts a value with or without a span; a missing span is then filled in
//! from the nearest enclosing key or value.

use std::fmt;
use std::ops::Range;

use aviary_diagnostics::Span;
use serde::de::{DeserializeSeed, Deserializer, Error as _, MapAccess, SeqAccess, Visitor};

// The serde data model names of `toml::Spanned` (serde_spanned 0.6). A test checks that
// the parser still honours them: every key and value of the example world has a span.
const SPANNED_NAME: &str = "$__serde_spanned_private_Spanned";
const SPANNED_START: &str = "$__serde_spanned_private_start";
const SPANNED_END: &str = "$__serde_spanned_private_end";
const SPANNED_VALUE: &str = "$__serde_spanned_private_value";
const SPANNED_FIELDS: &[&str] = &[SPANNED_START, SPANNED_END, SPANNED_VALUE];
// How toml_datetime passes a datetime through serde: a map with this one key.
const DATETIME_FIELD: &str = "$__toml_private_datetime";

/// One TOML value and where it is.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Node {
    pub span: Span,
    pub value: Value,
}

#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Value {
    Str(String),
    Int(i64),
    Float(f64),
    Bool(bool),
    Datetime(String),
    Array(Vec<Node>),
    Table(Vec<Entry>),
}

/// One `key = value` of a table, in file order.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Entry {
    pub key: String,
    pub key_span: Span,
    pub node: Node,
}

impl Node {
    /// The serde path: every TOML file, and the error messages of `toml`.
    pub fn parse_serde(text: &str) -> Result<Node, toml::de::Error> {
        let raw = NodeSeed { spanned: true }.deserialize(toml::Deserializer::new(text))?;
        Ok(raw.finish(Span::new(0, text.len())))
    }

    /// What a value is, for messages: "a string", "a table", ...
    pub fn describe(&self) -> &'static str {
        match &self.value {
            Value::Str(_) => "a string",
            Value::Int(_) => "an integer",
            Value::Float(_) => "a number",
            Value::Bool(_) => "a boolean",
            Value::Datetime(_) => "a date",
            Value::Array(_) => "a list",
            Value::Table(_) => "a table",
        }
    }
}

/// The tree as serde hands it over: some spans may be missing.
struct RawNode {
    span: Option<Range<usize>>,
    value: RawValue,
}

enum RawValue {
    Str(String),
    Int(i64),
    Float(f64),
    Bool(bool),
    Datetime(String),
    Array(Vec<RawNode>),
    Table(Vec<(RawKey, RawNode)>),
}

struct RawKey {
    name: String,
    span: Option<Range<usize>>,
}

fn to_span(range: Range<usize>) -> Span {
    Span::new(range.start, range.end)
}

impl RawNode {
    /// Fills every missing span from the closest enclosing one.
    fn finish(self, fallback: Span) -> Node {
        let span = self.span.map(to_span).unwrap_or(fallback);
        let value = match self.value {
            RawValue::Str(s) => Value::Str(s),
            RawValue::Int(i) => Value::Int(i),
            RawValue::Float(f) => Value::Float(f),
            RawValue::Bool(b) => Value::Bool(b),
            RawValue::Datetime(d) => Value::Datetime(d),
            RawValue::Array(items) => {
                Value::Array(items.into_iter().map(|n| n.finish(span)).collect())
            }
            RawValue::Table(entries) => Value::Table(
                entries
                    .into_iter()
                    .map(|(key, node)| {
                        let key_span = key
                            .span
                            .clone()
                            .or_else(|| node.span.clone())
                            .map(to_span)
                            .unwrap_or(span);
                        Entry { key: key.name, key_span, node: node.finish(key_span) }
                    })
                    .collect(),
            ),
        };
        Node { span, value }
    }
}

struct KeySeed;

impl<'de> DeserializeSeed<'de> for KeySeed {
    type Value = RawKey;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<RawKey, D::Error> {
        d.deserialize_struct(SPANNED_NAME, SPANNED_FIELDS, KeyVisitor)
    }
}

struct KeyVisitor;

impl<'de> Visitor<'de> for KeyVisitor {
    type Value = RawKey;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a key")
    }
    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<RawKey, E> {
        Ok(RawKey { name: v.to_owned(), span: None })
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawKey, A::Error> {
        let (span, name) = read_spanned(&mut map, std::marker::PhantomData::<String>)?;
        Ok(RawKey { name, span: Some(span) })
    }
}

/// Reads the rest of a `Spanned` map whose first key has been seen to be `start`.
fn read_spanned_rest<'de, A, S>(map: &mut A, seed: S) -> Result<(Range<usize>, S::Value), A::Error>
where
    A: MapAccess<'de>,
    S: DeserializeSeed<'de>,
{
    let start: usize = map.next_value()?;
    let _: Option<String> = map.next_key()?;
    let end: usize = map.next_value()?;
    let _: Option<String> = map.next_key()?;
    let value = map.next_value_seed(seed)?;
    Ok((start..end, value))
}

fn read_spanned<'de, A, S>(map: &mut A, seed: S) -> Result<(Range<usize>, S::Value), A::Error>
where
    A: MapAccess<'de>,
    S: DeserializeSeed<'de>,
{
    match map.next_key::<String>()? {
        Some(k) if k == SPANNED_START => read_spanned_rest(map, seed),
        _ => Err(A::Error::custom("expected a spanned value")),
    }
}

struct NodeSeed {
    /// Ask the deserializer for the value's span (false once inside the span wrapper).
    spanned: bool,
}

impl<'de> DeserializeSeed<'de> for NodeSeed {
    type Value = RawNode;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<RawNode, D::Error> {
        if self.spanned {
            d.deserialize_struct(SPANNED_NAME, SPANNED_FIELDS, NodeVisitor)
        } else {
            d.deserialize_any(NodeVisitor)
        }
    }
}

struct NodeVisitor;

fn bare(value: RawValue) -> RawNode {
    RawNode { span: None, value }
}

impl<'de> Visitor<'de> for NodeVisitor {
    type Value = RawNode;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a TOML value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<RawNode, E> {
        Ok(bare(RawValue::Bool(v)))
    }
    fn visit_i64<E>(self, v: i64) -> Result<RawNode, E> {
        Ok(bare(RawValue::Int(v)))
    }
    fn visit_u64<E>(self, v: u64) -> Result<RawNode, E> {
        Ok(bare(match i64::try_from(v) {
            Ok(i) => RawValue::Int(i),
            Err(_) => RawValue::Float(v as f64),
        }))
    }
    fn visit_f64<E>(self, v: f64) -> Result<RawNode, E> {
        Ok(bare(RawValue::Float(v)))
    }
    fn visit_str<E>(self, v: &str) -> Result<RawNode, E> {
        Ok(bare(RawValue::Str(v.to_owned())))
    }
    fn visit_string<E>(self, v: String) -> Result<RawNode, E> {
        Ok(bare(RawValue::Str(v)))
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawNode, A::Error> {
        let mut items = Vec::new();
        while let Some(item) = seq.next_element_seed(NodeSeed { spanned: true })? {
            items.push(item);
        }
        Ok(bare(RawValue::Array(items)))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawNode, A::Error> {
        let mut entries = Vec::new();
        let Some(first) = map.next_key_seed(KeySeed)? else {
            return Ok(bare(RawValue::Table(entries)));
        };
        // The serde protocol's special maps arrive with plain (span-less) keys.
        if first.span.is_none() && first.name == SPANNED_START {
            let (span, mut node) = read_spanned_rest(&mut map, NodeSeed { spanned: false })?;
            node.span = Some(span);
            return Ok(node);
        }
        if first.span.is_none() && first.name == DATETIME_FIELD {
            let text: String = map.next_value()?;
            return Ok(bare(RawValue::Datetime(text)));
        }
        let mut key = Some(first);
        while let Some(k) = key {
            let node = map.next_value_seed(NodeSeed { spanned: true })?;
            entries.push((k, node));
            key = map.next_key_seed(KeySeed)?;
        }
        Ok(bare(RawValue::Table(entries)))
    }
}
