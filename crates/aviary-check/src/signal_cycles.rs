//! Cycles of signals that take no time (W209): `ON EVERY` handlers whose bodies raise, at
//! once, signals that start one another again, back to the first: `ON EVERY X: SIGNAL X`,
//! or `X` → `Y` → `X`. Nothing in such a cycle lets time pass, so once one of its
//! handlers fires it goes round at one instant until the run stops the mission
//! (docs/LANGUAGE.md, section 11).
//!
//! What the checker sees: within one body (the mission's, or a capability's), an
//! `ON EVERY` without `BY` (a `BY` may let the raise pass unheard) whose body begins,
//! before anything that may take time or may not run (a call, a wait, an IF, a FOR), with
//! a `SIGNAL` (in it or in blocks at its start) that another such handler hears: one
//! declared in a block around the `SIGNAL`, up to the body's top. A cycle through a
//! capability call or a condition is not seen here; the run bounds it all the same.

use std::collections::HashMap;

use aviary_api::MAX_HANDLER_REENTRIES;
use aviary_diagnostics::{Code, Diagnostic, FileId};
use aviary_syntax::ast::*;

use crate::recursion::{shortest_cycle, strongly_connected};
use crate::Program;

/// One `ON EVERY` the walk found.
struct Node<'a> {
    file: FileId,
    handler: &'a Handler,
    /// What its body raises at once: the `SIGNAL` and the bodies around it, from the
    /// handler's own body inward.
    raises: Vec<(&'a Raise, Vec<*const Body>)>,
    /// The bodies around the handler, from the top of its tree inward: their handlers hear
    /// what its body raises.
    around: Vec<*const Body>,
}

pub(crate) fn check_signal_cycles(program: &Program, diagnostics: &mut Vec<Diagnostic>) {
    let mut nodes = Vec::new();
    for (file, tree) in &program.files {
        for item in &tree.items {
            let Some(bodies) = program.walked_bodies(*file, item) else { continue };
            for body in bodies {
                collect(*file, body, &mut Vec::new(), &mut nodes);
            }
        }
    }
    if nodes.is_empty() {
        return;
    }
    // The handlers of each body by signal: a raise looks only at its own.
    let mut heard: HashMap<(*const Body, &str), Vec<usize>> = HashMap::new();
    for (i, n) in nodes.iter().enumerate() {
        if let Some(&body) = n.around.last() {
            heard.entry((body, n.handler.signal.name.as_str())).or_default().push(i);
        }
    }
    // Edges: from a handler to every handler that hears what it raises at once, with the
    // raise that leads there.
    let edges: Vec<Vec<(usize, &Raise)>> = nodes
        .iter()
        .map(|n| {
            let mut out = Vec::new();
            for (raise, inside) in &n.raises {
                let name = raise.name.name.as_str();
                for body in n.around.iter().chain(inside) {
                    if let Some(hearers) = heard.get(&(*body, name)) {
                        out.extend(hearers.iter().map(|&h| (h, *raise)));
                    }
                }
            }
            out
        })
        .collect();
    for component in strongly_connected(&edges) {
        let Some(cycle) = shortest_cycle(&edges, &component) else { continue };
        let Some(&(first, (_, raise))) = cycle.first() else { continue };
        let names: Vec<&str> = cycle
            .iter()
            .map(|(h, _)| nodes[*h].handler.signal.name.as_str())
            .chain(std::iter::once(nodes[first].handler.signal.name.as_str()))
            .collect();
        let path = names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(" → ");
        let node = &nodes[first];
        let message = if cycle.len() == 1 {
            let name = nodes[first].handler.signal.name.as_str();
            format!("this handler of `{name}` raises `{name}` at once and so starts itself again, round after round at one instant, until the run stops the mission after {MAX_HANDLER_REENTRIES} rounds")
        } else {
            format!("a cycle of signals that takes no time ({path}): each handler raises the next one's signal at once, so they start one another round after round at one instant, until the run stops the mission after {MAX_HANDLER_REENTRIES} rounds")
        };
        let mut d = Diagnostic::new(Code::SignalCycle, node.file, raise.span, message);
        for (h, (_, r)) in &cycle[1..] {
            let back = nodes[*h].handler.signal.name.as_str();
            d = d.also(
                nodes[*h].file,
                r.span,
                format!("raised at once by the handler of `{back}`"),
            );
        }
        diagnostics.push(d.with_help(
            "let time pass in the cycle (a flight, a Hover, a WAITFOR), raise a signal that no handler of the cycle hears, or handle the first signal with `ON` (once) rather than `ON EVERY`",
        ));
    }
}

