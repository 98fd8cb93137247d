//! `--shard I/N`: the I-th of N shares of a campaign's seeds. The k-th run of the campaign
//! (seed `first + k`, k from 0) is in share `k mod N + 1`: the shares are as even as can
//! be (no two differ by more than one run), and each spreads over the whole range.

use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// From 1 to `count`.
    pub index: u64,
    pub count: u64,
}

impl Shard {
    /// `I/N` with 1 <= I <= N.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let wrong = || {
            format!("`{text}` is not a shard: write I/N, the I-th of N shares, with 1 <= I <= N (such as 1/4)")
        };
        let (i, n) = text.split_once('/').ok_or_else(wrong)?;
        let (index, count): (u64, u64) =
            (i.trim().parse().map_err(|_| wrong())?, n.trim().parse().map_err(|_| wrong())?);
        if count == 0 {
            return Err(format!(
                "`{text}` is not a shard: there must be at least one share (N >= 1)"
            ));
        }
        if index == 0 || index > count {
            return Err(format!(
                "`{text}` is not a shard: I must be from 1 to {count} (shares are counted from 1)"
            ));
        }
        Ok(Shard { index, count })
    }

    /// Whether the k-th run of the campaign (from 0) is in this share.
    pub fn holds(&self, k: u64) -> bool {
        k % self.count == self.index - 1
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_are_read_and_checked() {
        assert_eq!(Shard::parse("2/3"), Ok(Shard { index: 2, count: 3 }));
        for bad in ["0/3", "4/3", "1/0", "x", "1/", "/2", "-1/3", "1/3/4", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn every_run_is_in_exactly_one_share() {
        for count in 1..7 {
            for k in 0..50 {
                let holders = (1..=count).filter(|i| Shard { index: *i, count }.holds(k)).count();
                assert_eq!(holders, 1);
            }
        }
    }
}
