//! The kinds of values: what an expression is, and whether it fits where it stands
//! (units, places, conditions, telemetry and attributes).

use aviary_api::Kind;
use aviary_diagnostics::Code;
use aviary_syntax::ast::*;
use aviary_world::AttributeValue;

use super::{shown, Checker};
use crate::env::*;
use aviary_diagnostics::suggest::did_you_mean;

/// Where a remainder goes, for help lines.
const REMAINDER_FLOWN: &str = "give a remainder to `Sweep` in place of an area (`drone.Sweep(lost.remaining, 20m)`, or a capability that sweeps its parameter), or to `FollowPath` in place of its points";

impl<'a> Checker<'a> {
    pub(super) fn condition(&mut self, e: &'a Expr) {
        let k = self.value(e, None, "a condition");
        if let Some(k) = k {
            if k != Kind::Bool {
                let d = self.report(
                    Code::WrongKind,
                    e.span,
                    format!("a condition must be true or false, and this is {}", k.describe()),
                );
                d.help =
                    Some("compare it with something: `drone.battery > 25%`, `type = Body`".into());
            }
        }
    }

    /// The kind of a value, checked against `expected` when given. Reports what is wrong.
    pub(super) fn value(
        &mut self,
        e: &'a Expr,
        expected: Option<Kind>,
        what: &str,
    ) -> Option<Kind> {
        let actual = self.kind_of(e);
        self.fits(e, actual, expected, what)
    }

    /// Whether `e`, of kind `actual`, fits where `expected` is: reports what is wrong.
    pub(super) fn fits(
        &mut self,
        e: &'a Expr,
        actual: Option<Kind>,
        expected: Option<Kind>,
        what: &str,
    ) -> Option<Kind> {
        let (Some(expected), Some(actual)) = (expected, actual) else { return actual };
        if expected.accepts(actual) {
            return Some(actual);
        }
        if actual == Kind::Remainder {
            self.remainder_misplaced(e, expected, what);
            return Some(actual);
        }
        if let ExprKind::Name(id) = &e.kind {
            if actual == Kind::Symbol
                && matches!(expected, Kind::Position | Kind::Area | Kind::Path)
            {
                // Kinds of value, not constructs: the rest of the three is a position.
                #[allow(clippy::wildcard_enum_match_arm)]
                let noun = match expected {
                    Kind::Area => "area",
                    Kind::Path => "line or place",
                    _ => "place",
                };
                // As for `noun`.
                #[allow(clippy::wildcard_enum_match_arm)]
                let candidates: Vec<&str> = self.world.map_or(Vec::new(), |w| {
                    let areas = w.areas.iter().map(|a| a.name.as_str());
                    let places = w.places.iter().map(|p| p.name.as_str());
                    match expected {
                        Kind::Area => areas.collect(),
                        Kind::Path => w
                            .lines
                            .iter()
                            .map(|l| l.name.as_str())
                            .chain(places)
                            .chain(areas)
                            .collect(),
                        _ => places.chain(areas).collect(),
                    }
                });
                let table = if expected == Kind::Path { "lines] or [places" } else { noun };
                let help = did_you_mean(&id.name, candidates.iter().copied())
                    .unwrap_or_else(|| format!("define it in the world file's [{table}s], or use coordinates such as (100, 50)"));
                let d = self.report(
                    Code::UnknownPlace,
                    id.span,
                    format!("unknown {noun} `{}`", id.name),
                );
                d.help = Some(help);
                return Some(actual);
            }
        }
        if actual == Kind::Number {
            if let (Some(unit), ExprKind::Number { digits, .. }) = (unit_for(expected), &e.kind) {
                let d = self.report(
                    Code::WrongKind,
                    e.span,
                    format!("`{digits}` has no unit, and {what} is {}", expected.describe()),
                );
                d.help = Some(format!("write `{digits}{unit}`"));
                return Some(actual);
            }
        }
        let origin = self.parameter_origin(e);
        let help = self.what_to_write(e, expected, actual);
        let file = self.file;
        let d = self.report(
            Code::WrongKind,
            e.span,
            format!(
                "{what} is {}, but this is {}",
                expected.describe(),
                shown_as(actual, expected)
            ),
        );
        d.primary.message = format!("expected {}", expected.describe());
        d.help = Some(help);
        if let Some((name, cap, default)) = origin {
            // A parameter has one kind: say where this one comes from.
            match default {
                Some(default) => {
                    let span = default.span;
                    d.secondary.push(aviary_diagnostics::Label { file, span, message: format!("`{name}` is {} because of its default", actual.describe()) });
                    d.help = Some(match (&default.kind, unit_for(expected)) {
                        (ExprKind::Number { digits, unit: None, .. }, Some(unit)) => format!("give the default its unit: `{name}: {digits}{unit}`"),
                        _ => format!("change the default of `{name}`, or pass `{name}` only where {} is expected", actual.describe()),
                    });
                }
                None => {
                    d.help = Some(format!(
                        "`{name}` is a parameter of `{cap}`, and it is {} where it is first used; a parameter has one kind: pass `{name}` on only where {} is expected, or give `{cap}` a second parameter for {}",
                        actual.describe(),
                        actual.describe(),
                        expected.describe()
                    ))
                }
            }
        }
        Some(actual)
    }

