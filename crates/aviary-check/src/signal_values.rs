//! The values each signal carries, and their kinds where they can be known: what an
//! operator's signal (the operator API) is checked against before it is raised.
//!
//! A built-in signal's values are those of the middle layer's descriptor. A mission's
//! own signal carries as many values as its widest `SIGNAL X WITH ...` or `ON X WITH ...`;
//! a value's kind comes from what a `SIGNAL` passes (a literal, or a parameter of known
//! kind), else from what a handler does with its binding (passes it to a capability or
//! a middle-layer function whose parameter has a known kind). The first one found wins.
//! A value whose kind nothing fixes stays `None`: it may be anything.

use std::collections::BTreeMap;

use aviary_api::{Descriptor, Kind};
use aviary_diagnostics::FileId;
use aviary_syntax::ast::*;

use aviary_syntax::visit::for_each_stmt;

use crate::env::{bind_args, literal_kind};
use crate::Program;

pub(crate) fn signal_values(program: &Program) -> BTreeMap<String, Vec<Option<Kind>>> {
    let api = Descriptor::standard();
    let mut out: BTreeMap<String, Vec<Option<Kind>>> = BTreeMap::new();
    for s in &api.signals {
        out.insert(s.name().to_string(), s.values().iter().map(|(_, k)| Some(*k)).collect());
    }
    let builtin = |name: &str| api.signal(name).is_some();
    let learn = |out: &mut BTreeMap<String, Vec<Option<Kind>>>,
                 name: &str,
                 i: usize,
                 kind: Option<Kind>| {
        let values = out.entry(name.to_string()).or_default();
        if values.len() <= i {
            values.resize(i + 1, None);
        }
        if values[i].is_none() {
            values[i] = kind;
        }
    };
    for (file, tree) in &program.files {
        for item in &tree.items {
            let Some(bodies) = program.walked_bodies(*file, item) else { continue };
            let capability = match item {
                Item::Capability(c) => Some(c),
                Item::Use(_) | Item::Mission(_) => None,
            };
            // A parameter of the capability being read, with the kind inference gave it.
            let param_kind = |e: &Expr| -> Option<Kind> {
                let (ExprKind::Name(id), Some(c)) = (&e.kind, capability) else {
                    return None;
                };
                let i = c.params.iter().position(|p| p.name == id.name)?;
                *program.param_kinds.get(&c.name.name)?.get(i)?
            };
            for body in bodies {
                for_each_stmt(body, |stmt| match stmt {
                    Stmt::Signal(r) if !builtin(&r.name.name) => {
                        for (i, a) in r.args.iter().enumerate() {
                            learn(
                                &mut out,
                                &r.name.name,
                                i,
                                literal_kind(&a.value).or_else(|| param_kind(&a.value)),
                            );
                        }
                    }
                    Stmt::Handler(h) if !builtin(&h.signal.name) => {
                        for (i, b) in h.bindings.iter().enumerate() {
                            learn(
                                &mut out,
                                &h.signal.name,
                                i,
                                binding_kind(program, *file, &b.name, &h.body),
                            );
                        }
                    }
                    Stmt::Block(_)
                    | Stmt::Statement(_)
                    | Stmt::Leash(_)
                    | Stmt::Api(_)
                    | Stmt::Requirement(_)
                    | Stmt::For(_)
                    | Stmt::Signal(_)
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
                });
            }
        }
    }
    out
}

/// The kind a handler's body (in `file`) gives its binding `name`: the first capability
/// or middle-layer parameter of known kind it is passed to.
fn binding_kind(program: &Program, file: FileId, name: &str, body: &Body) -> Option<Kind> {
    let is_binding = |e: &Expr| matches!(&e.kind, ExprKind::Name(id) if id.name == name);
    let mut found = None;
    for_each_stmt(body, |stmt| {
        if found.is_some() {
            return;
        }
        match stmt {
            Stmt::Statement(s) => {
                let (Some(callee), Some(kinds)) = (
                    program.capability(&s.capability.name),
                    program.param_kinds.get(&s.capability.name),
                ) else {
                    return;
                };
                let binding = bind_args(&callee.params, &s.args);
                found = binding
                    .bound
                    .iter()
                    .zip(kinds)
                    .find_map(|(arg, kind)| arg.filter(|a| is_binding(a)).and(*kind));
            }
            Stmt::Api(call) => {
                let Some(f) = program.api_function(file, call) else {
                    return;
                };
                let last = call.args.last().and_then(literal_kind);
                found = call.args.iter().enumerate().find_map(|(j, arg)| {
                    let p = f.param_at(j, call.args.len(), last)?;
                    is_binding(arg).then_some(p.kind)
                });
            }
            Stmt::Block(_)
            | Stmt::Leash(_)
            | Stmt::Requirement(_)
            | Stmt::For(_)
            | Stmt::Signal(_)
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
    });
    found
}

#[cfg(test)]
mod tests {
    use aviary_diagnostics::SourceMap;

    use super::*;
    use crate::NoFiles;

    fn values(mission: &str) -> BTreeMap<String, Vec<Option<Kind>>> {
        let mut sources = SourceMap::default();
        let root = sources.add("m.mission", mission);
        let (program, _) = crate::check(&mut sources, root, None, &NoFiles);
        program.signal_values
    }

    #[test]
    fn kinds_come_from_raising_from_handlers_and_from_the_descriptor() {
        let v = values(
            "MISSION M:\n    PARALLEL:\n        SIGNAL Ready WITH 20m, Body\n        ON Go WITH where, how_long:\n            a FlyTo WITH where\n            a Hover WITH how_long\n        ON Stop WITH why:\n            SIGNAL Ready WITH 5m, why\n",
        );
        assert_eq!(v["Ready"], vec![Some(Kind::Length), None]);
        assert_eq!(v["Go"], vec![Some(Kind::Position), Some(Kind::Duration)]);
        assert_eq!(v["Stop"], vec![None], "a binding nothing fixes may be anything");
        assert_eq!(v["Detected"], vec![Some(Kind::Symbol), Some(Kind::Position)]);
        assert_eq!(v["BatteryLow"], vec![]);
    }
}
