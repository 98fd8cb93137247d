//! Where each signal is raised, summed up per construct: for a construct and a signal,
//! which of its children hold a raise. Enough to tell, walking down one statement's
//! path, whether every raise of the signal under a block comes after the statement
//! (it ends first), or before it, without looking at the raises one by one.

use std::collections::HashMap;

use aviary_ir::{BlockKind, SignalId};

use crate::sites::{Construct, Key, Sites, Step};

/// The children of one construct that hold a raise of one signal.
#[derive(Default)]
struct Children {
    /// Sorted, each once.
    keys: Vec<Key>,
    /// The lowest and highest `Item` and `Instance` indices among them.
    items: Option<(usize, usize)>,
    instances: Option<(usize, usize)>,
}

/// Whether a statement's raises all come after it, all before it, or neither.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub enum Order {
    After,
    Before,
    Neither,
}

pub struct Raises {
    by: HashMap<(usize, SignalId), Children>,
}

impl Raises {
    pub fn new(sites: &Sites) -> Raises {
        let mut by: HashMap<(usize, SignalId), Children> = HashMap::new();
        for r in &sites.raises {
            for &(construct, key) in &r.path {
                let c = by.entry((construct, r.signal)).or_default();
                c.keys.push(key);
                let widen = |range: &mut Option<(usize, usize)>, i: usize| {
                    *range = Some(range.map_or((i, i), |(lo, hi)| (lo.min(i), hi.max(i))))
                };
                // Steps of the analysis, not constructs: only items and instances are ranges.
                #[allow(clippy::wildcard_enum_match_arm)]
                match key {
                    Key::Item(i) => widen(&mut c.items, i),
                    Key::Instance(i) => widen(&mut c.instances, i),
                    _ => {}
                }
            }
        }
        for c in by.values_mut() {
            c.keys.sort_unstable();
            c.keys.dedup();
        }
        Raises { by }
    }

    /// Whether `signal` is raised anywhere under `construct`.
    pub fn under(&self, construct: usize, signal: SignalId) -> bool {
        self.by.contains_key(&(construct, signal))
    }

    /// How the raises of `signal` under the construct at `path[from]` stand to the
    /// statement at `path`: `After` when it ends before every one starts (`before(x, r)`
    /// of the pairwise rule for each), `Before` when every one ends before it starts.
    /// At least one must be there ([`Raises::under`]).
    pub fn order(&self, sites: &Sites, path: &[Step], from: usize, signal: SignalId) -> Order {
        let (mut after, mut before) = (true, true);
        for (depth, &(construct, key)) in path.iter().enumerate().skip(from) {
            let Some(children) = self.by.get(&(construct, signal)) else { break };
            let own = children.keys.binary_search(&key).is_ok();
            // The raises that part from the statement's path here, under the other children.
            if children.keys.len() > usize::from(own) {
                let (a, b) = match (sites.constructs[construct], key) {
                    (Construct::Block(BlockKind::Sequential), Key::Item(i)) => {
                        let only_items = children.keys.iter().all(|k| matches!(k, Key::Item(_)));
                        let (lo, hi) = children.items.unwrap_or((i, i));
                        (only_items && lo >= i, only_items && hi <= i)
                    }
                    (Construct::For { parallel: false }, Key::Instance(i)) => {
                        let (lo, hi) = children.instances.unwrap_or((i, i));
                        (lo >= i, hi <= i)
                    }
                    _ => (false, false),
                };
                after &= a;
                before &= b;
            }
            // A raise under the statement's own last step is the statement's own (its
            // capability raises the signal): neither before nor after it.
            if !own {
                break;
            }
            if depth + 1 == path.len() {
                (after, before) = (false, false);
            }
            if !after && !before {
                break;
            }
        }
        match (after, before) {
            (true, _) => Order::After,
            (false, true) => Order::Before,
            (false, false) => Order::Neither,
        }
    }
}
