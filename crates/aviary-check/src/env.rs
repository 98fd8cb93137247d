//! What names mean where: scopes of bindings over the world's names; the bodies of a
//! capability. (The walk over a body is `aviary_syntax::visit`.)

use aviary_api::Kind;
use aviary_syntax::ast::*;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Binding {
    /// A capability's BY actor, a FOR alias.
    Actor,
    /// A parameter or bound value, with its kind when known.
    Value(Option<Kind>),
}

/// What a name resolves to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Meaning {
    Local(Binding),
    Drone,
    Group,
    Place,
    Area,
    /// A line of the world file's `[lines]`.
    Line,
    /// Not a name of anything: a symbol (when the world is known).
    Unbound,
}

/// Every body of an item: a mission's, or a capability's ([`capability_bodies`]).
pub(crate) fn item_bodies(item: &Item) -> Vec<&Body> {
    match item {
        Item::Mission(m) => vec![&m.body],
        Item::Capability(c) => capability_bodies(c),
        Item::Use(_) => vec![],
    }
}

/// Every body of a capability: PERFORM sections and exception handlers.
pub(crate) fn capability_bodies(c: &Capability) -> Vec<&Body> {
    let mut out = Vec::new();
    for section in &c.sections {
        match section {
            Section::Perform { body, .. } => out.push(body),
            Section::Exceptions { handlers, .. } => out.extend(handlers.iter().map(|h| &h.body)),
            Section::Requirements { .. } | Section::Defaults { .. } => {}
        }
    }
    out
}

/// The signals the MISSION declares with `OPERATOR SIGNAL` (directly in its body, the
/// only place they count), in the order written.
pub(crate) fn operator_signals(program: &crate::Program) -> Vec<&Ident> {
    let Some(mission) = program.mission() else { return Vec::new() };
    mission
        .body
        .items
        .iter()
        .filter_map(|s| if let Stmt::OperatorSignals(o) = s { Some(&o.names) } else { None })
        .flatten()
        .collect()
}

/// The kind a literal has by itself; names and paths need the environment.
pub(crate) fn literal_kind(expr: &Expr) -> Option<Kind> {
    match &expr.kind {
        ExprKind::Number { unit, .. } => Some(unit_kind(*unit)),
        ExprKind::String(_) => Some(Kind::Text),
        ExprKind::Bool(_) => Some(Kind::Bool),
        ExprKind::Coordinates(_) | ExprKind::Geo(_) => Some(Kind::Position),
        ExprKind::Distance(..) => Some(Kind::Length),
        ExprKind::Offset(..) | ExprKind::Midpoint(..) => Some(Kind::Position),
        // `20m + 5m` is a length, `(0, 0) + (20m, 0m)` a position: the left side says.
        ExprKind::Arith(l, _, _) => literal_kind(l),
        ExprKind::Elapsed => Some(Kind::Duration),
        ExprKind::Paren(e) => literal_kind(e),
        ExprKind::Name(_)
        | ExprKind::Path(..)
        | ExprKind::Received(_)
        | ExprKind::Not(_)
        | ExprKind::Binary(..)
        | ExprKind::Error => None,
    }
}

pub(crate) fn unit_kind(unit: Option<Unit>) -> Kind {
    match unit {
        None => Kind::Number,
        Some(Unit::Metre | Unit::Kilometre) => Kind::Length,
        Some(Unit::Second | Unit::Minute | Unit::Hour) => Kind::Duration,
        Some(Unit::MetrePerSecond | Unit::KilometrePerHour) => Kind::Speed,
        Some(Unit::Degree) => Kind::Angle,
        Some(Unit::Percent) => Kind::Ratio,
    }
}

/// The unit to suggest for a bare number where `kind` is expected.
// Kinds of value, not constructs: only quantities have a unit.
#[allow(clippy::wildcard_enum_match_arm)]
pub(crate) fn unit_for(kind: Kind) -> Option<&'static str> {
    match kind {
        Kind::Length => Some("m"),
        Kind::Duration => Some("s"),
        Kind::Speed => Some("m/s"),
        Kind::Angle => Some("deg"),
        Kind::Ratio => Some("%"),
        _ => None,
    }
}

/// Binds a statement's arguments to a capability's parameters by name and position.
pub struct ArgBinding<'a> {
    pub bound: Vec<Option<&'a Expr>>,
    pub problems: Vec<BindProblem<'a>>,
}

pub enum BindProblem<'a> {
    UnknownName(&'a Ident),
    Twice(&'a Ident),
    TooMany(&'a Expr),
}

pub fn bind_args<'a>(params: &[Ident], args: &'a [Arg]) -> ArgBinding<'a> {
    let mut bound: Vec<Option<&Expr>> = vec![None; params.len()];
    let mut problems = Vec::new();
    let mut next = 0;
    for arg in args {
        match &arg.name {
            Some(name) => match params.iter().position(|p| p.name == name.name) {
                Some(i) if bound[i].is_some() => problems.push(BindProblem::Twice(name)),
                Some(i) => bound[i] = Some(&arg.value),
                None => problems.push(BindProblem::UnknownName(name)),
            },
            None => {
                while next < params.len() && bound[next].is_some() {
                    next += 1;
                }
                if next < params.len() {
                    bound[next] = Some(&arg.value);
                    next += 1;
                } else {
                    problems.push(BindProblem::TooMany(&arg.value));
                }
            }
        }
    }
    ArgBinding { bound, problems }
}
