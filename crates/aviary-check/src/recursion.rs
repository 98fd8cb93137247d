//! A capability that calls itself with nothing to stop it (E126): `Rec` calling `Rec`,
//! or `A` calling `B` calling `A`, where every call of the cycle runs whenever its
//! capability runs. Such a mission never ends that activity; run, it would nest calls
//! until the engine's depth limit fails it (`aviary_engine::RunOptions::max_call_depth`).
//!
//! A call is *conditional*, and so may end a recursion, when it stands under `IF`/`ELSE`,
//! `STARTIF` or `DOWHILE`, in a handler (`ON ...`, `ON EXCEPTION ...`), in a named
//! `PERFORM` section (it runs only when leashed), or in a capability with
//! `REQUIREMENTS` (which fail it at start when they do not hold). A call in a plain
//! block, a `FOR` or behind a `WAITFOR` is not: `WAITFOR` only delays what follows.
//! Recursion through a conditional call is allowed; the checker cannot tell whether the
//! condition ever ends it, and the engine's limit ends it at run time if it does not.

use std::collections::{HashMap, VecDeque};

use aviary_diagnostics::{Code, Diagnostic, FileId};
use aviary_syntax::ast::{Capability, Expr, RequirementKind, Section, Statement, Stmt};
use aviary_syntax::visit::{walk_stmt, Visitor};

use crate::Program;

/// A call that runs whenever its capability runs: (callee, the statement).
type Edge<'a> = (usize, &'a Statement);

pub(crate) fn check_recursion(program: &Program, diagnostics: &mut Vec<Diagnostic>) {
    let caps: Vec<(FileId, &Capability)> = program.active_capabilities().collect();
    let index: foldhash::HashMap<&str, usize> =
        caps.iter().enumerate().map(|(i, (_, c))| (c.name.name.as_str(), i)).collect();
    let edges: Vec<Vec<Edge>> = caps
        .iter()
        .map(|(_, c)| {
            let mut out = Vec::new();
            unconditional_calls(c, &mut |s| {
                if let Some(&j) = index.get(s.capability.name.as_str()) {
                    out.push((j, s));
                }
            });
            out
        })
        .collect();
    for component in strongly_connected(&edges) {
        let Some(cycle) = shortest_cycle(&edges, &component) else { continue };
        diagnostics.push(report(&caps, &cycle));
    }
}

/// Calls `f` on every statement of `c`'s nameless PERFORM that runs whenever `c` runs.
fn unconditional_calls<'a>(c: &'a Capability, f: &mut dyn FnMut(&'a Statement)) {
    let guarded = c
        .sections
        .iter()
        .any(|s| matches!(s, Section::Requirements { conditions, .. } if !conditions.is_empty()));
    if guarded {
        return;
    }
    for section in &c.sections {
        if let Section::Perform { name: None, body, .. } = section {
            Unconditional(&mut *f).visit_body(body);
        }
    }
}

/// The calls of a body that run whenever it runs: in plain blocks, `FOR`, `ANY` and after
/// a `WAITFOR`, not under anything that decides whether its body runs.
struct Unconditional<'f, 'a>(&'f mut dyn FnMut(&'a Statement));

