//! Conflicting commands: two mission-level statements that may run at once and claim the
//! same resource of the same drone. The second to start waits (LANGUAGE.md §3).
//!
//! May-run-in-parallel comes from the block structure: two statements are compared at
//! the construct where their paths part. Parallel branches, parallel `FOR` instances and
//! two handlers may overlap (W203). A handler may overlap the statements of the block it
//! listens on, unless they end before any raise of its signal; when every raise comes
//! earlier in the same sequential flow, the overlap is the handler queueing behind the
//! flow that started it, and firings of one `ON EVERY` queue behind each other (N303).

use std::collections::BTreeMap;

use aviary_api::{DroneId, Resource};
use aviary_diagnostics::{Code, Diagnostic};
use aviary_ir::{BlockKind, Mission, SignalId};

use crate::sites::{self, ClaimSite, Construct, Key, Sites, Step};

enum Overlap {
    Branches,
    Instances,
    Handlers,
    /// A handler (the waiting side) against statements its signal's raise does not order.
    HandlerAndFlow(SignalId),
    /// A handler against the flow after every raise of its signal.
    AfterSignal(SignalId),
    /// Firings of one `ON EVERY`.
    Firings(SignalId),
}

/// Appends a W203 or N303 for each statement that may have to wait for a drone.
pub fn check_conflicts(mission: &Mission, diagnostics: &mut Vec<Diagnostic>) {
    let sites = sites::collect(mission);
    let mut buckets: BTreeMap<(DroneId, Resource), Vec<usize>> = BTreeMap::new();
    for (i, site) in sites.claims.iter().enumerate() {
        for &claim in &site.claims {
            buckets.entry(claim).or_default().push(i);
        }
    }
    // One report per waiting statement (at the same place, the first other one found).
    let mut found: BTreeMap<(u32, u32, Code), Diagnostic> = BTreeMap::new();
    for (&(drone, resource), members) in &buckets {
        for (n, &a) in members.iter().enumerate() {
            for &b in &members[n..] {
                let Some((waiting, other, overlap)) = overlap(&sites, mission, drone, a, b) else { continue };
                let d = report(mission, &sites.claims[waiting], &sites.claims[other], drone, resource, &overlap);
                let w = &sites.claims[waiting].origin;
                found.entry((w.file.0, w.span.start, d.code)).or_insert(d);
            }
        }
    }
    diagnostics.extend(found.into_values());
}

/// Whether sites `a` and `b` may run at once: which one waits, which holds, and why.
fn overlap(sites: &Sites, mission: &Mission, drone: DroneId, a: usize, b: usize) -> Option<(usize, usize, Overlap)> {
    let (pa, pb) = (&sites.claims[a].path, &sites.claims[b].path);
    let every = pa.iter().zip(pb).take_while(|(x, y)| x == y).find_map(|((id, key), _)| match key {
        Key::Handler(h) => sites.handlers.get(&(*id, *h)).filter(|info| info.every).map(|info| info.signal),
        _ => None,
    });
    if a == b {
        return every.map(|signal| (a, a, Overlap::Firings(signal)));
    }
    let k = pa.iter().zip(pb).take_while(|(x, y)| x == y).count();
    let (&(id, ka), &(idb, kb)) = (pa.get(k)?, pb.get(k)?);
    if id != idb {
        return None;
    }
    let later = |x: usize, y: usize| if later_in_source(&sites.claims[x], &sites.claims[y]) { (x, y) } else { (y, x) };
    match (sites.constructs[id], ka, kb) {
        (Construct::Block(BlockKind::Parallel), Key::Item(_), Key::Item(_)) => {
            let (w, o) = later(a, b);
            Some((w, o, Overlap::Branches))
        }
        (Construct::Block(_), Key::Handler(_), Key::Handler(_)) => {
            let (w, o) = later(a, b);
            Some((w, o, Overlap::Handlers))
        }
        (Construct::Block(_), Key::Item(_), Key::Handler(h)) => handler_and_item(sites, mission, drone, &pb[..=k], h, a, b),
        (Construct::Block(_), Key::Handler(h), Key::Item(_)) => handler_and_item(sites, mission, drone, &pa[..=k], h, b, a),
        (Construct::For { parallel: true }, Key::Instance(i), Key::Instance(j)) => {
            let (w, o) = if i > j { (a, b) } else { (b, a) };
            Some((w, o, Overlap::Instances))
        }
        _ => None,
    }
    .filter(|_| every.is_none() || matches!(sites.constructs[id], Construct::Block(BlockKind::Parallel) | Construct::For { parallel: true }))
}

