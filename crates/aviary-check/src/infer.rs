//! Parameter kinds, inferred from use: a parameter takes the kind of its default, or of
//! the API or capability parameter it is passed to, through nested calls, to a fixpoint.
//! The first use that fixes a kind wins; a conflicting use is then reported at its call,
//! with the chain of uses that fixed the kind (`KindOrigin`).

use std::collections::BTreeMap;

use aviary_api::{Descriptor, Kind};
use aviary_diagnostics::Span;
use aviary_syntax::ast::*;

use crate::env::{bind_args, capability_bodies, literal_kind, visit_stmts};
use crate::Program;

/// Where a parameter's kind was fixed: the place in its capability, why, and the callee
/// parameter it came from (whose own origin continues the chain).
#[derive(Clone, Debug, PartialEq)]
pub struct KindOrigin {
    pub span: Span,
    pub why: String,
    pub from: Option<(String, usize)>,
}

pub(crate) type Origins = BTreeMap<String, Vec<Option<KindOrigin>>>;

pub(crate) fn parameter_kinds(program: &Program, api: &Descriptor) -> (BTreeMap<String, Vec<Option<Kind>>>, Origins) {
    let mut kinds: BTreeMap<String, Vec<Option<Kind>>> = BTreeMap::new();
    let mut origins: Origins = BTreeMap::new();
    for name in program.capabilities.keys() {
        if let Some(c) = program.capability(name) {
            let mut k = vec![None; c.params.len()];
            let mut o = vec![None; c.params.len()];
            for section in &c.sections {
                let Section::Defaults { entries, .. } = section else { continue };
                for e in entries {
                    if let Some(i) = c.params.iter().position(|p| p.name == e.name.name) {
                        k[i] = literal_kind(&e.value);
                        o[i] = k[i].map(|kind| KindOrigin { span: e.value.span, why: format!("`{}` is {} because of its default", e.name.name, kind.describe()), from: None });
                    }
                }
            }
            kinds.insert(name.clone(), k);
            origins.insert(name.clone(), o);
        }
    }
    // Each round fixes at least one more kind or stops; bounded by the parameter count.
    let total: usize = kinds.values().map(Vec::len).sum();
    for _ in 0..=total {
        let mut changed = false;
        for name in program.capabilities.keys() {
            let Some(c) = program.capability(name) else { continue };
            let mut learned: Vec<(usize, Kind, KindOrigin)> = Vec::new();
            let param_index = |e: &Expr| match &e.kind {
                ExprKind::Name(id) => c.params.iter().position(|p| p.name == id.name),
                _ => None,
            };
            for body in capability_bodies(c) {
                visit_stmts(body, &mut |stmt| match stmt {
                    Stmt::Api(call) => {
                        let Some(f) = api.function(&call.function.name) else { return };
                        for (j, arg) in call.args.iter().enumerate() {
                            let p = f.params.get(j).or(if f.variadic { f.params.last() } else { None });
                            if let (Some(i), Some(p)) = (param_index(arg), p) {
                                let why = format!("`{}` goes to the middle layer's {}: {}", c.params[i].name, f.signature(), p.kind.describe());
                                learned.push((i, p.kind, KindOrigin { span: arg.span, why, from: None }));
                            }
                        }
                    }
                    Stmt::Statement(s) => {
                        let Some(callee) = program.capability(&s.capability.name) else { return };
                        let Some(callee_kinds) = kinds.get(&s.capability.name) else { return };
                        let binding = bind_args(&callee.params, &s.args);
                        for (k, arg) in binding.bound.iter().enumerate() {
                            if let (Some(arg), Some(Some(kind))) = (arg, callee_kinds.get(k)) {
                                if let Some(i) = param_index(arg) {
                                    let why = format!("`{}` goes to `{}`'s `{}`: {}", c.params[i].name, callee.name.name, callee.params[k].name, kind.describe());
                                    learned.push((i, *kind, KindOrigin { span: arg.span, why, from: Some((callee.name.name.clone(), k)) }));
                                }
                            }
                        }
                    }
                    _ => {}
                });
            }
            if let (Some(k), Some(o)) = (kinds.get_mut(name), origins.get_mut(name)) {
                for (i, kind, origin) in learned {
                    if k[i].is_none() {
                        k[i] = Some(kind);
                        o[i] = Some(origin);
                        changed = true;
                    }
                }
            }
        }
        if !changed {
            break;
        }
    }
    (kinds, origins)
}