    /// What to write where `expected` is wanted and `e` is `actual`: the kind, with an
    /// example from the world where there is one (a place, an area), and why a point is
    /// no area.
    fn what_to_write(&self, e: &Expr, expected: Kind, actual: Kind) -> String {
        let world_example = |areas: bool| {
            self.world.and_then(|w| {
                if areas {
                    w.areas.first().map(|a| a.name.clone())
                } else {
                    w.places.first().map(|p| p.name.clone())
                }
            })
        };
        match (expected, actual) {
            (Kind::Area, Kind::Position) => {
                let what = match &e.kind {
                    ExprKind::Name(id) => format!("`{}` is a place, a single point", id.name),
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
                    | ExprKind::Error => "a position is a single point".to_string(),
                };
                match world_example(true) {
                    Some(area) => format!("{what}, with no area to cover: name an area of the world file's [areas], such as `{area}`, or add one there (an area stands for its centre where a position is expected, so one area serves both)"),
                    None => format!("{what}, with no area to cover: add the area to the world file's [areas] and name it here"),
                }
            }
            (Kind::Area, _) => match world_example(true) {
                Some(area) => format!("write the name of an area of the world file's [areas], such as `{area}`"),
                None => "write the name of an area of the world file's [areas]".to_string(),
            },
            (Kind::Position, Kind::Line) => {
                "a line is many points: fly along it with `FollowPath` (`drone FollowPath WITH line`), or name one place of it".to_string()
            }
            (Kind::Path, _) => match self.world.and_then(|w| w.lines.first()) {
                Some(line) => format!("write positions, or a line of the world file's [lines] such as `{}`", line.name),
                None => "write positions such as `(100, 50)`, or a line of the world file's [lines]".to_string(),
            },
            (Kind::Position, _) => match world_example(false) {
                Some(place) => format!("write a position: a place of the world file such as `{place}`, an area (its centre), or coordinates such as `(100, 50)`"),
                None => "write a position: a place or an area of the world file, or coordinates such as `(100, 50)`".to_string(),
            },
            _ => format!("write {}, such as `{}`", expected.describe(), expected.example()),
        }
    }

    /// `group.remaining`: each drone of a group leaves its own remainder.
    fn group_remainder(&mut self, a: &'a Ident, field: &'a Ident) {
        let first = self.world.and_then(|w| {
            w.drones
                .iter()
                .find(|d| d.group.as_deref() == Some(a.name.as_str()))
                .map(|d| d.name.clone())
        });
        let d = self.report(
            Code::GroupRemainder,
            a.span.to(field.span),
            format!("`{}` is a group, and each of its drones leaves its own remainder", a.name),
        );
        d.help = Some(match first {
            Some(one) => format!("name one drone (`{one}.{}`), or a FOR alias over the group (`PARALLEL FOR {} AS d:` then `d.{}`)", field.name, a.name, field.name),
            None => format!("name one drone, or a FOR alias over the group (`PARALLEL FOR {} AS d:` then `d.{}`)", a.name, field.name),
        });
    }