/// A statement `item` of a block against statement `handler_site` of handler `h` there;
/// `at` is the path down to the handler step.
fn handler_and_item(sites: &Sites, mission: &Mission, drone: DroneId, at: &[Step], h: usize, item: usize, handler_site: usize) -> Option<(usize, usize, Overlap)> {
    let (block, _) = *at.last()?;
    let info = sites.handlers.get(&(block, h))?;
    let signal = info.signal;
    // A drone's link comes back only after it was lost, and the loss aborted what the
    // drone was doing: its own restore handler does not race with that.
    if mission.signals[signal] == "ConnectionRestored" && info.by.as_deref() == Some(&[drone]) {
        return None;
    }
    let prefix = &at[..at.len() - 1];
    let raises: Vec<&[Step]> = sites
        .raises
        .iter()
        .filter(|r| r.signal == signal && r.path.len() > prefix.len() && r.path[..prefix.len()] == *prefix && r.path[prefix.len()].0 == block)
        .map(|r| r.path.as_slice())
        .collect();
    let x = sites.claims[item].path.as_slice();
    if sites::untimed(mission, signal) {
        return Some((handler_site, item, Overlap::HandlerAndFlow(signal)));
    }
    if raises.is_empty() || raises.iter().all(|r| before(sites, x, r)) {
        return None;
    }
    if raises.iter().all(|r| before(sites, r, x)) {
        return Some((handler_site, item, Overlap::AfterSignal(signal)));
    }
    Some((handler_site, item, Overlap::HandlerAndFlow(signal)))
}

/// Whether the statement at `p` always ends before the one at `q` starts.
fn before(sites: &Sites, p: &[Step], q: &[Step]) -> bool {
    let k = p.iter().zip(q).take_while(|(x, y)| x == y).count();
    let (Some(&(id, kp)), Some(&(_, kq))) = (p.get(k), q.get(k)) else { return false };
    match (sites.constructs[id], kp, kq) {
        (Construct::Block(BlockKind::Sequential), Key::Item(i), Key::Item(j)) => i < j,
        (Construct::For { parallel: false }, Key::Instance(i), Key::Instance(j)) => i < j,
        _ => false,
    }
}

fn later_in_source(x: &ClaimSite, y: &ClaimSite) -> bool {
    (x.origin.file.0, x.origin.span.start) >= (y.origin.file.0, y.origin.span.start)
}

fn report(mission: &Mission, waiting: &ClaimSite, other: &ClaimSite, drone: DroneId, resource: Resource, why: &Overlap) -> Diagnostic {
    let name = &mission.drones[drone];
    let cap = |s: &ClaimSite| mission.capabilities[s.capability].name.clone();
    let signal = |s: &SignalId| mission.signals[*s].clone();
    let res = resource.as_str();
    let (code, message, help) = match why {
        Overlap::Firings(s) => (
            Code::CommandsQueue,
            format!("each `{}` firing runs `{name} {}`; a later firing waits until the earlier one ends", signal(s), cap(waiting)),
            format!("the handler's firings take {name}'s {res} one at a time, in the order of their signals"),
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
    let mut d = Diagnostic::new(code, waiting.origin.file, waiting.origin.span, message).label(format!("waits for {name}'s {res}")).with_help(help);
    if waiting.origin != other.origin {
        d = d.also(other.origin.file, other.origin.span, format!("holds {name}'s {res} meanwhile: `{name} {}`", cap(other)));
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    struct NoFiles;

    impl aviary_check::SourceProvider for NoFiles {
        fn load(&self, _from: &str, path: &str) -> Result<(String, Vec<u8>), aviary_check::LoadError> {
            Err(format!("no files here ({path})").into())
        }
    }

    /// May-run-in-parallel is symmetric, whichever statement the pair starts from; checked
    /// on every pair of claimants in a large generated mission.
    #[test]
    fn may_run_in_parallel_is_symmetric() {
        let (text, world) = aviary_check::generate::large_mission(150_000);
        let mut sources = aviary_diagnostics::SourceMap::new();
        let api = aviary_api::Descriptor::standard();
        let checked = aviary_check::check_sources(&mut sources, ("gen.mission", text.as_bytes()), Some(("gen.world.toml", world.as_bytes())), &NoFiles, &api);
        let mission = aviary_ir::compile(checked.program.as_ref().expect("program"), checked.world.as_ref().expect("world"), &api).expect("a mission");
        let sites = sites::collect(&mission);
        let mut pairs = 0;
        for (i, x) in sites.claims.iter().enumerate() {
            for (j, y) in sites.claims.iter().enumerate().skip(i) {
                let Some(&(drone, _)) = x.claims.iter().find(|c| y.claims.contains(c)) else { continue };
                let ab = overlap(&sites, &mission, drone, i, j).map(|(w, o, _)| (w, o));
                let ba = overlap(&sites, &mission, drone, j, i).map(|(w, o, _)| (w, o));
                assert_eq!(ab, ba, "sites {i} and {j}");
                pairs += 1;
            }
        }
        assert!(pairs > 1000, "only {pairs} pairs share a claim");
    }
}
