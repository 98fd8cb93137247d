//! The drones' names in one string: a `String` per drone cost 40 bytes a drone, and the
//! simulator says a name only in messages.

use std::ops::Index;

use aviary_api::DroneId;

#[derive(Clone, Debug, Default)]
pub(crate) struct Names {
    text: String,
    /// Where each name ends in `text`.
    ends: Vec<usize>,
}

impl Names {
    pub fn new<'a>(names: impl ExactSizeIterator<Item = &'a str>) -> Names {
        let mut out = Names { text: String::new(), ends: Vec::with_capacity(names.len()) };
        for name in names {
            out.text.push_str(name);
            out.ends.push(out.text.len());
        }
        out.text.shrink_to_fit();
        out
    }
}

impl Index<DroneId> for Names {
    type Output = str;
    /// The drone's name; empty for an index the fleet does not have.
    fn index(&self, id: DroneId) -> &str {
        let start = match id.checked_sub(1) {
            Some(before) => self.ends.get(before).copied().unwrap_or(0),
            None => 0,
        };
        let end = self.ends.get(id).copied().unwrap_or(start);
        self.text.get(start..end).unwrap_or("")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_name_in_order() {
        let names = Names::new(["alpha", "", "b2"].into_iter());
        assert_eq!((&names[0], &names[1], &names[2], &names[3]), ("alpha", "", "b2", ""));
    }
}