    /// What a Sweep or FollowPath left, where something else is expected.
    fn remainder_misplaced(&mut self, e: &'a Expr, expected: Kind, what: &str) {
        let d = self.report(
            Code::WrongKind,
            e.span,
            format!(
                "{what} is {}, but this is {}",
                expected.describe(),
                Kind::Remainder.describe()
            ),
        );
        d.primary.message = format!("expected {}", expected.describe());
        let flown = REMAINDER_FLOWN;
        d.help = Some(if expected == Kind::Position {
            format!("{flown}; for where a drone is, name the drone or read `drone.position`")
        } else {
            format!(
                "{flown}; to compare how far a drone got, read its telemetry (`drone.position`)"
            )
        });
    }

    /// For a name that is a parameter of the capability being checked: its name, the
    /// capability's name, and its default, if it has one.
    pub(super) fn parameter_origin(&self, e: &Expr) -> Option<(String, String, Option<&'a Expr>)> {
        let ExprKind::Name(id) = &e.kind else { return None };
        let cap = self.capability?;
        if !cap.params.iter().any(|p| p.name == id.name)
            || !matches!(self.lookup(&id.name), Meaning::Local(Binding::Value(_)))
        {
            return None;
        }
        let default = cap.sections.iter().find_map(|s| match s {
            Section::Defaults { entries, .. } => {
                entries.iter().find(|d| d.name.name == id.name).map(|d| &d.value)
            }
            Section::Requirements { .. } | Section::Perform { .. } | Section::Exceptions { .. } => {
                None
            }
        });
        Some((id.name.clone(), cap.name.name.clone(), default))
    }

