//! A quick hasher for the reader's sets of names, which a large world looks up once per
//! drone. The names come from the operator's own world file, so the default SipHash's
//! resistance to chosen collisions buys nothing here (a file that collides on purpose
//! only reads slower).

use std::collections::{HashMap, HashSet};
use std::hash::{BuildHasherDefault, Hasher};

/// Multiply-rotate over 8-byte words (as rustc's FxHasher), then MurmurHash3's final
/// mix: without it, names that differ only in their last characters (`a12345`,
/// `a12346`) differ only in the high bits, and the table's buckets come from the low.
#[derive(Clone, Copy, Default)]
pub(crate) struct Quick(u64);

impl Quick {
    fn add(&mut self, word: u64) {
        self.0 = (self.0.rotate_left(5) ^ word).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

impl Hasher for Quick {
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            self.add(u64::from_le_bytes(c.try_into().unwrap_or_default()));
        }
        let mut last = [0u8; 8];
        last[..chunks.remainder().len()].copy_from_slice(chunks.remainder());
        self.add(u64::from_le_bytes(last));
    }

    fn write_u8(&mut self, b: u8) {
        self.add(u64::from(b));
    }

    fn write_usize(&mut self, n: usize) {
        self.add(n as u64);
    }

    fn finish(&self) -> u64 {
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
}

pub(crate) type QuickMap<K, V> = HashMap<K, V, BuildHasherDefault<Quick>>;
pub(crate) type QuickSet<K> = HashSet<K, BuildHasherDefault<Quick>>;

#[cfg(test)]
mod tests {
    use std::hash::BuildHasher;

    use super::*;

    /// Names that differ only at their end spread over the low bits (the buckets).
    #[test]
    fn similar_names_spread_over_buckets() {
        let build = BuildHasherDefault::<Quick>::default();
        let buckets: HashSet<u64> =
            (0..4096).map(|i| build.hash_one(format!("a{i}")) & 4095).collect();
        assert!(buckets.len() > 2400, "{} of 4096 buckets", buckets.len());
    }
}
