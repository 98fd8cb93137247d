//! W207: a handler of a drone's built-in signal that can never hear it.
//!
//! A drone's built-in signals (`BatteryLow`, `ConnectionRestored`, `Detected`) are raised
//! where the drone's work is at that moment, or, for the first two, at the mission's own
//! body when the drone runs nothing (docs/LANGUAGE.md, section 16). A handler hears them
//! only while that work is inside the handler's block. Two cases are certain, and only
//! those are reported:
//!
//! 1. **Nobody of the `BY` works here.** `ON S BY x` in a block (not the mission's own
//!    body, which hears idle drones too) where no statement and no middle-layer call
//!    gives work to `x` (a drone, a group's members, or a capability's own `BY` name),
//!    counting what the capabilities called there name, but not the handler's own body,
//!    which cannot start before the handler hears something. A handler directly in a
//!    capability's nameless `PERFORM` with `BY` its own drone is never reported: that
//!    PERFORM is the drone's work for as long as it runs.
//! 2. **`ConnectionRestored` in the capability its loss ends.** `ON ConnectionRestored`
//!    (`BY` the capability's own drone, or with no `BY` in a capability that names no
//!    other drone) anywhere in a capability's nameless `PERFORM`, when neither the
//!    capability nor any it calls handles `ConnectionLost` or `CommandFailed`, and its
//!    PERFORM begins with a middle-layer call on that drone. The link comes back only
//!    after it was lost; if the activity ran then, the loss (raised in it) went out of it
//!    and ended it; if it started during the loss, its first call was refused (a lost
//!    drone takes no command) and that ended it.
//!
//! Anything the checker cannot resolve (a `FOR` alias in `BY`, a parameter as an actor)
//! counts as "maybe": no warning.

use std::collections::{BTreeSet, HashMap};
use std::rc::Rc;

use aviary_api::{BuiltinException, BuiltinSignal, Descriptor};
use aviary_diagnostics::{Code, Diagnostic, FileId, Span};
use aviary_syntax::ast::*;
use aviary_world::World;

use aviary_syntax::visit::for_each_stmt;

use crate::actors::Actors;
use crate::env::capability_bodies;
use crate::Program;

/// The drones that may get work somewhere: world drones and a capability's own `BY`
/// names, by name, or anyone at all (a name the checker cannot resolve).
#[derive(Clone, Debug, Default)]
struct Drones {
    world: BTreeSet<String>,
    own: BTreeSet<String>,
    any: bool,
}

impl Drones {
    fn add(&mut self, other: &Drones) {
        self.world.extend(other.world.iter().cloned());
        self.own.extend(other.own.iter().cloned());
        self.any |= other.any;
    }

    fn meets(&self, other: &Drones) -> bool {
        self.any
            || other.any
            || self.world.iter().any(|d| other.world.contains(d))
            || self.own.iter().any(|d| other.own.contains(d))
    }
}

pub(crate) fn check_unheard(
    program: &Program,
    world: Option<&World>,
    actors: Option<&Actors>,
    out: &mut Vec<Diagnostic>,
) {
    let api = Descriptor::standard();
    let mut pass =
        Pass { program, world, actors, api, named: HashMap::new(), catches: HashMap::new() };
    // Rule 1 resolves the drones of every statement and `FOR` it passes: on a mission of
    // a hundred thousand drones that is most of the checker's time, so it runs only where
    // there is a handler for it to judge.
    let mut judged = false;
    let mission = program.mission().map(|m| &m.body);
    let capabilities = program.active_capabilities().flat_map(|(_, c)| capability_bodies(c));
    for body in mission.into_iter().chain(capabilities) {
        for_each_stmt(body, |stmt| {
            judged |= matches!(stmt, Stmt::Handler(h)
                if h.by.is_some() && api.signal(&h.signal.name).is_some());
        });
    }
    if !judged {
        for (file, c) in program.active_capabilities() {
            pass.restored_after_loss(c, file, &[], out);
        }
        return;
    }
    if let (Some(mission), Some(at)) = (program.mission(), program.mission) {
        let scope = Scope { file: at.file, own: &[], aliases: Vec::new() };
        pass.body(&mission.body, &scope, Place::MissionBody, out);
    }
    for (file, c) in program.active_capabilities() {
        let scope = Scope { file, own: &c.actors, aliases: Vec::new() };
        let mut reported = Vec::new();
        for section in &c.sections {
            match section {
                Section::Perform { name, body, .. } => {
                    let place = if name.is_none() { Place::Perform } else { Place::Nested };
                    let before = out.len();
                    pass.body(body, &scope, place, out);
                    reported.extend(out[before..].iter().map(|d| d.primary.span));
                }
                Section::Exceptions { handlers, .. } => {
                    for h in handlers {
                        pass.body(&h.body, &scope, Place::Nested, out);
                    }
                }
                Section::Requirements { .. } | Section::Defaults { .. } => {}
            }
        }
        pass.restored_after_loss(c, file, &reported, out);
    }
}

