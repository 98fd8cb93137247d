//! Conflicting commands: two statements that may run at once and claim the same resource
//! of the same drone. The second to start waits (docs/LANGUAGE.md, section 6).
//!
//! May-run-in-parallel comes from the block structure: two statements are compared at
//! the construct where their paths part. Parallel branches, parallel `FOR` instances and
//! two handlers may overlap (W203). A handler may overlap the statements of the block it
//! listens on, unless they end before any raise of its signal; when every raise comes
//! earlier in the same sequential flow, the overlap is the handler queueing behind the
//! flow that started it (N303). An `ON EXCEPTION` may overlap what its block runs beside
//! the chain the exception aborts (W203; `sites::goes_on_beside_exceptions`), unless it
//! hears only the drone's own exceptions, which stop the drone's work.
//!
//! Two firings of one `ON EVERY` (without `ONE AT A TIME`) run at once, each statement
//! holding the drone only while it runs: two statements under it on one drone may
//! interleave (W203, whatever stands between them inside), and a statement alone there
//! queues behind itself in the other firings (N303). Under `ONE AT A TIME` the firings
//! never overlap, and the body is compared as one firing.
//!
//! The rule is stated pair by pair (`pairwise.rs`, which the tests hold this to), but
//! applied construct by construct: the statements that claim one resource of one drone
//! are split down their paths, and at each construct only the children that may overlap
//! are compared, each statement with the first (in statement order) it may wait for.
//! So N statements in one SEQUENTIAL block cost N, not N² pairs, and a PARALLEL block of
//! N costs N log N. Each statement gets the report the pairwise rule gives first.
//!
//! At each construct: a sweep in source order for parallel branches and for handlers
//! (`Bucket::later_waits`), a running minimum for `PARALLEL FOR` instances, and for
//! a block's handlers one scan of its statements per signal, with `raises.rs` telling in
//! O(depth) whether a statement ends before every raise. The tests hold this to the
//! pairwise rule, diagnostic for diagnostic, on every fixture, a large generated mission
//! and 300 random block structures (`pairwise.rs`).

#[cfg(test)]
mod pairwise;
mod raises;

use std::collections::{BTreeMap, HashMap};

use aviary_api::{BuiltinSignal, DroneId, Resource};
use aviary_diagnostics::{Code, Diagnostic};
use aviary_ir::{BlockKind, ExceptionId, Mission, SignalId};

use crate::sites::{self, ClaimSite, Construct, Key, Sites};
use raises::{Order, Raises};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Overlap {
    Branches,
    Instances,
    Handlers,
    /// A handler (the waiting side) against statements its signal's raise does not order.
    HandlerAndFlow(SignalId),
    /// A handler against the flow after every raise of its signal.
    AfterSignal(SignalId),
    /// Firings of one `ON EVERY`: a statement alone on the drone there, against itself.
    Firings(SignalId),
    /// Two statements under one `ON EVERY` whose firings may interleave.
    Interleave(SignalId),
    /// An `ON EXCEPTION` (the waiting side) against what its block runs meanwhile.
    Exception(ExceptionId),
}

impl Overlap {
    /// W203 (0) or N303 (1).
    fn slot(self) -> usize {
        usize::from(matches!(self, Overlap::AfterSignal(_) | Overlap::Firings(_)))
    }
}

/// What a waiting statement waits for first: its partner, and the order in which the
/// pairwise rule meets the pair (positions in the bucket, lower first).
#[derive(Clone, Copy)]
struct Found {
    at: (usize, usize),
    other: usize,
    why: Overlap,
}

/// Per statement of a bucket (by position) that waits at all, the first W203 and N303
/// partner. Sparse: in a long SEQUENTIAL block nobody waits.
type Best = HashMap<usize, [Option<Found>; 2]>;

fn offer(best: &mut Best, waiting: usize, other: usize, why: Overlap) {
    let at = (waiting.min(other), waiting.max(other));
    let slot = &mut best.entry(waiting).or_default()[why.slot()];
    if slot.map_or(true, |f| at < f.at) {
        *slot = Some(Found { at, other, why });
    }
}

