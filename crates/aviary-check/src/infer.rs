//! Parameter kinds, inferred from use: a parameter takes the kind of its default, or of
//! the API or capability parameter it is passed to, through nested calls, to a fixpoint.
//! The first use that fixes a kind wins; a conflicting use is then reported at its call,
//! with the chain of uses that fixed the kind (`KindOrigin`). One exception: a parameter
//! used both as a position and as an area is an area, whichever use comes first, since an
//! area stands for its centroid where a position is expected (docs/LANGUAGE.md, section
//! 13). `merge` says which kind two uses give.

use std::collections::BTreeSet;

use aviary_api::Kind;
use aviary_diagnostics::{FileId, Span};
use aviary_syntax::ast::*;

use aviary_syntax::visit::for_each_stmt;

use crate::env::{bind_args, capability_bodies, literal_kind};
use crate::{ByName, Program};

/// Where a parameter's kind was fixed: the place in its capability, why, and the callee
/// parameter it came from (whose own origin continues the chain).
#[derive(Clone, Debug, PartialEq)]
pub struct KindOrigin {
    pub span: Span,
    pub why: String,
    pub from: Option<(String, usize)>,
}

pub(crate) type Origins = ByName<Vec<Option<KindOrigin>>>;

pub(crate) fn parameter_kinds(program: &Program) -> (ByName<Vec<Option<Kind>>>, Origins) {
    // The capabilities with parameters, in name order, by index; names are looked up by
    // hash. One without parameters has nothing to learn, and so never tells a caller
    // anything, nor gets an entry (most capabilities of a long chain are such).
    let mut learners: Vec<(&str, FileId, &Capability)> =
        program.capabilities().filter(|(_, _, c)| !c.params.is_empty()).collect();
    learners.sort_unstable_by_key(|(name, _, _)| *name);
    let names: Vec<&str> = learners.iter().map(|(name, _, _)| *name).collect();
    let caps: Vec<Option<&Capability>> = learners.iter().map(|(_, _, c)| Some(*c)).collect();
    let index: foldhash::HashMap<&str, usize> =
        names.iter().enumerate().map(|(i, n)| (*n, i)).collect();
    let mut kinds: Vec<Option<Vec<Option<Kind>>>> = vec![None; names.len()];
    let mut origins: Vec<Option<Vec<Option<KindOrigin>>>> = vec![None; names.len()];
    for (ci, c) in caps.iter().enumerate() {
        let Some(c) = c else { continue };
        let (k, o) = from_defaults(c);
        kinds[ci] = Some(k);
        origins[ci] = Some(o);
    }
    // Each round fixes at least one more kind or stops; bounded by the parameter count.
    // A round visits the capabilities in name order, each seeing what the ones before it
    // learned. Only those that can learn anything are visited: all in the first round,
    // then a capability when a callee of it learned a kind since its last visit (one
    // later in the order is visited in the same round, as the full scan would; one
    // earlier, in the next). A visit with nothing new learns what it learned before, so
    // the result is the full scan's; a chain of N capabilities costs N visits, not N².
    let callers = callers(&caps, &index);
    let mut round: BTreeSet<usize> = (0..names.len()).collect();
    // Each parameter's kind is fixed once and may be widened once (position to area).
    let total: usize = 2 * kinds.iter().flatten().map(Vec::len).sum::<usize>();
    for _ in 0..=total {
        let mut changed = false;
        let mut next_round: BTreeSet<usize> = BTreeSet::new();
        while let Some(ci) = round.pop_first() {
            let Some(c) = caps[ci] else { continue };
            let file = learners[ci].1;
            let learned = Uses { program, caps: &caps, index: &index, kinds: &kinds }.of(file, c);
            let mut grew = false;
            if let (Some(k), Some(o)) = (kinds[ci].as_mut(), origins[ci].as_mut()) {
                for (i, kind, origin) in learned {
                    let merged = merge(k[i], kind);
                    if merged != k[i] {
                        k[i] = merged;
                        o[i] = Some(origin);
                        grew = true;
                    }
                }
            }
            if grew {
                changed = true;
                for &caller in &callers[ci] {
                    if caller > ci {
                        round.insert(caller);
                    } else {
                        next_round.insert(caller);
                    }
                }
            }
        }
        if !changed {
            break;
        }
        round = next_round;
    }
    (by_name(&names, kinds), by_name(&names, origins))
}

