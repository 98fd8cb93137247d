//! Signals and exceptions across the whole program: handlers that can never fire,
//! waits that can never end, signals nobody listens to, and exception handlers that take
//! their own exception again at once.

use std::collections::HashSet;

use aviary_api::Descriptor;
use aviary_diagnostics::{Code, Diagnostic, FileId};
use aviary_syntax::ast::*;

use aviary_syntax::visit::{for_each_expr, for_each_stmt, stmt_exprs};

use crate::env::operator_signals;
use crate::Program;
use aviary_diagnostics::suggest::did_you_mean;

#[derive(Default)]
struct Uses<'a> {
    raised: Vec<(FileId, &'a Ident)>,
    thrown: Vec<&'a str>,
    handlers: Vec<(FileId, &'a Ident)>,
    exception_handlers: Vec<(FileId, &'a Ident)>,
    received: Vec<(FileId, &'a Ident)>,
}

pub(crate) fn check_signals(program: &Program, diagnostics: &mut Vec<Diagnostic>) {
    let api = Descriptor::standard();
    let uses = Uses::of(program);
    // A built-in one is refused where it is declared (E130), and said no more.
    let declared: Vec<&Ident> =
        operator_signals(program).into_iter().filter(|i| api.signal(&i.name).is_none()).collect();
    // The lists keep their order for the "did you mean" help; the sets answer membership
    // in constant time, so a large mission is not checked in quadratic time.
    let raised: Vec<&str> = uses
        .raised
        .iter()
        .map(|(_, i)| i.name.as_str())
        .chain(api.signals.iter().map(|s| s.name()))
        .chain(declared.iter().map(|i| i.name.as_str()))
        .collect();
    let raised_set: HashSet<&str> = raised.iter().copied().collect();
    never_raised(&uses, &raised, &raised_set, diagnostics);
    unknown_exceptions(&uses, &raised_set, diagnostics);
    never_handled(&uses, &declared, program, diagnostics);
    rethrows(program, diagnostics);
}

impl<'a> Uses<'a> {
    /// Every use in the mission and the active capabilities, in file order.
    fn of(program: &'a Program) -> Uses<'a> {
        let mut uses = Uses::default();
        for (file, tree) in &program.files {
            for item in &tree.items {
                let Some(mut bodies) = program.walked_bodies(*file, item) else { continue };
                if let Item::Capability(c) = item {
                    for s in &c.sections {
                        if let Section::Exceptions { handlers, .. } = s {
                            uses.exception_handlers
                                .extend(handlers.iter().map(|h| (*file, &h.exception)));
                        }
                        if let Section::Requirements { conditions, .. } = s {
                            for c in conditions {
                                collect_received(*file, c, &mut uses);
                            }
                        }
                    }
                }
                for body in bodies.drain(..) {
                    for_each_stmt(body, |stmt| {
                        match stmt {
                            Stmt::Signal(r) => uses.raised.push((*file, &r.name)),
                            Stmt::Throw(r) => uses.thrown.push(&r.name.name),
                            Stmt::Handler(h) => uses.handlers.push((*file, &h.signal)),
                            Stmt::ExceptionHandler(h) => {
                                uses.exception_handlers.push((*file, &h.exception))
                            }
                            Stmt::Block(_)
                            | Stmt::Statement(_)
                            | Stmt::Leash(_)
                            | Stmt::Api(_)
                            | Stmt::Requirement(_)
                            | Stmt::For(_)
                            | Stmt::If(_)
                            | Stmt::OperatorSignals(_)
                            | Stmt::Any(_)
                            | Stmt::Let(_)
                            | Stmt::Allow(_)
                            | Stmt::StopBlock(_)
                            | Stmt::Error(_) => {}
                        }
                        for e in stmt_exprs(stmt) {
                            collect_received(*file, e, &mut uses);
                        }
                    });
                }
            }
        }
        uses
    }
}

/// Handlers and `RECEIVED` of signals nothing raises.
fn never_raised(
    uses: &Uses,
    raised: &[&str],
    raised_set: &HashSet<&str>,
    diagnostics: &mut Vec<Diagnostic>,
) {
    for (file, h) in &uses.handlers {
        if !raised_set.contains(h.name.as_str()) {
            let help = did_you_mean(&h.name, raised.iter().copied()).unwrap_or_else(|| {
                format!("raise it somewhere with `SIGNAL {}`; if the operator raises it, declare it in the MISSION body: `OPERATOR SIGNAL {}`", h.name, h.name)
            });
            diagnostics.push(
                Diagnostic::new(
                    Code::HandlerNeverFires,
                    *file,
                    h.span,
                    format!("nothing raises `{}`, so this handler never runs", h.name),
                )
                .with_help(help),
            );
        }
    }
    for (file, r) in &uses.received {
        if !raised_set.contains(r.name.as_str()) {
            let help = did_you_mean(&r.name, raised.iter().copied()).unwrap_or_else(|| {
                format!("raise it somewhere with `SIGNAL {}`; if the operator raises it, declare it in the MISSION body: `OPERATOR SIGNAL {}`", r.name, r.name)
            });
            diagnostics.push(
                Diagnostic::new(
                    Code::SignalNeverRaised,
                    *file,
                    r.span,
                    format!("nothing raises `{}`, so RECEIVED({}) is never true", r.name, r.name),
                )
                .with_help(help),
            );
        }
    }
}

/// Exception handlers of what is neither a built-in exception nor thrown (or is a signal).
fn unknown_exceptions(uses: &Uses, raised_set: &HashSet<&str>, diagnostics: &mut Vec<Diagnostic>) {
    let api = Descriptor::standard();
    let exceptions: Vec<&str> =
        api.exceptions.iter().map(|e| e.name()).chain(uses.thrown.iter().copied()).collect();
    let exception_set: HashSet<&str> = exceptions.iter().copied().collect();
    for (file, e) in &uses.exception_handlers {
        if !exception_set.contains(e.name.as_str()) && raised_set.contains(e.name.as_str()) {
            // `ON EXCEPTION BatteryLow`: a signal, not an exception.
            diagnostics.push(
                Diagnostic::new(
                    Code::UnknownException,
                    *file,
                    e.span,
                    format!(
                        "`{}` is a signal, not an exception, so this handler never runs",
                        e.name
                    ),
                )
                .with_help(format!("handle a signal with `ON {}:`", e.name)),
            );
        } else if !exception_set.contains(e.name.as_str()) {
            let help = did_you_mean(&e.name, exceptions.iter().copied()).unwrap_or_else(|| {
                format!(
                    "the built-in exceptions are {}; or throw it with `THROW EXCEPTION {}`",
                    api.exceptions.iter().map(|e| e.name()).collect::<Vec<_>>().join(", "),
                    e.name
                )
            });
            diagnostics.push(
                Diagnostic::new(
                    Code::UnknownException,
                    *file,
                    e.span,
                    format!("`{}` is neither a built-in exception nor thrown anywhere", e.name),
                )
                .with_help(help),
            );
        }
    }
}

/// Signals raised (or declared for the operator) that no handler or `RECEIVED` hears.
fn never_handled(
    uses: &Uses,
    declared: &[&Ident],
    program: &Program,
    diagnostics: &mut Vec<Diagnostic>,
) {
    let heard: HashSet<&str> =
        uses.handlers.iter().chain(&uses.received).map(|(_, h)| h.name.as_str()).collect();
    let file = program.mission.map(|r| r.file).unwrap_or_default();
    let mut said = HashSet::new();
    for s in declared {
        if !heard.contains(s.name.as_str()) && said.insert(s.name.as_str()) {
            diagnostics.push(
                Diagnostic::new(
                    Code::SignalNeverHandled,
                    file,
                    s.span,
                    format!("nothing in the mission hears `{}`; when the operator raises it, it is only recorded in the trace", s.name),
                )
                .with_help(format!("handle it with `ON {}:` where it should be heard, or leave it out of OPERATOR SIGNAL", s.name)),
            );
        }
    }
    for (file, s) in &uses.raised {
        if !heard.contains(s.name.as_str()) {
            diagnostics.push(
                Diagnostic::new(
                    Code::SignalNeverHandled,
                    *file,
                    s.span,
                    format!("nothing handles `{}`; it is only recorded in the trace", s.name),
                )
                .with_help(format!("handle it with `ON {}:` where it should be heard", s.name)),
            );
        }
    }
}

fn collect_received<'a>(file: FileId, e: &'a Expr, uses: &mut Uses<'a>) {
    for_each_expr(e, |x| {
        if let ExprKind::Received(id) = &x.kind {
            uses.received.push((file, id));
        }
    });
}

/// An `ON EXCEPTION X` (with no `BY`) whose body throws `X` before anything else that it
/// runs: the throw is taken by that handler again at once, round after round, until the
/// run passes the handler over (docs/LANGUAGE.md, section 12). Someone who wrote it most
/// likely meant to hand the exception to the blocks around, which a throw does not do.
fn rethrows(program: &Program, diagnostics: &mut Vec<Diagnostic>) {
    for (file, tree) in &program.files {
        for item in &tree.items {
            let Some(bodies) = program.walked_bodies(*file, item) else { continue };
            let mut check = |h: &ExceptionHandler| {
                if let Some(throw) = rethrow(h) {
                    let name = &h.exception.name;
                    diagnostics.push(
                        Diagnostic::new(
                            Code::HandlerRethrows,
                            *file,
                            throw.span,
                            format!("this handler of `{name}` throws `{name}` at once and takes it again itself, round after round at one instant, until the run passes it over"),
                        )
                        .with_help("a THROW in a handler is taken by the nearest handler, this one; to hand the exception to the blocks around, throw another exception and handle that there"),
                    );
                }
            };
            if let Item::Capability(c) = item {
                for s in &c.sections {
                    if let Section::Exceptions { handlers, .. } = s {
                        handlers.iter().for_each(&mut check);
                    }
                }
            }
            for body in bodies {
                for_each_stmt(body, |stmt| {
                    if let Stmt::ExceptionHandler(h) = stmt {
                        check(h);
                    }
                });
            }
        }
    }
}

/// The `THROW` of its own exception that `h` starts with, if it does: only signals
/// (which take no time) before it, no `BY` (a thrower it filters out would go outward),
/// and no handler of that exception in its own body (which would take it first).
fn rethrow(h: &ExceptionHandler) -> Option<&Raise> {
    let name = &h.exception.name;
    if h.by.is_some() {
        return None;
    }
    let handled_inside = h
        .body
        .items
        .iter()
        .any(|s| matches!(s, Stmt::ExceptionHandler(inner) if inner.exception.name == *name));
    if handled_inside {
        return None;
    }
    let first = h
        .body
        .items
        .iter()
        .find(|s| !matches!(s, Stmt::Signal(_) | Stmt::Handler(_) | Stmt::ExceptionHandler(_)));
    match first {
        Some(Stmt::Throw(r)) if r.name.name == *name => Some(r),
        _ => None,
    }
}
