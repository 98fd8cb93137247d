//! The conflict rule pair by pair, its plainest statement: for any two statements that
//! claim one resource of one drone, whether they may run at once and which one waits.
//! Quadratic, so only the tests run it: they hold `check_conflicts` to it.

use std::collections::BTreeMap;

use aviary_api::DroneId;
use aviary_diagnostics::{Code, Diagnostic};
use aviary_ir::{BlockKind, Mission};

use super::{report, Overlap};
use crate::sites::{self, ClaimSite, Construct, Key, Sites, Step};

/// `check_conflicts` by comparing every pair of a bucket.
pub(super) fn check_conflicts_pairwise(mission: &Mission, diagnostics: &mut Vec<Diagnostic>) {
    let sites = sites::collect(mission);
    let mut buckets: BTreeMap<(DroneId, aviary_api::Resource), Vec<usize>> = BTreeMap::new();
    for (i, site) in sites.claims.iter().enumerate() {
        for &claim in &site.claims {
            buckets.entry(claim).or_default().push(i);
        }
    }
    let mut found: BTreeMap<(u32, u32, Code), Diagnostic> = BTreeMap::new();
    for (&(drone, resource), members) in &buckets {
        for (n, &a) in members.iter().enumerate() {
            for &b in &members[n..] {
                let Some((waiting, other, overlap)) = overlap(&sites, mission, drone, a, b) else {
                    continue;
                };
                // A statement waits for itself in another firing only where it is alone
                // on the drone: beside others, the firings interleave (W203).
                if a == b && alone(&sites, members, a).is_none() {
                    continue;
                }
                let d = report(
                    mission,
                    &sites.claims[waiting],
                    &sites.claims[other],
                    drone,
                    resource,
                    &overlap,
                );
                let w = &sites.claims[waiting].origin;
                found.entry((w.file.0, w.span.start, d.code)).or_insert(d);
            }
        }
    }
    diagnostics.extend(found.into_values());
}

/// `Some` when site `a` is under an `ON EVERY` whose firings overlap and no other site
/// of the bucket is under it.
fn alone(sites: &Sites, members: &[usize], a: usize) -> Option<()> {
    let (step, _) = sites::overlapping_firings(sites, &sites.claims[a].path)?;
    let shared = members.iter().any(|&b| {
        b != a
            && sites::overlapping_firings(sites, &sites.claims[b].path).map(|f| f.0) == Some(step)
    });
    (!shared).then_some(())
}

/// Whether sites `a` and `b` may run at once: which one waits, which holds, and why.
pub(super) fn overlap(
    sites: &Sites,
    mission: &Mission,
    drone: DroneId,
    a: usize,
    b: usize,
) -> Option<(usize, usize, Overlap)> {
    let (pa, pb) = (&sites.claims[a].path, &sites.claims[b].path);
    let later = |x: usize, y: usize| {
        if later_in_source(&sites.claims[x], &sites.claims[y]) {
            (x, y)
        } else {
            (y, x)
        }
    };
    // Under one `ON EVERY` whose firings overlap, anything may meet anything.
    if let Some((step, signal)) = sites::overlapping_firings(sites, pa) {
        if a == b {
            return Some((a, a, Overlap::Firings(signal)));
        }
        if sites::overlapping_firings(sites, pb).map(|f| f.0) == Some(step) {
            let (w, o) = later(a, b);
            return Some((w, o, Overlap::Interleave(signal)));
        }
    }
    if a == b {
        return None;
    }
    let k = pa.iter().zip(pb).take_while(|(x, y)| x == y).count();
    let (&(id, ka), &(idb, kb)) = (pa.get(k)?, pb.get(k)?);
    if id != idb {
        return None;
    }
    let stops =
        |key: Key| matches!(key, Key::Exception(e) if sites::stops_the_drone(sites, id, e, drone));
    match (sites.constructs[id], ka, kb) {
        (Construct::Block(BlockKind::Parallel), Key::Item(_), Key::Item(_)) => {
            let (w, o) = later(a, b);
            Some((w, o, Overlap::Branches))
        }
        (
            Construct::Block(_),
            Key::Handler(_) | Key::Exception(_),
            Key::Handler(_) | Key::Exception(_),
        ) if !stops(ka) && !stops(kb) => {
            let (w, o) = later(a, b);
            Some((w, o, Overlap::Handlers))
        }
        (Construct::Block(_), Key::Item(_), Key::Handler(h)) => {
            handler_and_item(sites, mission, drone, &pb[..=k], h, a, b)
        }
        (Construct::Block(_), Key::Handler(h), Key::Item(_)) => {
            handler_and_item(sites, mission, drone, &pa[..=k], h, b, a)
        }
        (Construct::Block(_), Key::Item(_), Key::Exception(e)) if !stops(kb) => {
            exception_and_item(sites, id, e, pa, k, a, b)
        }
        (Construct::Block(_), Key::Exception(e), Key::Item(_)) if !stops(ka) => {
            exception_and_item(sites, id, e, pb, k, b, a)
        }
        (Construct::For { parallel: true }, Key::Instance(i), Key::Instance(j)) => {
            let (w, o) = if i > j { (a, b) } else { (b, a) };
            Some((w, o, Overlap::Instances))
        }
        _ => None,
    }
}