/// Appends a W203 or N303 for each statement that may have to wait for a drone.
pub fn check_conflicts(mission: &Mission, diagnostics: &mut Vec<Diagnostic>) {
    let sites = sites::collect(mission);
    let raises = Raises::new(&sites);
    let mut buckets: BTreeMap<(DroneId, Resource), Vec<usize>> = BTreeMap::new();
    for (i, site) in sites.claims.iter().enumerate() {
        for &claim in &site.claims {
            buckets.entry(claim).or_default().push(i);
        }
    }
    // One report per waiting statement (at the same place, the first pair the pairwise
    // rule meets: buckets in order, then pairs by position).
    let mut found: BTreeMap<(u32, u32, Code), Diagnostic> = BTreeMap::new();
    for (&(drone, resource), members) in &buckets {
        let best = Bucket { sites: &sites, mission, raises: &raises, drone, members }.solve();
        let mut first: BTreeMap<(u32, u32, Code), (usize, Found)> = BTreeMap::new();
        for (&w, slots) in &best {
            for f in slots.iter().flatten() {
                let origin = &sites.claims[members[w]].origin;
                let code =
                    if f.why.slot() == 0 { Code::CommandsMayCollide } else { Code::CommandsQueue };
                let entry =
                    first.entry((origin.file.0, origin.span.start, code)).or_insert((w, *f));
                // The map's order is arbitrary: the pair's order alone decides.
                if (f.at, w) < (entry.1.at, entry.0) {
                    *entry = (w, *f);
                }
            }
        }
        for (key, (w, f)) in first {
            found.entry(key).or_insert_with(|| {
                report(
                    mission,
                    &sites.claims[members[w]],
                    &sites.claims[members[f.other]],
                    drone,
                    resource,
                    &f.why,
                )
            });
        }
    }
    diagnostics.extend(found.into_values());
}

/// A statement's place in the source (file, byte), then the later position first.
type SourceOrder = (u32, u32, std::cmp::Reverse<usize>);

/// A statement seen by a sweep: its position and its group.
type Seen = (usize, usize);

/// The statements that claim one resource of one drone, by position (site order).
struct Bucket<'a> {
    sites: &'a Sites,
    mission: &'a Mission,
    raises: &'a Raises,
    drone: DroneId,
    members: &'a [usize],
}