    /// `Some(Actor)` when `e` names a drone, group or alias; reports nothing.
    pub(super) fn kind_of_quietly(&self, e: &Expr) -> Option<Kind> {
        match &e.kind {
            ExprKind::Name(id) => matches!(
                self.lookup(&id.name),
                Meaning::Local(Binding::Actor) | Meaning::Drone | Meaning::Group
            )
            .then_some(Kind::Actor),
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

    pub(super) fn kind_of(&mut self, e: &'a Expr) -> Option<Kind> {
        match &e.kind {
            ExprKind::Name(id) => match self.lookup(&id.name) {
                Meaning::Local(Binding::Actor) | Meaning::Drone | Meaning::Group => {
                    Some(Kind::Actor)
                }
                Meaning::Local(Binding::Value(k)) => k,
                Meaning::Place => Some(Kind::Position),
                Meaning::Area => Some(Kind::Area),
                Meaning::Unbound if self.let_not_here(id) => None,
                Meaning::Line => Some(Kind::Line),
                Meaning::Unbound if self.names_are_known() => Some(Kind::Symbol),
                Meaning::Unbound => None,
            },
            ExprKind::Path(a, field) => self.path(a, field),
            ExprKind::Coordinates(parts) => {
                for p in parts {
                    if let Some(k) = self.kind_of(p) {
                        if !matches!(k, Kind::Number | Kind::Length) {
                            let d = self.report(
                                Code::WrongKind,
                                p.span,
                                format!(
                                    "a coordinate is a number of metres, and this is {}",
                                    k.describe()
                                ),
                            );
                            d.help = Some(
                                "write coordinates as `(x, y)` or `(x, y, z)` in metres".into(),
                            );
                        }
                    }
                }
                Some(Kind::Position)
            }
            ExprKind::Geo(parts) => {
                for p in parts {
                    self.kind_of(p);
                }
                Some(Kind::Position)
            }
            ExprKind::Distance(a, b) => {
                // A drone stands for where it is now: `distance(drone, Home) < 10m`.
                for (e, what) in [(a, "`distance`'s first place"), (b, "`distance`'s second place")]
                {
                    if self.kind_of_quietly(e) != Some(Kind::Actor) {
                        self.value(e, Some(Kind::Position), what);
                    }
                }
                Some(Kind::Length)
            }
            ExprKind::Arith(l, op, r) => self.arith(l, *op, r),
            ExprKind::Offset(p, d, b) => {
                self.place_value(p, "`OFFSET`'s position");
                self.value(d, Some(Kind::Length), "`OFFSET`'s distance");
                self.value(b, Some(Kind::Angle), "`OFFSET`'s bearing (clockwise from north)");
                Some(Kind::Position)
            }
            ExprKind::Midpoint(a, b) => {
                self.place_value(a, "`MIDPOINT`'s first position");
                self.place_value(b, "`MIDPOINT`'s second position");
                Some(Kind::Position)
            }
            ExprKind::Received(_) => Some(Kind::Bool),
            ExprKind::Not(inner) => {
                self.condition(inner);
                Some(Kind::Bool)
            }
            ExprKind::Binary(l, BinaryOp::And | BinaryOp::Or, r) => {
                self.condition(l);
                self.condition(r);
                Some(Kind::Bool)
            }
            ExprKind::Binary(l, op, r) => {
                let lk = self.kind_of(l);
                match lk {
                    Some(Kind::Remainder) => {
                        let d = self.report(
                            Code::WrongKind,
                            l.span,
                            format!("{} cannot be compared", Kind::Remainder.describe()),
                        );
                        d.help = Some(format!("{REMAINDER_FLOWN}: it ends at once when nothing is left; to know how far a drone got, read its `position`"));
                        self.kind_of(r);
                    }
                    // A symbol on the left (`x = Hoem` reads fine either way): check the right against it.
                    Some(k) => {
                        let what = shown(l).map_or_else(
                            || format!("the other side of `{}`", op.as_str()),
                            |l| format!("`{l}`"),
                        );
                        self.value(r, Some(k), &what);
                    }
                    None => {
                        self.kind_of(r);
                    }
                }
                Some(Kind::Bool)
            }
            ExprKind::Paren(inner) => self.kind_of(inner),
            ExprKind::Error => None,
            ExprKind::Number { .. }
            | ExprKind::String(_)
            | ExprKind::Bool(_)
            | ExprKind::Elapsed => literal_kind(e),
        }
    }

    /// A position, where a drone stands for where it is (as in `distance`).
    fn place_value(&mut self, e: &'a Expr, what: &str) {
        if self.kind_of_quietly(e) != Some(Kind::Actor) {
            self.value(e, Some(Kind::Position), what);
        }
    }

    /// `a + b`, `a - b`: a position and an offset written as coordinates, or two
    /// quantities of one kind. The kind of the sum.
    fn arith(&mut self, l: &'a Expr, op: ArithOp, r: &'a Expr) -> Option<Kind> {
        let sign = op.as_str();
        let left = if self.kind_of_quietly(l) == Some(Kind::Actor) {
            Some(Kind::Position)
        } else {
            self.kind_of(l)
        };
        let offset = matches!(unparen(r).kind, ExprKind::Coordinates(_));
        match left {
            Some(Kind::Position | Kind::Area) => {
                if offset {
                    self.kind_of(r);
                } else {
                    let right = self.kind_of(r);
                    let d = self.report(
                        Code::WrongKind,
                        r.span,
                        format!(
                            "a position moves by an offset in metres written as coordinates, and this is {}",
                            right.map_or("not coordinates", |k| k.describe())
                        ),
                    );
                    d.primary.message = "expected (east, north) in metres".into();
                    let base = shown(l).unwrap_or_else(|| "where".into());
                    d.help = Some(format!(
                        "write `{base} {sign} (20m, 0m)` for 20 m east, `(0m, 20m)` north, `(0m, 0m, 5m)` up; or `OFFSET({base}, 20m, 90deg)` by bearing"
                    ));
                }
                Some(Kind::Position)
            }
            Some(
                k @ (Kind::Length
                | Kind::Duration
                | Kind::Speed
                | Kind::Angle
                | Kind::Ratio
                | Kind::Number),
            ) => {
                let verb = if op == ArithOp::Add { "added to" } else { "taken from" };
                let what = shown(l).map_or_else(
                    || format!("the other side of `{sign}`"),
                    |l| format!("what is {verb} `{l}`"),
                );
                self.value(r, Some(k), &what);
                Some(k)
            }
            Some(k) => {
                let d = self.report(
                    Code::WrongKind,
                    l.span,
                    format!("`{sign}` joins quantities of one kind, or a position and an offset, and this is {}", k.describe()),
                );
                d.primary.message = format!("{} has no `{sign}`", k.describe());
                d.help = Some("add lengths to lengths (`20m + 5m`), or move a position by metres (`where + (20m, 0m)`)".into());
                self.kind_of(r);
                None
            }
            None => {
                let right = self.kind_of(r);
                if offset {
                    Some(Kind::Position)
                } else {
                    right.filter(|k| {
                        matches!(
                            k,
                            Kind::Length
                                | Kind::Duration
                                | Kind::Speed
                                | Kind::Angle
                                | Kind::Ratio
                                | Kind::Number
                        )
                    })
                }
            }
        }
    }

    /// `a.field`: telemetry, or an attribute from the world file.
    pub(super) fn path(&mut self, a: &'a Ident, field: &'a Ident) -> Option<Kind> {
        self.actor(a);
        if let Some(k) = self.api.telemetry(&field.name) {
            if k == Kind::Remainder && matches!(self.lookup(&a.name), Meaning::Group) {
                self.group_remainder(a, field);
            }
            return Some(k);
        }
        let world = self.world?;
        let found = world
            .drones
            .iter()
            .find_map(|d| d.attributes.iter().find(|(k, _)| **k == *field.name).map(|(_, v)| v));
        match found {
            Some(AttributeValue::Number(_)) => Some(Kind::Number),
            Some(AttributeValue::Text(_)) => Some(Kind::Text),
            Some(AttributeValue::Bool(_)) => Some(Kind::Bool),
            Some(AttributeValue::Other(_)) => None,
            None => {
                let mut names: Vec<&str> = self.api.telemetry.iter().map(|(n, _)| *n).collect();
                for d in &world.drones {
                    names.extend(d.attributes.iter().map(|(k, _)| &**k));
                }
                names.sort_unstable();
                names.dedup();
                let help = did_you_mean(&field.name, names.iter().copied())
                    .unwrap_or_else(|| format!("telemetry and attributes: {}", names.join(", ")));
                let d = self.report(
                    Code::UnknownTelemetry,
                    field.span,
                    format!(
                        "`{}` is no telemetry field and no attribute of `{}`",
                        field.name, a.name
                    ),
                );
                d.help = Some(help);
                None
            }
        }
    }
}

/// An expression without the parentheses around it.
fn unparen(e: &Expr) -> &Expr {
    match &e.kind {
        ExprKind::Paren(inner) => unparen(inner),
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
        | ExprKind::Received(_)
        | ExprKind::Elapsed
        | ExprKind::Not(_)
        | ExprKind::Binary(..)
        | ExprKind::Error => e,
    }
}

/// How to call a value of kind `actual` where `expected` was wanted: a position where an
/// area is wanted is a single point (an area is a position too, so "a position (a place,
/// an area, ...)" would say nothing).
fn shown_as(actual: Kind, expected: Kind) -> &'static str {
    match (expected, actual) {
        (Kind::Area, Kind::Position) => "a single point (a place or coordinates)",
        _ => actual.describe(),
    }
}
