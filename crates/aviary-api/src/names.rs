//! The drones' names in one string: a `String` per drone costs 40 bytes a drone (and an
//! allocation), where a fleet's names are mostly read to say who did what.

use std::ops::Index;

use typed_index_collections::TiVec;

use crate::DroneId;

#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Names {
    text: String,
    /// Where each name ends in `text`.
    ends: TiVec<DroneId, usize>,
}

impl Names {
    pub fn new<'a>(names: impl ExactSizeIterator<Item = &'a str>) -> Names {
        let mut out = Names { text: String::new(), ends: TiVec::with_capacity(names.len()) };
        for name in names {
            out.text.push_str(name);
            out.ends.push(out.text.len());
        }
        out.text.shrink_to_fit();
        out
    }

    pub fn len(&self) -> usize {
        self.ends.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ends.is_empty()
    }

    /// The drone's name, if the fleet has it.
    pub fn get(&self, id: DroneId) -> Option<&str> {
        let end = *self.ends.get(id)?;
        let start = id.0.checked_sub(1).map_or(0, |before| self.ends[DroneId(before)]);
        self.text.get(start..end)
    }

    /// Every name, in drone order.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = &str> + '_ {
        (0..self.len()).map(|d| &self[DroneId(d)])
    }

    /// The drone of this name (the first, if two share it).
    pub fn position(&self, name: &str) -> Option<DroneId> {
        self.iter().position(|n| n == name).map(DroneId)
    }
}

impl Index<DroneId> for Names {
    type Output = str;
    /// The drone's name; empty for an index the fleet does not have.
    fn index(&self, id: DroneId) -> &str {
        self.get(id).unwrap_or("")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_name_in_order() {
        let names = Names::new(["alpha", "", "b2"].into_iter());
        let d = DroneId;
        assert_eq!(
            (&names[d(0)], &names[d(1)], &names[d(2)], &names[d(3)]),
            ("alpha", "", "b2", "")
        );
        assert_eq!((names.len(), names.get(d(2)), names.get(d(3))), (3, Some("b2"), None));
        assert_eq!(names.iter().collect::<Vec<_>>(), ["alpha", "", "b2"]);
        assert_eq!((names.position("b2"), names.position("c")), (Some(d(2)), None));
    }
}