/// The kind of a parameter known as `known` that a use as `used` gives: the first kind
/// fixed stays, but a position used as an area too becomes an area (every area is a
/// position as well, its centroid; not every position an area).
fn merge(known: Option<Kind>, used: Kind) -> Option<Kind> {
    match known {
        None => Some(used),
        Some(Kind::Position) if used == Kind::Area => Some(Kind::Area),
        // A path (what `FollowPath` flies) used as a single position too is a position
        // (or an area): a line could not stand for one point.
        Some(Kind::Path) if matches!(used, Kind::Position | Kind::Area) => Some(used),
        known => known,
    }
}

/// The kinds a capability's parameters take from their defaults, and where.
fn from_defaults(c: &Capability) -> (Vec<Option<Kind>>, Vec<Option<KindOrigin>>) {
    let mut k = vec![None; c.params.len()];
    let mut o = vec![None; c.params.len()];
    for section in &c.sections {
        let Section::Defaults { entries, .. } = section else { continue };
        for e in entries {
            if let Some(i) = c.params.iter().position(|p| p.name == e.name.name) {
                k[i] = literal_kind(&e.value);
                o[i] = k[i].map(|kind| KindOrigin {
                    span: e.value.span,
                    why: format!("`{}` is {} because of its default", e.name.name, kind.describe()),
                    from: None,
                });
            }
        }
    }
    (k, o)
}

/// A kind a parameter (by index) learns from a use, and where.
type Learned = (usize, Kind, KindOrigin);

/// What a visit of a capability learns from where its parameters go: to the middle
/// layer's parameters, and to capabilities' parameters of the kinds known so far.
struct Uses<'a> {
    /// Where the middle-layer calls' functions were resolved.
    program: &'a Program,
    caps: &'a [Option<&'a Capability>],
    index: &'a foldhash::HashMap<&'a str, usize>,
    kinds: &'a [Option<Vec<Option<Kind>>>],
}

impl Uses<'_> {
    /// `c`, defined in `file`.
    fn of(&self, file: FileId, c: &Capability) -> Vec<Learned> {
        let mut learned = Vec::new();
        for body in capability_bodies(c) {
            for_each_stmt(body, |stmt| match stmt {
                Stmt::Api(call) => self.api_call(file, c, call, &mut learned),
                Stmt::Statement(s) => self.capability_call(c, s, &mut learned),
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
            });
        }
        learned
    }

    /// A parameter passed to a middle-layer function takes the kind of its parameter.
    fn api_call(&self, file: FileId, c: &Capability, call: &ApiCall, learned: &mut Vec<Learned>) {
        let Some(f) = self.program.api_function(file, call) else { return };
        let last = call.args.last().and_then(literal_kind);
        for (j, arg) in call.args.iter().enumerate() {
            let p = f.param_at(j, call.args.len(), last);
            if let (Some(i), Some(p)) = (param_index(c, arg), p) {
                let why = format!(
                    "`{}` goes to the middle layer's {}: {}",
                    c.params[i].name,
                    f.signature(),
                    p.kind.describe()
                );
                learned.push((i, p.kind, KindOrigin { span: arg.span, why, from: None }));
            }
        }
    }

    /// A parameter passed to a capability takes the kind of its parameter, once known.
    fn capability_call(&self, c: &Capability, s: &Statement, learned: &mut Vec<Learned>) {
        let Some(&callee_index) = self.index.get(s.capability.name.as_str()) else {
            return;
        };
        let (Some(callee), Some(callee_kinds)) =
            (self.caps[callee_index], &self.kinds[callee_index])
        else {
            return;
        };
        // Only a parameter passed on can learn anything here.
        if !s.args.iter().any(|a| param_index(c, &a.value).is_some()) {
            return;
        }
        let binding = bind_args(&callee.params, &s.args);
        for (k, arg) in binding.bound.iter().enumerate() {
            if let (Some(arg), Some(Some(kind))) = (arg, callee_kinds.get(k)) {
                if let Some(i) = param_index(c, arg) {
                    let why = format!(
                        "`{}` goes to `{}`'s `{}`: {}",
                        c.params[i].name,
                        callee.name.name,
                        callee.params[k].name,
                        kind.describe()
                    );
                    let from = Some((callee.name.name.clone(), k));
                    learned.push((i, *kind, KindOrigin { span: arg.span, why, from }));
                }
            }
        }
    }
}

