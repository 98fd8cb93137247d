//! A duration no drone can fly (W205): a middle-layer call that takes a duration
//! (`Hover`) given more seconds than its drone's `endurance`. `Hover WITH 10^12 s` checks
//! as a fine duration, and a run at `--speed max` would then take months: the battery
//! runs out (or, on the ground, the wait goes on) long before it ends.
//!
//! Durations written as numbers with a time unit are followed, as the geofence check
//! follows places, from where they are written (a mission statement's argument, a
//! capability's default or its own call) through the capabilities' parameters to the
//! middle-layer call, and with them the drones the call's actor can be. The warning is
//! at the number as written, with the call as a second place when it is elsewhere.

use std::collections::{HashMap, HashSet};
use std::rc::Rc;

use aviary_api::show::number;
use aviary_api::Kind;
use aviary_diagnostics::{Code, Diagnostic, FileId, Span};
use aviary_syntax::ast::*;
use aviary_syntax::visit::for_each_stmt;
use aviary_world::World;

use crate::actors::Actors;
use crate::env::{bind_args, capability_bodies};
use crate::Program;

/// How deep capabilities may call each other before the check stops following, as for
/// the geofence.
const MAX_CALLS: usize = 16;

/// A duration in seconds, and where it is written.
#[derive(Clone, Copy)]
struct Written {
    seconds: f64,
    file: FileId,
    span: Span,
}

/// The drones an actor can be (shared: a group of a million is copied once); `None`:
/// any drone.
type Drones = Option<Rc<[usize]>>;

/// What a name stands for while a body is walked: a duration, or the drones an actor
/// can be.
#[derive(Clone, Default)]
struct Env {
    durations: HashMap<String, Written>,
    actors: HashMap<String, Drones>,
}

pub(crate) fn check_endurance(
    program: &Program,
    world: &World,
    actors: &Actors,
    diagnostics: &mut Vec<Diagnostic>,
) {
    let (Some(mission), Some(file)) = (program.mission(), program.mission.map(|r| r.file)) else {
        return;
    };
    let timed = timed_capabilities(program);
    if timed.is_empty() {
        return;
    }
    let budget = crate::geofence::follow_budget(&mission.body);
    let mut walker =
        Walker { program, world, timed, actors, reported: HashSet::new(), out: Vec::new(), budget };
    walker.body(&mission.body, &Env::default(), file, 0);
    diagnostics.extend(walker.out);
}

