//! Signals in time: a `WAITFOR RECEIVED(X)` whose X comes only later in the same
//! sequence (docs/LANGUAGE.md, section 9: it can never end), and a handler's `BY` filter on a signal
//! that no actor ever raises (§7: a handler whose `BY` can never match).

use std::collections::{HashMap, HashSet};

use aviary_api::Descriptor;
use aviary_diagnostics::{Code, Diagnostic, FileId};
use aviary_syntax::ast::*;

use aviary_syntax::visit::for_each_stmt;

use crate::env::{capability_bodies, operator_signals};
use crate::Program;

/// The names of the signals `SIGNAL`ed anywhere in the capabilities that run.
fn raised_in_capabilities(program: &Program) -> HashSet<&str> {
    let mut out = HashSet::new();
    for (_, c) in program.active_capabilities() {
        for body in capability_bodies(c) {
            for_each_stmt(body, |stmt| {
                if let Stmt::Signal(r) = stmt {
                    out.insert(r.name.name.as_str());
                }
            });
        }
    }
    out
}

/// One step of the way from the mission body down to an item: the body it is in, its
/// index there, and how that body runs.
#[derive(Clone, Copy)]
struct Step {
    body: *const Body,
    index: usize,
    /// The body of a PARALLEL block: its items run at once.
    parallel: bool,
    /// A body that may run as several instances at once (PARALLEL FOR, ON EVERY, ON EXCEPTION).
    copies: bool,
    /// The item is a handler, which listens for the whole time its body runs.
    handler: bool,
}

#[derive(Default)]
struct Walk<'a> {
    waits: Vec<(Vec<Step>, &'a Ident)>,
    signals: Vec<(Vec<Step>, &'a Ident)>,
    /// Signals raised inside a FOR body: they have the instance's actor.
    in_for: Vec<&'a str>,
    /// Handlers with a `BY` filter: the signal and the filter.
    filtered: Vec<(&'a Ident, &'a Ident)>,
}

fn walk<'a>(
    body: &'a Body,
    parallel: bool,
    copies: bool,
    in_for: bool,
    path: &mut Vec<Step>,
    out: &mut Walk<'a>,
) {
    for (index, stmt) in body.items.iter().enumerate() {
        let handler = matches!(stmt, Stmt::Handler(_) | Stmt::ExceptionHandler(_));
        path.push(Step { body, index, parallel, copies, handler });
        match stmt {
            Stmt::Signal(r) => {
                out.signals.push((path.clone(), &r.name));
                if in_for {
                    out.in_for.push(&r.name.name);
                }
            }
            Stmt::Requirement(r) if r.kind == RequirementKind::WaitFor => {
                for id in required_signals(&r.condition) {
                    out.waits.push((path.clone(), id));
                }
            }
            Stmt::Handler(Handler { signal, by: Some(by), .. }) => out.filtered.push((signal, by)),
            Stmt::Block(_)
            | Stmt::Statement(_)
            | Stmt::Leash(_)
            | Stmt::Api(_)
            | Stmt::Requirement(_)
            | Stmt::For(_)
            | Stmt::Throw(_)
            | Stmt::Handler(_)
            | Stmt::ExceptionHandler(_)
            | Stmt::If(_)
            | Stmt::OperatorSignals(_)
            | Stmt::Any(_)
            | Stmt::Let(_)
            | Stmt::Allow(_)
            | Stmt::StopBlock(_)
            | Stmt::Error(_) => {}
        }
        let (inner_parallel, inner_copies) = match stmt {
            Stmt::Block(b) => (b.kind == BlockKind::Parallel, false),
            Stmt::For(f) => (false, f.kind == BlockKind::Parallel),
            // `ANY 2 d IN ...` runs its body once per drone taken, at once.
            Stmt::Any(a) => (false, a.count.is_some()),
            Stmt::Handler(h) => (false, h.every),
            Stmt::ExceptionHandler(_) => (false, true),
            Stmt::Statement(_)
            | Stmt::Leash(_)
            | Stmt::Api(_)
            | Stmt::Requirement(_)
            | Stmt::Signal(_)
            | Stmt::Throw(_)
            | Stmt::If(_)
            | Stmt::OperatorSignals(_)
            | Stmt::Let(_)
            | Stmt::Allow(_)
            | Stmt::StopBlock(_)
            | Stmt::Error(_) => (false, false),
        };
        let inner_for = in_for
            || (matches!(stmt, Stmt::For(_)) || matches!(stmt, Stmt::Any(a) if a.count.is_some()));
        stmt.for_each_body(|inner| walk(inner, inner_parallel, inner_copies, inner_for, path, out));
        path.pop();
    }
}