/// Where a body is, for the two bodies that hear more than their work.
#[derive(Clone, Copy, PartialEq)]
enum Place {
    /// The mission's own body: idle drones' signals are raised there.
    MissionBody,
    /// A capability's nameless PERFORM: its drones' work while it runs.
    Perform,
    Nested,
}

/// What names mean in a body: a capability's own drones, and the `FOR` aliases around.
#[derive(Clone)]
struct Scope<'a> {
    file: FileId,
    own: &'a [Ident],
    /// Shared: every statement inside a `FOR` has its own scope, and a group's alias may
    /// stand for a hundred thousand drones.
    aliases: Vec<(&'a str, Rc<Drones>)>,
}

struct Pass<'a, 'w> {
    program: &'a Program,
    world: Option<&'a World>,
    /// The drones each name of the world stands for.
    actors: Option<&'a Actors<'w>>,
    api: &'a Descriptor,
    /// The drones each capability names in its statements, through what it calls.
    named: HashMap<&'a str, Drones>,
    /// Whether each capability, or one it calls, handles `ConnectionLost` or `CommandFailed`.
    catches: HashMap<&'a str, bool>,
}

impl<'a> Pass<'a, '_> {
    /// Rule 1 on every handler of `body` and of the bodies inside it.
    fn body(&mut self, body: &'a Body, scope: &Scope<'a>, place: Place, out: &mut Vec<Diagnostic>) {
        for stmt in &body.items {
            if let Stmt::Handler(h) = stmt {
                self.handler(h, body, scope, place, out);
            }
            let inner = self.inside(stmt, scope);
            stmt.for_each_body(|b| self.body(b, &inner, Place::Nested, out));
        }
    }

    /// The scope of the bodies of `stmt`: a `FOR` binds its alias there.
    fn inside(&mut self, stmt: &'a Stmt, scope: &Scope<'a>) -> Scope<'a> {
        let mut inner = scope.clone();
        if let Stmt::For(f) = stmt {
            let mut drones = Drones::default();
            for i in &f.instances {
                drones.add(&self.resolve(&i.actor.name, scope));
            }
            inner.aliases.push((f.alias.name.as_str(), Rc::new(drones)));
        }
        // The drone an ANY takes is one of its group.
        if let Stmt::Any(a) = stmt {
            let mut drones = Drones::default();
            drones.add(&self.resolve(&a.group.name, scope));
            inner.aliases.push((a.alias.name.as_str(), Rc::new(drones)));
        }
        inner
    }

    fn handler(
        &mut self,
        h: &'a Handler,
        block: &'a Body,
        scope: &Scope<'a>,
        place: Place,
        out: &mut Vec<Diagnostic>,
    ) {
        let Some(signal) = self.api.signal(&h.signal.name) else { return };
        let Some(by) = &h.by else { return };
        if place == Place::MissionBody || self.world.is_none() {
            return;
        }
        let targets = self.resolve(&by.name, scope);
        let alias = scope.aliases.iter().any(|(a, _)| *a == by.name);
        if targets.any || alias {
            return;
        }
        if place == Place::Perform && !targets.own.is_empty() {
            return;
        }
        let mut work = Drones::default();
        self.work(block, scope, h, &mut work);
        if work.meets(&targets) {
            return;
        }
        let who = &by.name;
        // Built-in signals, not constructs: only `Detected` comes from a call of its own.
        #[allow(clippy::wildcard_enum_match_arm)]
        let raised = match signal {
            BuiltinSignal::Detected => "where it called `StartDetection`",
            _ => "where its work is (at mission level when it runs nothing)",
        };
        out.push(
            Diagnostic::new(
                Code::SignalNeverHeard,
                scope.file,
                by.span,
                format!("`{}` of `{who}` is raised {raised}, and nothing in this block gives `{who}` work, so this handler never hears it", h.signal.name),
            )
            .with_help(format!("put this handler in the block that runs `{who}`'s statements, or directly under MISSION, which also hears a drone that runs nothing; or name in `BY` a drone that works in this block")),
        );
    }

    /// Adds to `work` the drones given work in `body`, outside `except`'s own body.
    fn work(&mut self, body: &'a Body, scope: &Scope<'a>, except: &Handler, work: &mut Drones) {
        for stmt in &body.items {
            match stmt {
                Stmt::Statement(s) => {
                    for a in &s.actors {
                        work.add(&self.resolve(&a.name, scope));
                    }
                    let named = self.named(&s.capability.name);
                    work.add(&named);
                }
                Stmt::Api(a) => work.add(&self.resolve(&a.actor.name, scope)),
                Stmt::Handler(h) if std::ptr::eq(h, except) => continue,
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
            let inner = self.inside(stmt, scope);
            stmt.for_each_body(|b| self.work(b, &inner, except, work));
        }
    }

    /// What an actor's name stands for here.
    fn resolve(&self, name: &str, scope: &Scope<'a>) -> Drones {
        let mut d = Drones::default();
        if let Some((_, drones)) = scope.aliases.iter().rev().find(|(a, _)| *a == name) {
            return Drones::clone(drones);
        }
        if scope.own.iter().any(|o| o.name == name) {
            d.own.insert(name.to_string());
            return d;
        }
        let (Some(world), Some(actors)) = (self.world, self.actors) else {
            d.any = true;
            return d;
        };
        match actors.drones(name) {
            Some(drones) => d
                .world
                .extend(drones.iter().filter_map(|m| world.drones.get(*m)).map(|x| x.name.clone())),
            // A parameter, or a name the walk reports as unknown.
            None => d.any = true,
        }
        d
    }

    /// The world drones a capability's statements name, through the capabilities it
    /// calls (its own drones are its caller's, counted there).
    fn named(&mut self, capability: &'a str) -> Drones {
        if let Some(known) = self.named.get(capability) {
            return known.clone();
        }
        // A cycle of calls adds nothing the first visit does not find.
        self.named.insert(capability, Drones::default());
        let mut drones = Drones::default();
        if let Some(c) = self.program.capability(capability) {
            let scope = Scope { file: FileId::default(), own: &c.actors, aliases: Vec::new() };
            let mut calls = Vec::new();
            for body in capability_bodies(c) {
                for_each_stmt(body, |stmt| {
                    if let Stmt::Statement(s) = stmt {
                        calls.push(s);
                    }
                });
            }
            for s in calls {
                for a in &s.actors {
                    let mut r = self.resolve(&a.name, &scope);
                    // Its own drones and FOR aliases over them are its caller's.
                    r.own.clear();
                    drones.add(&r);
                }
                drones.add(&self.named(&s.capability.name));
            }
        }
        self.named.insert(capability, drones.clone());
        drones
    }

    /// Whether a capability or one it calls handles `ConnectionLost` or `CommandFailed`.
    fn catches_loss(&mut self, capability: &'a str) -> bool {
        if let Some(known) = self.catches.get(capability) {
            return *known;
        }
        self.catches.insert(capability, false);
        let Some(c) = self.program.capability(capability) else { return false };
        let caught = |name: &str| {
            name == BuiltinException::ConnectionLost.name()
                || name == BuiltinException::CommandFailed.name()
        };
        let mut found = false;
        let mut calls = Vec::new();
        for section in &c.sections {
            if let Section::Exceptions { handlers, .. } = section {
                found |= handlers.iter().any(|h| caught(&h.exception.name));
            }
        }
        for body in capability_bodies(c) {
            for_each_stmt(body, |stmt| match stmt {
                Stmt::ExceptionHandler(h) if caught(&h.exception.name) => found = true,
                Stmt::Statement(s) => calls.push(s.capability.name.as_str()),
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
        for callee in calls {
            found |= self.catches_loss(callee);
        }
        self.catches.insert(capability, found);
        found
    }

    /// Rule 2 on the capability `c`.
    fn restored_after_loss(
        &mut self,
        c: &'a Capability,
        file: FileId,
        reported: &[Span],
        out: &mut Vec<Diagnostic>,
    ) {
        let Some(perform) = c.sections.iter().find_map(|s| match s {
            Section::Perform { name: None, body, .. } => Some(body),
            Section::Requirements { .. }
            | Section::Defaults { .. }
            | Section::Perform { .. }
            | Section::Exceptions { .. } => None,
        }) else {
            return;
        };
        let restored = BuiltinSignal::ConnectionRestored.name();
        let mut handlers = Vec::new();
        for_each_stmt(perform, |stmt| {
            if let Stmt::Handler(h) = stmt {
                if h.signal.name == restored {
                    handlers.push(h);
                }
            }
        });
        if handlers.is_empty() || self.catches_loss(&c.name.name) {
            return;
        }
        let names_others = {
            let named = self.named(&c.name.name);
            named.any || !named.world.is_empty()
        };
        for h in handlers {
            let drone = match &h.by {
                Some(by) if c.actors.iter().any(|a| a.name == by.name) => &by.name,
                None if !names_others && c.actors.len() == 1 => &c.actors[0].name,
                _ => continue,
            };
            let span = h.by.as_ref().map_or(h.signal.span, |b| b.span);
            if reported.contains(&span) || !begins_with_call_on(perform, drone) {
                continue;
            }
            out.push(
                Diagnostic::new(
                    Code::SignalNeverHeard,
                    file,
                    h.signal.span,
                    format!("`{restored}` of `{drone}` comes only after its link was lost, and nothing in `{}` handles that loss, which ends it first, so this handler never hears it", c.name.name),
                )
                .with_help(format!("handle `{restored}` in the mission, beside the `ON EXCEPTION ConnectionLost BY ...` that takes the loss; or catch `ConnectionLost` inside `{}` so that it keeps running until the link is back", c.name.name)),
            );
        }
    }
}

/// Whether the first thing `body` does (past handlers and signals, which take no time)
/// is a middle-layer call on `drone`.
fn begins_with_call_on(body: &Body, drone: &str) -> bool {
    let first = body
        .items
        .iter()
        .find(|s| !matches!(s, Stmt::Signal(_) | Stmt::Handler(_) | Stmt::ExceptionHandler(_)));
    matches!(first, Some(Stmt::Api(a)) if a.actor.name == drone)
}
