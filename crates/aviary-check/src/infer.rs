//! Parameter kinds, inferred from use: a parameter takes the kind of its default, or of
//! the API or capability parameter it is passed to, through nested calls, to a fixpoint.
//! The first use that fixes a kind wins; a conflicting use is then reported at its call.

use std::collections::BTreeMap;

use aviary_api::{Descriptor, Kind};
use aviary_syntax::ast::*;

use crate::env::{bind_args, capability_bodies, literal_kind, visit_stmts};
use crate::Program;

pub(crate) fn parameter_kinds(program: &Program, api: &Descriptor) -> BTreeMap<String, Vec<Option<Kind>>> {
    let mut kinds: BTreeMap<String, Vec<Option<Kind>>> = BTreeMap::new();
    for name in program.capabilities.keys() {
        if let Some(c) = program.capability(name) {
            let mut k = vec![None; c.params.len()];
            for section in &c.sections {
                let Section::Defaults { entries, .. } = section else { continue };
                for e in entries {
                    if let Some(i) = c.params.iter().position(|p| p.name == e.name.name) {
                        k[i] = literal_kind(&e.value);
                    }
                }
            }
            kinds.insert(name.clone(), k);
        }
    }
    // Each round fixes at least one more kind or stops; bounded by the parameter count.
    let total: usize = kinds.values().map(Vec::len).sum();
    for _ in 0..=total {
        let mut changed = false;
        for name in program.capabilities.keys() {
            let Some(c) = program.capability(name) else { continue };
            let mut learned: Vec<(usize, Kind)> = Vec::new();
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
                                learned.push((i, p.kind));
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
                                    learned.push((i, *kind));
                                }
                            }
                        }
                    }
                    _ => {}
                });
            }
            if let Some(k) = kinds.get_mut(name) {
                for (i, kind) in learned {
                    if k[i].is_none() {
                        k[i] = Some(kind);
                        changed = true;
                    }
                }
            }
        }
        if !changed {
            break;
        }
    }
    kinds
}