/// The signals a condition cannot hold without: `RECEIVED(X)`, alone or joined by AND.
fn required_signals(e: &Expr) -> Vec<&Ident> {
    match &e.kind {
        ExprKind::Received(id) => vec![id],
        ExprKind::Paren(inner) => required_signals(inner),
        ExprKind::Binary(l, BinaryOp::And, r) => {
            let mut out = required_signals(l);
            out.extend(required_signals(r));
            out
        }
        ExprKind::Number { .. }
        | ExprKind::String(_)
        | ExprKind::Bool(_)
        | ExprKind::Coordinates(_)
        | ExprKind::Geo(_)
        | ExprKind::Name(_)
        | ExprKind::Path(..)
        | ExprKind::Distance(..)
        | ExprKind::Arith(..)
        | ExprKind::Offset(..)
        | ExprKind::Midpoint(..)
        | ExprKind::Elapsed
        | ExprKind::Not(_)
        | ExprKind::Binary(..)
        | ExprKind::Error => Vec::new(),
    }
}

/// Whether the item at `signal` can only run after the WAITFOR at `wait` has ended:
/// both are in one sequence (no PARALLEL block, no body that runs as several instances
/// at once between them), the signal's item comes later, and neither is a handler there
/// (a handler listens from the start of its body).
fn later_in_chain(wait: &[Step], signal: &[Step]) -> bool {
    let same = |a: &Step, b: &Step| std::ptr::eq(a.body, b.body) && a.index == b.index;
    let k = wait.iter().zip(signal).take_while(|(a, b)| same(a, b)).count();
    if wait[..k].iter().any(|s| s.copies) {
        return false;
    }
    if k == wait.len() {
        // The signal is inside the WAITFOR's own body, which runs after the wait.
        return true;
    }
    let (Some(w), Some(s)) = (wait.get(k), signal.get(k)) else { return false };
    std::ptr::eq(w.body, s.body)
        && !w.parallel
        && !w.copies
        && w.index < s.index
        && !w.handler
        && !s.handler
}

pub(crate) fn check_chains(program: &Program, diagnostics: &mut Vec<Diagnostic>) {
    let api = Descriptor::standard();
    let (Some(mission), Some(at)) = (program.mission(), program.mission) else { return };
    let file: FileId = at.file;
    let in_capabilities = raised_in_capabilities(program);
    // The operator may raise these at any time, so a wait for one can always end.
    let operator: HashSet<&str> =
        operator_signals(program).into_iter().map(|i| i.name.as_str()).collect();
    let mut found = Walk::default();
    walk(&mission.body, false, false, false, &mut Vec::new(), &mut found);

    let mut raisers: HashMap<&str, Vec<&(Vec<Step>, &Ident)>> = HashMap::new();
    for s in &found.signals {
        raisers.entry(s.1.name.as_str()).or_default().push(s);
    }
    for (wait, id) in &found.waits {
        let name = id.name.as_str();
        if api.signal(name).is_some() || in_capabilities.contains(name) || operator.contains(name) {
            continue;
        }
        let Some(raisers) = raisers.get(name) else { continue };
        if !raisers.iter().all(|(path, _)| later_in_chain(wait, path)) {
            continue;
        }
        diagnostics.push(
            Diagnostic::new(Code::SignalNeverRaised, file, id.span, format!("`{name}` is raised only later in this sequence, so this WAITFOR never ends"))
                .also(file, raisers[0].1.span, "raised here, after the WAITFOR")
                .with_help(format!(
                    "raise `{name}` before the WAITFOR, or wait in a block that runs beside the one that raises it (PARALLEL)"
                )),
        );
    }

    // A signal raised only at mission level, outside every FOR, has no signalling actor.
    let in_for: HashSet<&str> = found.in_for.iter().copied().collect();
    for (signal, by) in &found.filtered {
        let name = signal.name.as_str();
        if api.signal(name).is_some()
            || !(raisers.contains_key(name) || operator.contains(name))
            || in_capabilities.contains(name)
            || in_for.contains(name)
        {
            continue;
        }
        if !raisers.contains_key(name) {
            // Only the operator raises it, and the operator is no drone.
            diagnostics.push(
                Diagnostic::new(
                    Code::HandlerNeverFires,
                    file,
                    by.span,
                    format!("`{name}` is raised only by the operator, who is no drone, so `BY {}` never matches", by.name),
                )
                .with_help(format!("remove `BY {}`: every `{name}` the operator raises is heard without it", by.name)),
            );
            continue;
        }
        diagnostics.push(
            Diagnostic::new(
                Code::HandlerNeverFires,
                file,
                by.span,
                format!("`{name}` is only raised at mission level, where no drone raises it, so `BY {}` never matches", by.name),
            )
            .with_help(format!("remove `BY {}`, or raise `{name}` inside a capability or a FOR block that `{}` runs", by.name, by.name)),
        );
    }
}