/// Which of the capability's parameters an argument is, when it is one by name.
fn param_index(c: &Capability, e: &Expr) -> Option<usize> {
    match &e.kind {
        ExprKind::Name(id) => c.params.iter().position(|p| p.name == id.name),
        ExprKind::Number { .. }
        | ExprKind::String(_)
        | ExprKind::Bool(_)
        | ExprKind::Coordinates(_)
        | ExprKind::Geo(_)
        | ExprKind::Path(..)
        | ExprKind::Distance(..)
        | ExprKind::Arith(..)
        | ExprKind::Offset(..)
        | ExprKind::Midpoint(..)
        | ExprKind::Received(_)
        | ExprKind::Elapsed
        | ExprKind::Not(_)
        | ExprKind::Binary(..)
        | ExprKind::Paren(_)
        | ExprKind::Error => None,
    }
}

/// Values by index as a map by name.
fn by_name<T>(names: &[&str], values: Vec<Option<T>>) -> ByName<T> {
    names.iter().zip(values).filter_map(|(n, v)| Some((n.to_string(), v?))).collect()
}

/// For each capability (by index), the capabilities whose bodies call it.
fn callers(
    caps: &[Option<&Capability>],
    index: &foldhash::HashMap<&str, usize>,
) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new(); caps.len()];
    for (ci, c) in caps.iter().enumerate() {
        let Some(c) = c else { continue };
        for body in capability_bodies(c) {
            for_each_stmt(body, |stmt| {
                if let Stmt::Statement(s) = stmt {
                    if let Some(&callee) = index.get(s.capability.name.as_str()) {
                        out[callee].push(ci);
                    }
                }
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use aviary_api::Kind;
    use aviary_diagnostics::SourceMap;

    use crate::NoFiles;

    /// A parameter used as a position and as an area is an area, in either order, and so
    /// is one that passes it on to such a parameter: nothing is reported.
    #[test]
    fn a_position_also_used_as_an_area_is_an_area() {
        let text = "MISSION M:\n    scout Outer WITH Field\n\n\
            CAPABILITY Outer BY d WITH z:\n    PERFORM:\n        d FlyTo WITH z\n        d Both WITH z\n\n\
            CAPABILITY Both BY d WITH z:\n    PERFORM:\n        d.FlyToPosition(z)\n        d.Sweep(z, 20m)\n\n\
            CAPABILITY Swapped BY d WITH z:\n    PERFORM:\n        d.Sweep(z, 20m)\n        d.FlyToPosition(z)\n";
        let world = "[areas]\nField = [[0, 0], [100, 0], [100, 100], [0, 100]]\n\
            [drones.scout]\nhome = [0, 0]\n";
        let mut sources = SourceMap::new();
        let checked = crate::check_sources(
            &mut sources,
            ("m.mission", text.as_bytes()),
            Some(("w.toml", world.as_bytes())),
            &NoFiles,
        );
        let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.is_error()).collect();
        assert!(errors.is_empty(), "{errors:?}");
        let program = checked.program.expect("program");
        for cap in ["Outer", "Both", "Swapped"] {
            assert_eq!(program.param_kinds[cap], vec![Some(Kind::Area)], "{cap}");
        }
    }

    /// A parameter passed down a chain of capabilities to a middle-layer call gets its
    /// kind at every link, and a wrong argument at the top is reported with the chain.
    /// (Names are chosen so that each link is learned one round after the next: in name
    /// order, `C00000` calls `C00001`, which learns its kind only from `C00002`, ...)
    #[test]
    fn a_kind_travels_up_a_long_chain() {
        let n = 3000;
        let mut text = String::from("MISSION M:\n    scout C00000 WITH 5m\n");
        for i in 0..n {
            let body =
                if i + 1 < n { format!("d C{:05} WITH x", i + 1) } else { "d.Hover(x)".into() };
            text.push_str(&format!(
                "\nCAPABILITY C{i:05} BY d WITH x:\n    PERFORM:\n        {body}\n"
            ));
        }
        let mut sources = SourceMap::new();
        let world = "[drones.scout]\nhome = [0, 0]\n";
        let checked = crate::check_sources(
            &mut sources,
            ("m.mission", text.as_bytes()),
            Some(("w.toml", world.as_bytes())),
            &NoFiles,
        );
        let program = checked.program.expect("program");
        for i in [0, 1, n / 2, n - 1] {
            assert_eq!(
                program.param_kinds[&format!("C{i:05}")],
                vec![Some(Kind::Duration)],
                "C{i:05}"
            );
        }
        let wrong: Vec<_> = checked
            .diagnostics
            .iter()
            .filter(|d| d.code == aviary_diagnostics::Code::WrongKind)
            .collect();
        assert_eq!(wrong.len(), 1, "{:?}", checked.diagnostics);
    }
}