impl<'a> Visitor<'a> for Unconditional<'_, 'a> {
    fn visit_stmt(&mut self, stmt: &'a Stmt) {
        match stmt {
            Stmt::Statement(s) => (self.0)(s),
            Stmt::Block(_) | Stmt::For(_) | Stmt::Any(_) => walk_stmt(self, stmt),
            Stmt::Requirement(r) => match r.kind {
                RequirementKind::WaitFor => walk_stmt(self, stmt),
                RequirementKind::StartIf | RequirementKind::DoWhile => {}
            },
            Stmt::If(_) | Stmt::Handler(_) | Stmt::ExceptionHandler(_) => {}
            Stmt::Leash(_)
            | Stmt::Api(_)
            | Stmt::Signal(_)
            | Stmt::Throw(_)
            | Stmt::OperatorSignals(_)
            | Stmt::Let(_)
            | Stmt::Allow(_)
            | Stmt::StopBlock(_)
            | Stmt::Error(_) => {}
        }
    }
    fn visit_expr(&mut self, _: &'a Expr) {}
}

/// The components of the call graph that hold a cycle (two or more capabilities, or
/// one that calls itself), each in index order; Tarjan's algorithm without recursion,
/// since a chain of thousands of capabilities is a fine mission.
pub(crate) fn strongly_connected<T>(edges: &[Vec<(usize, T)>]) -> Vec<Vec<usize>> {
    const NONE: usize = usize::MAX;
    let n = edges.len();
    let (mut order, mut low, mut on_stack) = (vec![NONE; n], vec![0; n], vec![false; n]);
    let (mut stack, mut out, mut next) = (Vec::new(), Vec::new(), 0);
    for root in 0..n {
        if order[root] != NONE {
            continue;
        }
        // (node, how many of its edges have been followed)
        let mut work = vec![(root, 0)];
        order[root] = next;
        low[root] = next;
        next += 1;
        stack.push(root);
        on_stack[root] = true;
        while let Some(top) = work.last_mut() {
            let v = top.0;
            if let Some(&(w, _)) = edges[v].get(top.1) {
                top.1 += 1;
                if order[w] == NONE {
                    order[w] = next;
                    low[w] = next;
                    next += 1;
                    stack.push(w);
                    on_stack[w] = true;
                    work.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(order[w]);
                }
                continue;
            }
            work.pop();
            if let Some(&(parent, _)) = work.last() {
                low[parent] = low[parent].min(low[v]);
            }
            if low[v] == order[v] {
                let mut component = Vec::new();
                while let Some(w) = stack.pop() {
                    on_stack[w] = false;
                    component.push(w);
                    if w == v {
                        break;
                    }
                }
                let cyclic = component.len() > 1 || edges[v].iter().any(|&(w, _)| w == v);
                if cyclic {
                    component.sort_unstable();
                    out.push(component);
                }
            }
        }
    }
    out.sort();
    out
}

/// The shortest cycle through the component's first node (capability), as the edges
/// (calls) that make it, in order, each with the node it leaves. Also the checker's
/// cycles of signals (`signal_cycles.rs`).
pub(crate) fn shortest_cycle<T: Copy>(
    edges: &[Vec<(usize, T)>],
    component: &[usize],
) -> Option<Vec<(usize, (usize, T))>> {
    let start = *component.first()?;
    let inside = |v: usize| component.binary_search(&v).is_ok();
    // How each capability was first reached: (caller, the call).
    let mut reached: HashMap<usize, (usize, (usize, T))> = HashMap::new();
    let mut queue = VecDeque::from([start]);
    while let Some(v) = queue.pop_front() {
        for &edge in &edges[v] {
            let w = edge.0;
            if !inside(w) || reached.contains_key(&w) {
                continue;
            }
            reached.insert(w, (v, edge));
            if w == start {
                let mut cycle = vec![(v, edge)];
                let mut at = v;
                while at != start {
                    let &(caller, e) = reached.get(&at)?;
                    cycle.push((caller, e));
                    at = caller;
                }
                cycle.reverse();
                return Some(cycle);
            }
            queue.push_back(w);
        }
    }
    None
}

fn report(caps: &[(FileId, &Capability)], cycle: &[(usize, Edge)]) -> Diagnostic {
    let name = |i: usize| caps[i].1.name.name.as_str();
    let (first, (_, call)) = cycle[0];
    let mut names: Vec<&str> = cycle.iter().map(|&(caller, _)| name(caller)).collect();
    names.push(name(first));
    let message = if cycle.len() == 1 {
        format!("`{}` calls itself with nothing to stop it: {}", name(first), names.join(" → "))
    } else {
        let through: Vec<String> =
            names[1..names.len() - 1].iter().map(|n| format!("`{n}`")).collect();
        format!(
            "`{}` calls itself through {} with nothing to stop it: {}",
            name(first),
            through.join(", "),
            names.join(" → ")
        )
    };
    let mut d = Diagnostic::new(Code::UnboundedRecursion, caps[first].0, call.capability.span, message)
        .label(format!("every run of `{}` makes this call", name(first)))
        .with_help(
            "a recursion needs a way out: put the call under IF, STARTIF or DOWHILE with a condition that ends it, or in a handler; \
             to repeat something, use DOWHILE instead of a call. (A run fails a call nested too deep with CommandFailed.)",
        );
    for &(caller, (callee, stmt)) in &cycle[1..] {
        d = d.also(
            caps[caller].0,
            stmt.capability.span,
            format!("`{}` calls `{}` here, every time", name(caller), name(callee)),
        );
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Edges without statements are enough for the graph algorithms: a statement is only
    /// carried along. One made-up statement stands for all.
    fn graph(n: usize, pairs: &[(usize, usize)], stmt: &Statement) -> Vec<Vec<(usize, Statement)>> {
        let mut out = vec![Vec::new(); n];
        for &(a, b) in pairs {
            out[a].push((b, stmt.clone()));
        }
        out
    }

    fn components(n: usize, pairs: &[(usize, usize)]) -> Vec<Vec<usize>> {
        let stmt = Statement {
            actors: Vec::new(),
            capability: aviary_syntax::ast::Ident { name: String::new(), span: Default::default() },
            tag: None,
            args: Vec::new(),
            span: Default::default(),
        };
        let owned = graph(n, pairs, &stmt);
        let edges: Vec<Vec<Edge>> =
            owned.iter().map(|es| es.iter().map(|(w, s)| (*w, s)).collect()).collect();
        strongly_connected(&edges)
    }

    #[test]
    fn components_with_a_cycle_and_only_those() {
        assert_eq!(components(3, &[(0, 1), (1, 2)]), Vec::<Vec<usize>>::new());
        assert_eq!(components(2, &[(1, 1)]), vec![vec![1]]);
        assert_eq!(
            components(4, &[(0, 1), (1, 2), (2, 1), (2, 3), (3, 3)]),
            vec![vec![1, 2], vec![3]]
        );
        assert_eq!(components(3, &[(2, 0), (0, 1), (1, 2)]), vec![vec![0, 1, 2]]);
    }

    #[test]
    fn a_long_chain_is_no_cycle_and_costs_no_stack() {
        let n = 200_000;
        let pairs: Vec<(usize, usize)> = (0..n - 1).map(|i| (i, i + 1)).collect();
        assert!(components(n, &pairs).is_empty());
        let mut ring = pairs.clone();
        ring.push((n - 1, 0));
        assert_eq!(components(n, &ring).len(), 1);
    }
}