impl Bucket<'_> {
    fn path(&self, pos: usize) -> &[sites::Step] {
        &self.sites.claims[self.members[pos]].path
    }

    fn solve(&self) -> Best {
        let mut best = Best::new();
        // Under an `ON EVERY` whose firings overlap: a statement alone there waits for
        // itself in another firing; several interleave, each pair.
        let mut firings: BTreeMap<sites::Step, (SignalId, Vec<usize>)> = BTreeMap::new();
        for pos in 0..self.members.len() {
            if let Some((step, signal)) = sites::overlapping_firings(self.sites, self.path(pos)) {
                firings.entry(step).or_insert((signal, Vec::new())).1.push(pos);
            }
        }
        for (signal, group) in firings.values() {
            match group.as_slice() {
                [pos] => offer(&mut best, *pos, *pos, Overlap::Firings(*signal)),
                _ => {
                    let each: Vec<&[usize]> = group.chunks(1).collect();
                    self.later_waits(&each, Overlap::Interleave(*signal), &mut best);
                }
            }
        }
        self.split(&(0..self.members.len()).collect::<Vec<_>>(), 0, &mut best);
        best
    }

    /// Whether a step enters an `ON EVERY` whose firings may overlap: all below it is
    /// compared in `solve`.
    fn overlapping(&self, id: usize, key: Key) -> bool {
        let Key::Handler(h) = key else { return false };
        self.sites.handlers.get(&(id, h)).is_some_and(|i| i.every && !i.one_at_a_time)
    }

    /// `group` shares the path down to `depth`, which enters no `ON EVERY` whose firings
    /// overlap.
    fn split(&self, group: &[usize], depth: usize, best: &mut Best) {
        let step = |pos: usize| self.path(pos).get(depth).copied();
        // Sites are in the order of a depth-first walk that visits a construct's children
        // in key order, so a group's steps come sorted, each child's statements together.
        // Under a SEQUENTIAL block without handlers nothing overlaps at this step: only
        // children of two or more statements are looked into, and nothing is allocated
        // (a block of a million statements is one pass).
        let sorted = group.first().is_some_and(|&p| step(p).is_some())
            && group.windows(2).all(|w| step(w[0]) <= step(w[1]));
        if let (true, Some(Some((id, _)))) = (sorted, group.first().map(|&p| step(p))) {
            let one_construct =
                group.last().and_then(|&p| step(p)).is_some_and(|(last, _)| last == id);
            let plain =
                matches!(self.sites.constructs[id], Construct::Block(BlockKind::Sequential))
                    && group.iter().all(|&p| {
                        !matches!(step(p), Some((_, Key::Handler(_) | Key::Exception(_))))
                    });
            if one_construct && plain {
                for child in group.chunk_by(|&a, &b| step(a) == step(b)).filter(|g| g.len() > 1) {
                    self.split(child, depth + 1, best);
                }
                return;
            }
        }
        // Otherwise: by construct, then child, each in position order, cut into runs.
        let mut steps: Vec<((usize, Key), usize)> = group
            .iter()
            .filter_map(|&pos| self.path(pos).get(depth).map(|&step| (step, pos)))
            .collect();
        if !steps.windows(2).all(|w| w[0] <= w[1]) {
            steps.sort_unstable();
        }
        let positions: Vec<usize> = steps.iter().map(|&(_, pos)| pos).collect();
        let mut children: Vec<((usize, Key), &[usize])> = Vec::new();
        let mut from = 0;
        for run in steps.chunk_by(|a, b| a.0 == b.0) {
            children.push((run[0].0, &positions[from..from + run.len()]));
            from += run.len();
        }
        for same in children.chunk_by(|a, b| a.0 .0 == b.0 .0) {
            let id = same[0].0 .0;
            // The analysis's own kinds of step, not the IR's nodes (`sites.rs` names those):
            // only parallel blocks and FOR order nothing.
            #[allow(clippy::wildcard_enum_match_arm)]
            match self.sites.constructs[id] {
                // A SEQUENTIAL block without handlers orders all it holds: nothing here.
                Construct::Block(kind)
                    if kind == BlockKind::Parallel
                        || same
                            .iter()
                            .any(|(s, _)| matches!(s.1, Key::Handler(_) | Key::Exception(_))) =>
                {
                    self.block(id, kind, depth, same, best);
                }
                Construct::For { parallel: true } => {
                    // A later instance waits for any earlier one.
                    let mut earliest: Option<usize> = None;
                    for (_, g) in same {
                        if let Some(p) = earliest {
                            for &w in g.iter() {
                                offer(best, w, p, Overlap::Instances);
                            }
                        }
                        earliest = match (earliest, g.first()) {
                            (Some(e), Some(&f)) => Some(e.min(f)),
                            (e, f) => e.or(f.copied()),
                        };
                    }
                }
                _ => {}
            }
            // One statement alone below a step pairs with nobody there (with itself only
            // through `ON EVERY`, which `solve` has done, as all below such a handler).
            for ((sid, key), g) in same.iter().filter(|(_, g)| g.len() > 1) {
                if !self.overlapping(*sid, *key) {
                    self.split(g, depth + 1, best);
                }
            }
        }
    }

    /// The children of block `id` that hold statements of the bucket: its items (branches
    /// of a PARALLEL block), its handlers and its exception handlers.
    fn block(
        &self,
        id: usize,
        kind: BlockKind,
        depth: usize,
        same: &[((usize, Key), &[usize])],
        best: &mut Best,
    ) {
        let items: Vec<&[usize]> =
            same.iter().filter(|(s, _)| matches!(s.1, Key::Item(_))).map(|(_, g)| *g).collect();
        let handlers: Vec<(usize, &[usize])> = same
            .iter()
            .filter_map(|(s, g)| if let Key::Handler(h) = s.1 { Some((h, *g)) } else { None })
            .collect();
        // An exception handler that hears only this drone stops its work: left out.
        let exceptions: Vec<(usize, &[usize])> = same
            .iter()
            .filter_map(|(s, g)| if let Key::Exception(e) = s.1 { Some((e, *g)) } else { None })
            .filter(|(e, _)| !sites::stops_the_drone(self.sites, id, *e, self.drone))
            .collect();
        if kind == BlockKind::Parallel {
            self.later_waits(&items, Overlap::Branches, best);
        }
        let all_handlers: Vec<&[usize]> =
            handlers.iter().chain(&exceptions).map(|(_, g)| *g).collect();
        self.later_waits(&all_handlers, Overlap::Handlers, best);
        self.handlers_and_items(id, depth, &handlers, &items, best);
        self.exceptions_and_items(id, depth, &exceptions, &items, best);
    }

    /// An exception handler of block `id` against the block's own statements: the
    /// handler's statement waits for the first that may run meanwhile.
    fn exceptions_and_items(
        &self,
        id: usize,
        depth: usize,
        exceptions: &[(usize, &[usize])],
        items: &[&[usize]],
        best: &mut Best,
    ) {
        if exceptions.is_empty() {
            return;
        }
        let all = sites::goes_on_beside_exceptions(self.sites, id);
        let first = items
            .iter()
            .flat_map(|g| g.iter().copied())
            .filter(|&x| all || sites::beside_the_chain(self.sites, &self.path(x)[depth + 1..]))
            .min();
        let Some(x) = first else { return };
        for &(e, g) in exceptions {
            let Some(info) = self.sites.exceptions.get(&(id, e)) else { continue };
            for &w in g {
                offer(best, w, x, Overlap::Exception(info.exception));
            }
        }
    }

    /// Statements in different `groups` (branches, or handlers) may overlap; the one later
    /// in the source waits. Swept in source order, each statement is offered the first
    /// (by position) of the statements of other groups before it.
    fn later_waits(&self, groups: &[&[usize]], why: Overlap, best: &mut Best) {
        if groups.len() < 2 {
            return;
        }
        // (source place, then later position first; position; group)
        let mut order: Vec<(SourceOrder, usize, usize)> = Vec::new();
        for (g, members) in groups.iter().enumerate() {
            for &pos in members.iter() {
                let o = &self.sites.claims[self.members[pos]].origin;
                // Equal places: the pairwise rule makes the earlier position wait.
                order.push(((o.file.0, o.span.start, std::cmp::Reverse(pos)), pos, g));
            }
        }
        order.sort_unstable();
        // The first two positions seen, from two different groups.
        let (mut first, mut second): (Option<Seen>, Option<Seen>) = (None, None);
        for (_, pos, g) in order {
            let other = match first {
                Some((p, fg)) if fg != g => Some(p),
                _ => second.map(|(p, _)| p),
            };
            if let Some(p) = other {
                offer(best, pos, p, why);
            }
            match first {
                Some((p, fg)) if pos < p => {
                    if fg != g {
                        second = first;
                    }
                    first = Some((pos, g));
                }
                Some((_, fg)) if fg != g && second.map_or(true, |(p, _)| pos < p) => {
                    second = Some((pos, g))
                }
                None => first = Some((pos, g)),
                _ => {}
            }
        }
    }

    /// A handler of block `id` against the block's own statements: the handler's
    /// statement waits, unless they end before every raise of its signal.
    fn handlers_and_items(
        &self,
        id: usize,
        depth: usize,
        handlers: &[(usize, &[usize])],
        items: &[&[usize]],
        best: &mut Best,
    ) {
        if handlers.is_empty() || items.is_empty() {
            return;
        }
        let mut flow: Vec<usize> = items.iter().flat_map(|g| g.iter().copied()).collect();
        flow.sort_unstable();
        // Per signal: the first statement it races with (W203), and the first it queues
        // behind (N303).
        let mut memo: HashMap<SignalId, (Option<usize>, Option<usize>)> = HashMap::new();
        for &(h, g) in handlers {
            let Some(info) = self.sites.handlers.get(&(id, h)) else { continue };
            let signal = info.signal;
            // A drone's link comes back only after it was lost, and the loss aborted what
            // the drone was doing: its own restore handler does not race with that.
            if signal == self.mission.builtins.signal(BuiltinSignal::ConnectionRestored)
                && info.by.as_deref() == Some(&[self.drone])
            {
                continue;
            }
            let (race, queue) =
                *memo.entry(signal).or_insert_with(|| self.first_of_flow(id, depth, signal, &flow));
            for &w in g.iter() {
                if let Some(x) = race {
                    offer(best, w, x, Overlap::HandlerAndFlow(signal));
                }
                if let Some(x) = queue {
                    offer(best, w, x, Overlap::AfterSignal(signal));
                }
            }
        }
    }

    fn first_of_flow(
        &self,
        id: usize,
        depth: usize,
        signal: SignalId,
        flow: &[usize],
    ) -> (Option<usize>, Option<usize>) {
        if sites::untimed(self.mission, signal) {
            return (flow.first().copied(), None);
        }
        if !self.raises.under(id, signal) {
            return (None, None);
        }
        let (mut race, mut queue) = (None, None);
        for &x in flow {
            match self.raises.order(self.sites, self.path(x), depth, signal) {
                Order::After => {}
                Order::Before => queue = queue.or(Some(x)),
                Order::Neither => race = race.or(Some(x)),
            }
            if race.is_some() && queue.is_some() {
                break;
            }
        }
        (race, queue)
    }
}

