//! RIHS01, the type hash ROS 2 (Iron and later) gives each message type and rmw_zenoh puts
//! in every key (REP 2011): SHA-256 of the type's description, with every type it uses,
//! as one line of JSON. The description is read from the same `.msg` texts a bag holds
//! ([`Message`]), so a type's hash and its definition cannot disagree.
//!
//! The rule, as rosidl's `calculate_type_hash` (Jazzy) has it: the fields in the order
//! they are declared (constants and default values left out), each with its type's id
//! (`type_description_interfaces/FieldType`), capacity, string capacity and nested type
//! name; the types used, each once, sorted by name; `json.dumps` with `", "` and `": "`.

use serde::Serialize;
use sha2::{Digest, Sha256};

use crate::msgs::Message;

#[derive(Serialize)]
struct Description {
    type_description: TypeDescription,
    referenced_type_descriptions: Vec<TypeDescription>,
}

#[derive(Serialize)]
struct TypeDescription {
    type_name: String,
    fields: Vec<Field>,
}

#[derive(Serialize)]
struct Field {
    name: String,
    #[serde(rename = "type")]
    ty: FieldType,
}

#[derive(Serialize)]
struct FieldType {
    type_id: u8,
    capacity: u64,
    string_capacity: u64,
    nested_type_name: String,
}

/// The RIHS01 hash of `M`: `RIHS01_` and 64 hex digits.
pub fn rihs01<M: Message>() -> Result<String, String> {
    let package = M::TYPE.split('/').next().unwrap_or_default();
    let mut referenced = Vec::new();
    for (name, text) in M::USES {
        let name = full_name(name, "");
        let own = name.split('/').next().unwrap_or_default().to_string();
        referenced.push(TypeDescription { fields: fields(text, &own)?, type_name: name });
    }
    referenced.sort_by(|a, b| a.type_name.cmp(&b.type_name));
    let description = Description {
        type_description: TypeDescription {
            type_name: M::TYPE.to_string(),
            fields: fields(M::TEXT, package)?,
        },
        referenced_type_descriptions: referenced,
    };
    let mut json = Vec::new();
    let mut writer = serde_json::Serializer::with_formatter(&mut json, PythonStyle);
    description.serialize(&mut writer).map_err(|e| e.to_string())?;
    Ok(format!("RIHS01_{:x}", Sha256::digest(&json)))
}

/// `pkg/msg/Type` of a `.msg` type written `pkg/Type`, or `Type` in package `package`.
fn full_name(name: &str, package: &str) -> String {
    match name.split_once('/') {
        Some((pkg, ty)) => format!("{pkg}/msg/{}", ty.rsplit('/').next().unwrap_or(ty)),
        None => format!("{package}/msg/{name}"),
    }
}

/// The fields of a `.msg` text, in order: constants (`TYPE NAME=VALUE`) and comments are
/// not fields, and a default value (`TYPE NAME VALUE`) is not part of the hash.
fn fields(text: &str, package: &str) -> Result<Vec<Field>, String> {
    let mut out = Vec::new();
    for line in text.lines() {
        let line = line.split('#').next().unwrap_or_default().trim();
        let mut words = line.split_whitespace();
        let (Some(ty), Some(name)) = (words.next(), words.next()) else { continue };
        if name.contains('=') || words.next().is_some_and(|w| w.starts_with('=')) {
            continue;
        }
        out.push(Field { name: name.to_string(), ty: field_type(ty, package)? });
    }
    Ok(out)
}

/// A field's type: its `FieldType` id (plus 48 for an array `T[N]`, 96 for a bounded
/// sequence `T[<=N]`, 144 for a sequence `T[]`), its capacity and its nested type.
fn field_type(ty: &str, package: &str) -> Result<FieldType, String> {
    let (base, (offset, capacity)) = match ty.split_once('[') {
        None => (ty, (0, 0)),
        Some((base, rest)) => {
            let inside = rest.trim_end_matches(']');
            let bound = |n: &str| n.parse::<u64>().map_err(|_| format!("`{ty}`: no size"));
            let shape = match inside.strip_prefix("<=") {
                Some(n) => (96, bound(n)?),
                None if inside.is_empty() => (144, 0),
                None => (48, bound(inside)?),
            };
            (base, shape)
        }
    };
    let primitive = match base {
        "int8" => 2,
        "uint8" | "char" => 3,
        "int16" => 4,
        "uint16" => 5,
        "int32" => 6,
        "uint32" => 7,
        "int64" => 8,
        "uint64" => 9,
        "float32" => 10,
        "float64" => 11,
        "bool" => 15,
        "byte" => 16,
        "string" => 17,
        "wstring" => 18,
        _ => 0,
    };
    if base.starts_with("string<=") || base.starts_with("wstring<=") {
        return Err(format!("`{ty}`: bounded strings are not used by Aviary's messages"));
    }
    let (type_id, nested_type_name) = match primitive {
        0 => (1, full_name(base, package)),
        id => (id, String::new()),
    };
    Ok(FieldType { type_id: type_id + offset, capacity, string_capacity: 0, nested_type_name })
}

/// Python's `json.dumps` with its default separators: `", "` between items, `": "`
/// after a key.
struct PythonStyle;

impl serde_json::ser::Formatter for PythonStyle {
    fn begin_array_value<W: ?Sized + std::io::Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        between_items(writer, first)
    }

    fn begin_object_key<W: ?Sized + std::io::Write>(
        &mut self,
        writer: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        between_items(writer, first)
    }

    fn begin_object_value<W: ?Sized + std::io::Write>(
        &mut self,
        writer: &mut W,
    ) -> std::io::Result<()> {
        writer.write_all(b": ")
    }
}

fn between_items<W: ?Sized + std::io::Write>(writer: &mut W, first: bool) -> std::io::Result<()> {
    if first {
        Ok(())
    } else {
        writer.write_all(b", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::{NavSatFix, PoseStamped};

    /// ROS 2 Jazzy's own hashes of its types (rmw_zenoh's keys carry them; rosbags'
    /// `hash_rihs01` gives the same).
    #[test]
    fn the_hashes_of_ros_2_s_own_types_are_ros_2_s() {
        assert_eq!(
            rihs01::<NavSatFix>().unwrap(),
            "RIHS01_62223ab3fe210a15976021da7afddc9e200dc9ec75231c1b6a557fc598a65404"
        );
        assert_eq!(
            rihs01::<PoseStamped>().unwrap(),
            "RIHS01_10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8"
        );
    }

    #[test]
    fn a_field_s_type_is_its_id_with_its_shape() {
        let t = field_type("float64[9]", "p").unwrap();
        assert_eq!((t.type_id, t.capacity), (59, 9));
        assert_eq!(field_type("Point[]", "geometry_msgs").unwrap().type_id, 145);
        assert_eq!(
            field_type("Point", "geometry_msgs").unwrap().nested_type_name,
            "geometry_msgs/msg/Point"
        );
        assert_eq!(field_type("uint8[<=4]", "p").unwrap().type_id, 99);
        assert_eq!(field_type("char", "p").unwrap().type_id, 3);
    }
}