/// Every `ON EVERY` without `BY` in `body` and below, with what its body raises at once.
fn collect<'a>(
    file: FileId,
    body: &'a Body,
    around: &mut Vec<*const Body>,
    nodes: &mut Vec<Node<'a>>,
) {
    around.push(body);
    for stmt in &body.items {
        if let Stmt::Handler(h) = stmt {
            if h.every && h.by.is_none() {
                let mut raises = Vec::new();
                let mut inside = vec![&h.body as *const Body];
                at_once(&h.body, false, &mut inside, &mut raises);
                nodes.push(Node { file, handler: h, raises, around: around.clone() });
            }
        }
        stmt.for_each_body(|inner| collect(file, inner, around, nodes));
    }
    around.pop();
}

/// The `SIGNAL`s `body` raises before anything that may take time or may not run, each
/// with the bodies around it; whether all of it runs at once.
fn at_once<'a>(
    body: &'a Body,
    parallel: bool,
    inside: &mut Vec<*const Body>,
    out: &mut Vec<(&'a Raise, Vec<*const Body>)>,
) -> bool {
    let mut all = true;
    for stmt in &body.items {
        let instant = match stmt {
            Stmt::Signal(r) => {
                out.push((r, inside.clone()));
                true
            }
            // Declarations run nothing; a leash takes no time.
            Stmt::Handler(_) | Stmt::ExceptionHandler(_) | Stmt::Leash(_) => true,
            Stmt::OperatorSignals(_) | Stmt::Allow(_) | Stmt::Error(_) => true,
            Stmt::Block(b) => {
                inside.push(&b.body);
                let instant = at_once(&b.body, b.kind == BlockKind::Parallel, inside, out);
                inside.pop();
                instant
            }
            // A THROW ends the body; the rest may take time or may not run.
            Stmt::Statement(_)
            | Stmt::Api(_)
            | Stmt::Requirement(_)
            | Stmt::For(_)
            | Stmt::Throw(_)
            | Stmt::If(_)
            | Stmt::Any(_)
            | Stmt::Let(_)
            | Stmt::StopBlock(_) => false,
        };
        if !instant {
            // In a PARALLEL block every item starts at once; in a sequence the next waits.
            all = false;
            if !parallel {
                break;
            }
        }
    }
    all
}

#[cfg(test)]
mod tests {
    use aviary_diagnostics::{Code, SourceMap};

    fn cycles(mission: &str) -> Vec<String> {
        let checked = crate::check_sources(
            &mut SourceMap::new(),
            ("m.mission", mission.as_bytes()),
            None,
            &crate::NoFiles,
        );
        checked
            .diagnostics
            .iter()
            .filter(|d| d.code == Code::SignalCycle)
            .map(|d| d.message.clone())
            .collect()
    }

    /// `n` handlers in a ring, each raising the next one's signal; with `closed` false
    /// the last raises a signal nobody hears.
    fn ring(n: usize, closed: bool) -> String {
        let mut m = String::from("MISSION Ring:\n    PARALLEL P:\n        SIGNAL S0\n");
        for i in 0..n {
            let next = if i + 1 < n || !closed { i + 1 } else { 0 };
            m.push_str(&format!("        ON EVERY S{i}:\n            SIGNAL S{next}\n"));
        }
        m
    }

    #[test]
    fn a_long_ring_is_one_cycle_and_a_long_chain_none() {
        let found = cycles(&ring(5_000, true));
        assert_eq!(found.len(), 1);
        assert!(found[0].starts_with("a cycle of signals that takes no time (`S0` → `S1` → "));
        assert!(found[0].contains("`S4999` → `S0`)"));
        assert!(cycles(&ring(5_000, false)).is_empty());
    }
}