fn report(
    mission: &Mission,
    waiting: &ClaimSite,
    other: &ClaimSite,
    drone: DroneId,
    resource: Resource,
    why: &Overlap,
) -> Diagnostic {
    let name = &mission.drones[drone];
    let cap = |s: &ClaimSite| mission.capabilities[s.capability].name.clone();
    let signal = |s: &SignalId| mission.signals[*s].clone();
    let res = resource.as_str();
    // Kinds of finding, not constructs: several share one wording.
    #[allow(clippy::wildcard_enum_match_arm)]
    let (code, message, help) = match why {
        Overlap::Firings(s) => (
            Code::CommandsQueue,
            format!("each `{}` firing runs `{name} {}`; a firing that reaches it while another firing's runs waits until that one ends", signal(s), cap(waiting)),
            format!("the firings take {name}'s {res} one at a time, first come, first served; to run each firing whole before the next starts, write `ONE AT A TIME` at the end of the handler's header"),
        ),
        Overlap::Interleave(s) => (
            Code::CommandsMayCollide,
            format!("{name} is commanded from two places that may run at once (two `{}` firings may interleave: another firing's `{name} {}` may take {name} between this firing's statements); the second to start waits", signal(s), cap(other)),
            format!("write `ONE AT A TIME` at the end of the handler's header (`ON EVERY {} ... ONE AT A TIME:`) so that each firing runs whole before the next starts, or give the firings different drones", signal(s)),
        ),
        Overlap::AfterSignal(s) => (
            Code::CommandsQueue,
            format!("`{name} {}` in the handler for `{}` may wait for {name}: the flow that raised the signal goes on with `{name} {}`", cap(waiting), signal(s), cap(other)),
            format!("whichever starts first holds {name}'s {res}; the other waits until it ends (the flow goes first when its statement follows the SIGNAL directly)"),
        ),
        _ => {
            let how = match why {
                Overlap::Branches => "they are in parallel branches".to_string(),
                Overlap::Instances => "two instances of this PARALLEL FOR both give it".to_string(),
                Overlap::Handlers => "both handlers may run at once".to_string(),
                Overlap::HandlerAndFlow(s) => format!("`{}` may be raised while the other statement runs", signal(s)),
                Overlap::Exception(e) => format!("`{}` may be handled while the other statement runs", mission.exceptions.get(*e).map_or("", String::as_str)),
                _ => String::new(),
            };
            (
                Code::CommandsMayCollide,
                format!("{name} is commanded from two places that may run at once ({how}); the second to start waits"),
                match why {
                    Overlap::Instances => "use SEQUENTIAL FOR, or give each instance its own drone".to_string(),
                    _ => format!("put the two in one SEQUENTIAL block if one should go first, or use another drone; until then `{name} {}` waits for {name}'s {res}", cap(waiting)),
                },
            )
        }
    };
    let mut d = Diagnostic::new(code, waiting.origin.file, waiting.origin.span, message)
        .label(format!("waits for {name}'s {res}"))
        .with_help(help);
    if waiting.origin != other.origin {
        d = d.also(
            other.origin.file,
            other.origin.span,
            format!("holds {name}'s {res} meanwhile: `{name} {}`", cap(other)),
        );
    }
    d
}