/// Statement `item` (at `path`, an item of block `id` at depth `k`) against statement
/// `handler_site` of the block's exception handler `e`.
fn exception_and_item(
    sites: &Sites,
    id: usize,
    e: usize,
    path: &[Step],
    k: usize,
    item: usize,
    handler_site: usize,
) -> Option<(usize, usize, Overlap)> {
    let info = sites.exceptions.get(&(id, e))?;
    let meanwhile = sites::goes_on_beside_exceptions(sites, id)
        || sites::beside_the_chain(sites, &path[k + 1..]);
    meanwhile.then_some((handler_site, item, Overlap::Exception(info.exception)))
}

/// A statement `item` of a block against statement `handler_site` of handler `h` there;
/// `at` is the path down to the handler step.
fn handler_and_item(
    sites: &Sites,
    mission: &Mission,
    drone: DroneId,
    at: &[Step],
    h: usize,
    item: usize,
    handler_site: usize,
) -> Option<(usize, usize, Overlap)> {
    let (block, _) = *at.last()?;
    let info = sites.handlers.get(&(block, h))?;
    let signal = info.signal;
    // A drone's link comes back only after it was lost, and the loss aborted what the
    // drone was doing: its own restore handler does not race with that.
    let restored = mission.builtins.signal(aviary_api::BuiltinSignal::ConnectionRestored);
    if signal == restored && info.by.as_deref() == Some(&[drone]) {
        return None;
    }
    let prefix = &at[..at.len() - 1];
    let raises: Vec<&[Step]> = sites
        .raises
        .iter()
        .filter(|r| {
            r.signal == signal
                && r.path.len() > prefix.len()
                && r.path[..prefix.len()] == *prefix
                && r.path[prefix.len()].0 == block
        })
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

#[cfg(test)]
mod tests {
    use super::*;
    use aviary_test_support::harness;

    fn compiled(text: &str, world: &str) -> Mission {
        harness::compile(text, world).0
    }

    /// Both ways of applying the rule, on one mission: the same diagnostics, in order.
    fn agree(mission: &Mission) -> Vec<Diagnostic> {
        let (mut fast, mut slow) = (Vec::new(), Vec::new());
        super::super::check_conflicts(mission, &mut fast);
        check_conflicts_pairwise(mission, &mut slow);
        assert!(fast == slow, "construct by construct:\n{fast:#?}\npair by pair:\n{slow:#?}");
        fast
    }

    #[test]
    fn construct_by_construct_gives_what_pair_by_pair_gives_on_every_fixture() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
        let default_world = std::fs::read_to_string(dir.join("world.toml")).expect("world");
        let mut seen = 0;
        for entry in std::fs::read_dir(&dir).expect("fixtures") {
            let path = entry.expect("entry").path();
            if path.extension().is_none_or(|e| e != "mission") {
                continue;
            }
            let own = path.with_extension("world.toml");
            let world = std::fs::read_to_string(&own).unwrap_or_else(|_| default_world.clone());
            agree(&compiled(&std::fs::read_to_string(&path).expect("mission"), &world));
            seen += 1;
        }
        assert!(seen >= 10, "only {seen} fixtures");
    }

    #[test]
    fn construct_by_construct_gives_what_pair_by_pair_gives_on_a_large_mission() {
        let (text, world) = aviary_bench::generate::large_mission(150_000);
        let found = agree(&compiled(&text, &world));
        assert!(found.len() > 10, "only {} findings", found.len());
    }

    /// A PARALLEL block of N statements on one drone: each but the first waits, and for
    /// the first (the pairwise rule's choice); a SEQUENTIAL block of many: nothing.
    #[test]
    fn large_blocks_on_one_drone_give_one_finding_per_waiting_statement() {
        let world = aviary_bench::generate::front_world();
        let n = 400;
        let mut text = String::from("MISSION M:\n    PARALLEL All:\n");
        for _ in 0..n {
            text.push_str("        scout Hover WITH 1s\n");
        }
        let found = agree(&compiled(&text, &world));
        assert_eq!(found.len(), n - 1);
        assert!(found.iter().all(|d| d.code == Code::CommandsMayCollide
            && d.secondary[0].span.start == found[0].secondary[0].span.start));
        let many = aviary_bench::generate::sequential_mission(100_000);
        let mut none = Vec::new();
        super::super::check_conflicts(&compiled(&many, &world), &mut none);
        assert!(none.is_empty(), "{none:?}");
        let mut text = String::from("MISSION M:\n    PARALLEL All:\n");
        for _ in 0..50_000 {
            text.push_str("        scout Hover WITH 1s\n");
        }
        let mut found = Vec::new();
        super::super::check_conflicts(&compiled(&text, &world), &mut found);
        assert_eq!(found.len(), 49_999);
    }

    /// Capabilities the random missions call: one that gives work to another drone than
    /// its own (its body is walked), with an `ON EVERY` and an exception handler inside.
    const FETCH: &str = "CAPABILITY Fetch BY d:\n    PERFORM:\n        PARALLEL:\n            b Hover WITH 1s\n            d Hover WITH 1s\n        ON EVERY S1:\n            b Hover WITH 1s\n            a Hover WITH 1s\n    EXCEPTIONS:\n        ON EXCEPTION CommandFailed:\n            b Hover WITH 1s\n\n";

    /// Random block structures on two drones: blocks, FORs, IFs, signals, handlers (ON,
    /// ON EVERY, SEQUENTIAL ON, ONE AT A TIME), exception handlers (with and without
    /// BY) and a capability whose body is walked, nested at random; both ways agree on each.
    #[test]
    fn construct_by_construct_gives_what_pair_by_pair_gives_on_random_missions() {
        let world = "[drones.a]\nhome = [0, 0]\n[drones.b]\nhome = [10, 0]\n";
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut findings = 0;
        for _ in 0..300 {
            let mut text = format!("{FETCH}MISSION M:\n");
            let mut names = 0;
            random_body(&mut seed, &mut text, 1, 0, &mut names);
            findings += agree(&compiled(&text, world)).len();
        }
        assert!(findings > 300, "only {findings} findings in all");
    }

    fn next(seed: &mut u64, n: u64) -> u64 {
        *seed ^= *seed << 13;
        *seed ^= *seed >> 7;
        *seed ^= *seed << 17;
        *seed % n
    }

    fn random_body(
        seed: &mut u64,
        out: &mut String,
        indent: usize,
        depth: usize,
        names: &mut usize,
    ) {
        let pad = "    ".repeat(indent);
        for _ in 0..1 + next(seed, 4) {
            let drone = if next(seed, 2) == 0 { "a" } else { "b" };
            let signal = next(seed, 3);
            let choice = if depth >= 3 { next(seed, 3) } else { next(seed, 11) };
            *names += 1;
            match choice {
                0 if next(seed, 4) == 0 => out.push_str(&format!("{pad}{drone} Fetch\n")),
                0 | 1 => out.push_str(&format!("{pad}{drone} Hover WITH 1s\n")),
                2 => out.push_str(&format!("{pad}SIGNAL S{signal}\n")),
                3 => {
                    let kind = if next(seed, 2) == 0 { "SEQUENTIAL" } else { "PARALLEL" };
                    out.push_str(&format!("{pad}{kind} B{names}:\n"));
                    random_body(seed, out, indent + 1, depth + 1, names);
                }
                4 => {
                    let kind = ["ON", "ON EVERY", "SEQUENTIAL ON", "PARALLEL ON EVERY"]
                        [next(seed, 4) as usize];
                    let one = if kind.ends_with("EVERY") && next(seed, 2) == 0 {
                        " ONE AT A TIME"
                    } else {
                        ""
                    };
                    out.push_str(&format!("{pad}{kind} S{signal}{one}:\n"));
                    random_body(seed, out, indent + 1, depth + 1, names);
                }
                9 | 10 => {
                    let by = ["", " BY a", " BY b"][next(seed, 3) as usize];
                    out.push_str(&format!("{pad}ON EXCEPTION CommandFailed{by}:\n"));
                    random_body(seed, out, indent + 1, depth + 1, names);
                }
                5 => {
                    let kind = if next(seed, 2) == 0 { "SEQUENTIAL" } else { "PARALLEL" };
                    out.push_str(&format!(
                        "{pad}{kind} FOR a AND b AS d{names}:\n{pad}    d{names} Hover WITH 1s\n"
                    ));
                    if next(seed, 2) == 0 {
                        random_body(seed, out, indent + 1, depth + 1, names);
                    }
                }
                6 => {
                    out.push_str(&format!("{pad}IF {drone}.battery > 50%:\n"));
                    random_body(seed, out, indent + 1, depth + 1, names);
                    out.push_str(&format!("{pad}ELSE:\n"));
                    random_body(seed, out, indent + 1, depth + 1, names);
                }
                7 => {
                    out.push_str(&format!("{pad}STARTIF {drone}.battery > 50%:\n"));
                    random_body(seed, out, indent + 1, depth + 1, names);
                }
                _ => {
                    out.push_str(&format!("{pad}ON ConnectionRestored BY {drone}:\n"));
                    random_body(seed, out, indent + 1, depth + 1, names);
                }
            }
        }
    }

    /// May-run-in-parallel is symmetric, whichever statement the pair starts from; checked
    /// on every pair of claimants in a large generated mission.
    #[test]
    fn may_run_in_parallel_is_symmetric() {
        let (text, world) = aviary_bench::generate::large_mission(150_000);
        let (_, checked) = harness::check(&text, &world);
        let mission = aviary_lower::compile(
            checked.program.as_ref().expect("program"),
            checked.world.as_ref().expect("world"),
        )
        .expect("a mission");
        let sites = sites::collect(&mission);
        let mut pairs = 0;
        for (i, x) in sites.claims.iter().enumerate() {
            for (j, y) in sites.claims.iter().enumerate().skip(i) {
                let Some(&(drone, _)) = x.claims.iter().find(|c| y.claims.contains(c)) else {
                    continue;
                };
                let ab = overlap(&sites, &mission, drone, i, j).map(|(w, o, _)| (w, o));
                let ba = overlap(&sites, &mission, drone, j, i).map(|(w, o, _)| (w, o));
                assert_eq!(ab, ba, "sites {i} and {j}");
                pairs += 1;
            }
        }
        assert!(pairs > 1000, "only {pairs} pairs share a claim");
    }
}