/// The capabilities that make, themselves or through those they call, a middle-layer
/// call with a duration: only statements of these are followed.
fn timed_capabilities(program: &Program) -> foldhash::HashSet<&str> {
    let mut callers: foldhash::HashMap<&str, Vec<&str>> = foldhash::HashMap::default();
    let mut pending: Vec<&str> = Vec::new();
    for (file, c) in program.active_capabilities() {
        for body in capability_bodies(c) {
            for_each_stmt(body, |stmt| match stmt {
                Stmt::Statement(s) => callers
                    .entry(s.capability.name.as_str())
                    .or_default()
                    .push(c.name.name.as_str()),
                Stmt::Api(a)
                    if program
                        .api_function(file, a)
                        .is_some_and(|f| f.params.iter().any(|p| p.kind == Kind::Duration)) =>
                {
                    pending.push(c.name.name.as_str())
                }
                Stmt::Block(_)
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
    let mut timed = foldhash::HashSet::default();
    while let Some(name) = pending.pop() {
        if timed.insert(name) {
            pending.extend(callers.get(name).into_iter().flatten());
        }
    }
    timed
}

struct Walker<'a, 'w> {
    program: &'a Program,
    world: &'a World,
    timed: foldhash::HashSet<&'a str>,
    /// The drones each name of the world stands for.
    actors: &'a Actors<'w>,
    /// Each written number once, however many statements reach it.
    reported: HashSet<(FileId, u32)>,
    out: Vec<Diagnostic>,
    /// Calls into capabilities the walk may still follow (as the geofence check's).
    budget: usize,
}

impl Walker<'_, '_> {
    fn body(&mut self, body: &Body, env: &Env, file: FileId, depth: usize) {
        for stmt in &body.items {
            match stmt {
                Stmt::Statement(s) => self.statement(s, env, file, depth),
                Stmt::Api(a) => self.api_call(a, env, file),
                Stmt::For(f) => {
                    let mut inner = env.clone();
                    let sets: Option<Vec<Rc<[usize]>>> =
                        f.instances.iter().map(|i| self.drones(&i.actor, env)).collect();
                    inner.actors.insert(f.alias.name.clone(), sets.map(|v| v.concat().into()));
                    for p in &f.params {
                        inner.durations.remove(&p.name);
                    }
                    self.body(&f.body, &inner, file, depth);
                }
                Stmt::Any(a) => {
                    let mut inner = env.clone();
                    inner.actors.insert(a.alias.name.clone(), self.drones(&a.group, env));
                    self.body(&a.body, &inner, file, depth);
                }
                other @ (Stmt::Block(_)
                | Stmt::Leash(_)
                | Stmt::Requirement(_)
                | Stmt::Signal(_)
                | Stmt::Throw(_)
                | Stmt::Handler(_)
                | Stmt::ExceptionHandler(_)
                | Stmt::If(_)
                | Stmt::OperatorSignals(_)
                | Stmt::Let(_)
                | Stmt::Allow(_)
                | Stmt::StopBlock(_)
                | Stmt::Error(_)) => other.for_each_body(|b| self.body(b, env, file, depth)),
            }
        }
    }

    /// The drones an actor name can be; `None` when it could be any.
    fn drones(&self, actor: &Ident, env: &Env) -> Drones {
        if let Some(known) = env.actors.get(&actor.name) {
            return known.clone();
        }
        self.actors.drones(&actor.name).map(Rc::from)
    }

    fn duration(&self, e: &Expr, env: &Env, file: FileId) -> Option<Written> {
        match &e.kind {
            ExprKind::Number {
                value,
                unit: Some(unit @ (Unit::Second | Unit::Minute | Unit::Hour)),
                ..
            } => Some(Written { seconds: value * unit.to_si(), file, span: e.span }),
            ExprKind::Name(id) => env.durations.get(&id.name).copied(),
            ExprKind::Paren(inner) => self.duration(inner, env, file),
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
            | ExprKind::Error => None,
        }
    }

    fn statement(&mut self, s: &Statement, env: &Env, file: FileId, depth: usize) {
        if depth >= MAX_CALLS
            || self.budget == 0
            || !self.timed.contains(s.capability.name.as_str())
        {
            return;
        }
        self.budget -= 1;
        let Some((callee_file, callee)) = self.program.capability_in(&s.capability.name) else {
            return;
        };
        let mut inner = Env::default();
        // `a b Cap` on a one-actor capability runs it once per actor: any of them.
        let sets: Vec<Drones> = s.actors.iter().map(|a| self.drones(a, env)).collect();
        if callee.actors.len() == 1 && sets.len() > 1 {
            let all: Option<Vec<Rc<[usize]>>> = sets.into_iter().collect();
            inner.actors.insert(callee.actors[0].name.clone(), all.map(|v| v.concat().into()));
        } else {
            for (by, set) in callee.actors.iter().zip(sets) {
                inner.actors.insert(by.name.clone(), set);
            }
        }
        let binding = bind_args(&callee.params, &s.args);
        for (i, p) in callee.params.iter().enumerate() {
            let known = match binding.bound[i] {
                Some(e) => self.duration(e, env, file),
                None => crate::geofence::default_of(callee, &p.name)
                    .and_then(|e| self.duration(e, &Env::default(), callee_file)),
            };
            if let Some(w) = known {
                inner.durations.insert(p.name.clone(), w);
            }
        }
        for body in capability_bodies(callee) {
            self.body(body, &inner, callee_file, depth + 1);
        }
    }

    fn api_call(&mut self, call: &ApiCall, env: &Env, file: FileId) {
        let Some(f) = self.program.api_function(file, call) else { return };
        for (j, arg) in call.args.iter().enumerate() {
            let Some(p) = f.param_at(j, call.args.len(), None) else {
                continue;
            };
            if p.kind != Kind::Duration {
                continue;
            }
            let Some(w) = self.duration(arg, env, file) else { continue };
            // The longest any drone the actor can be flies; with nobody known, the fleet's.
            let drones: Rc<[usize]> = self
                .drones(&call.actor, env)
                .unwrap_or_else(|| (0..self.world.drones.len()).collect());
            let Some(longest) = drones
                .iter()
                .filter_map(|&d| self.world.drones.get(d))
                .max_by(|a, b| a.endurance.total_cmp(&b.endurance))
            else {
                continue;
            };
            if w.seconds <= longest.endurance || !self.reported.insert((w.file, w.span.start)) {
                continue;
            }
            let who = if drones.len() == 1 {
                format!("{} can stay in the air ({} s)", longest.name, number(longest.endurance))
            } else {
                format!(
                    "any of its drones can stay in the air (at most {} s)",
                    number(longest.endurance)
                )
            };
            let mut d = Diagnostic::new(Code::PastEndurance, w.file, w.span, format!("`{}` for {} s ({}) is longer than {who}", f.name(), number(w.seconds), human(w.seconds)))
                .label("longer than the battery lasts")
                .with_help("give a duration the drone can fly (its `endurance` in the world file); in the air the battery runs out long before this ends, and on the ground the wait outlasts any mission");
            if (w.file, w.span) != (file, call.span) {
                d = d.also(file, call.span, format!("{} is called here", f.name()));
            }
            self.out.push(d);
        }
    }
}

/// A long duration in the unit people think of it in.
fn human(seconds: f64) -> String {
    const UNITS: [(f64, &str); 5] = [
        (365.25 * 86400.0, "years"),
        (86400.0, "days"),
        (3600.0, "hours"),
        (60.0, "minutes"),
        (1.0, "seconds"),
    ];
    let (size, name) = UNITS.iter().copied().find(|(size, _)| seconds >= *size).unwrap_or(UNITS[4]);
    format!("about {} {name}", number((seconds / size * 10.0).round() / 10.0))
}
