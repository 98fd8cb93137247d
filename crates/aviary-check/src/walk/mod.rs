//! The name, argument and kind checks: one walk over the mission and every capability.

use std::collections::HashSet;

use aviary_api::{Descriptor, Kind};
use aviary_diagnostics::{Code, Diagnostic, FileId, Span};
use aviary_syntax::ast::*;
use aviary_syntax::visit::for_each_stmt;
use aviary_world::World;

use crate::env::*;
use crate::Program;
use aviary_diagnostics::suggest::did_you_mean;

mod calls;
mod kinds;
mod lets;

pub(crate) fn check_program(
    program: &Program,
    world: Option<&World>,
    root: FileId,
    diagnostics: &mut Vec<Diagnostic>,
) {
    let api = Descriptor::standard();
    let mut tags = Vec::new();
    let mut aliases = HashSet::new();
    let mut blocks = Vec::new();
    for (_, tree) in &program.files {
        for item in &tree.items {
            for body in item_bodies(item) {
                for_each_stmt(body, |stmt| match stmt {
                    Stmt::Statement(Statement { capability, tag: Some(tag), .. }) => {
                        tags.push((capability.name.as_str(), tag.name.as_str()))
                    }
                    Stmt::For(f) => {
                        aliases.insert(f.alias.name.as_str());
                    }
                    Stmt::Any(a) => {
                        aliases.insert(a.alias.name.as_str());
                    }
                    Stmt::Block(Block { name: Some(name), .. }) => blocks.push(name.name.as_str()),
                    Stmt::Block(_)
                    | Stmt::Statement(_)
                    | Stmt::Leash(_)
                    | Stmt::Api(_)
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
                    | Stmt::Error(_) => {}
                });
            }
        }
    }
    let tag_set = tags.iter().copied().collect();
    let world_names = world.map(world_names).unwrap_or_default();
    let mut checker = Checker {
        program,
        world,
        api,
        diagnostics,
        file: root,
        capability: None,
        scopes: Vec::new(),
        tags,
        tag_set,
        aliases,
        blocks,
        world_names,
        top_level: HashSet::new(),
        lets: Vec::new(),
        hidden: Vec::new(),
    };
    for (file, tree) in &program.files {
        checker.file = *file;
        for item in &tree.items {
            match item {
                Item::Mission(m) if program.mission().map(|x| x.span) == Some(m.span) => {
                    if world.is_none() {
                        let d = Diagnostic::new(
                            Code::NoWorld,
                            *file,
                            m.name.span,
                            "no world file, so actors, places and areas were not checked",
                        )
                        .with_help(
                            "put NAME.world.toml beside the mission, or pass `--world FILE`",
                        );
                        checker.diagnostics.push(d);
                    }
                    checker.capability = None;
                    checker.lets = lets::all_lets(&[&m.body]);
                    checker.operator_signals(&m.body);
                    checker.body(&m.body);
                }
                // Overridden library capabilities are never run, so never checked here.
                Item::Capability(c)
                    if program.is_active(*file, c) || checker.is_user_file(*file) =>
                {
                    checker.capability_def(c);
                }
                Item::Use(_) | Item::Capability(_) | Item::Mission(_) => {}
            }
        }
    }
}

struct Checker<'a> {
    program: &'a Program,
    world: Option<&'a World>,
    api: &'a Descriptor,
    diagnostics: &'a mut Vec<Diagnostic>,
    file: FileId,
    capability: Option<&'a Capability>,
    scopes: Vec<Vec<(&'a str, Binding)>>,
    /// Every `Capability-Tag` that some statement starts, in order (for help lines).
    tags: Vec<(&'a str, &'a str)>,
    /// The same, for lookups.
    tag_set: HashSet<(&'a str, &'a str)>,
    /// Every FOR alias of the mission: a `BY` filter may name one from anywhere.
    aliases: HashSet<&'a str>,
    /// The names of the named SEQUENTIAL and PARALLEL blocks, which `Name ABORT` stops.
    blocks: Vec<&'a str>,
    /// What each name of the world means (see [`world_names`]).
    world_names: foldhash::HashMap<&'a str, Meaning>,
    /// Where the `OPERATOR SIGNAL` lines directly in the MISSION body start: those are
    /// in their place; any other is misplaced.
    top_level: HashSet<(u32, u32)>,
    /// Every LET of the mission or capability being checked, in source order: what a
    /// name that no scope binds is checked against (E133).
    lets: Vec<&'a Let>,
    /// The LETs of a body that its handler being checked cannot see, since the handler
    /// may fire before they are reached (E133).
    hidden: Vec<&'a Let>,
}

/// The world's names: a drone before a group of the same name, then places, then
/// areas, as [`Checker::lookup`] has always read them; a table, so that a lookup does
/// not scan every drone of a large world. Hashed with foldhash (seeded per process): a
/// quick hash for keys no attacker chooses, since the names come from the operator's own
/// world file.
fn world_names(w: &World) -> foldhash::HashMap<&str, Meaning> {
    let count = w.drones.len() + w.groups.len() + w.places.len() + w.areas.len() + w.lines.len();
    let mut names = foldhash::HashMap::with_capacity_and_hasher(count, Default::default());
    let drones = w.drones.iter().map(|d| (d.name.as_str(), Meaning::Drone));
    let groups = w.groups.iter().map(|g| (g.name.as_str(), Meaning::Group));
    let places = w.places.iter().map(|p| (p.name.as_str(), Meaning::Place));
    let areas = w.areas.iter().map(|a| (a.name.as_str(), Meaning::Area));
    let lines = w.lines.iter().map(|l| (l.name.as_str(), Meaning::Line));
    for (name, meaning) in drones.chain(groups).chain(places).chain(areas).chain(lines) {
        names.entry(name).or_insert(meaning);
    }
    names
}

impl<'a> Checker<'a> {
    fn is_user_file(&self, file: FileId) -> bool {
        self.program.files.first().map(|(f, _)| *f) != Some(file)
    }

    fn report(&mut self, code: Code, span: Span, message: impl Into<String>) -> &mut Diagnostic {
        let d = Diagnostic::new(code, self.file, span, message);
        self.diagnostics.push(d);
        let last = self.diagnostics.len() - 1;
        &mut self.diagnostics[last]
    }

    fn help(d: &mut Diagnostic, help: Option<String>) {
        if let Some(h) = help {
            d.help = Some(h);
        }
    }

    fn lookup(&self, name: &str) -> Meaning {
        for scope in self.scopes.iter().rev() {
            if let Some((_, b)) = scope.iter().rev().find(|(n, _)| *n == name) {
                return Meaning::Local(*b);
            }
        }
        self.world_names.get(name).copied().unwrap_or(Meaning::Unbound)
    }

    /// Whether an unbound name is known to be a mistake (not merely unknowable).
    fn names_are_known(&self) -> bool {
        self.world.is_some()
    }

    fn local_names(&self, want: impl Fn(&Binding) -> bool) -> Vec<&str> {
        self.scopes.iter().flatten().filter(|(_, b)| want(b)).map(|(n, _)| *n).collect()
    }

    fn actor_candidates(&self) -> Vec<&'a str> {
        let mut names: Vec<&str> = Vec::new();
        if let Some(w) = self.world {
            names.extend(w.drones.iter().map(|d| d.name.as_str()));
            names.extend(w.groups.iter().map(|g| g.name.as_str()));
        }
        names
    }

    fn capability_def(&mut self, c: &'a Capability) {
        self.capability = Some(c);
        let mut declared: Vec<&Ident> = Vec::new();
        for p in c.actors.iter().chain(&c.params) {
            if let Some(first) = declared.iter().find(|d| d.name == p.name) {
                let first = first.span;
                let file = self.file;
                let d = self.report(
                    Code::DuplicateParameter,
                    p.span,
                    format!("`{}` is declared twice in `{}`", p.name, c.name.name),
                );
                d.secondary.push(aviary_diagnostics::Label {
                    file,
                    span: first,
                    message: "first declared here".into(),
                });
                d.help = Some("give each actor and parameter of a capability its own name".into());
            }
            declared.push(p);
        }
        let kinds = self.program.param_kinds.get(&c.name.name).cloned().unwrap_or_default();
        let mut scope: Vec<(&str, Binding)> =
            c.actors.iter().map(|a| (a.name.as_str(), Binding::Actor)).collect();
        scope.extend(
            c.params
                .iter()
                .enumerate()
                .map(|(i, p)| (p.name.as_str(), Binding::Value(kinds.get(i).copied().flatten()))),
        );
        self.scopes.push(scope);
        self.lets = lets::all_lets(&capability_bodies(c));
        for section in &c.sections {
            match section {
                Section::Requirements { conditions, .. } => {
                    conditions.iter().for_each(|e| self.condition(e))
                }
                Section::Defaults { entries, .. } => {
                    for e in entries {
                        match c.params.iter().position(|p| p.name == e.name.name) {
                            Some(i) => {
                                let what = format!("the default of `{}`", e.name.name);
                                self.value(&e.value, kinds.get(i).copied().flatten(), &what);
                            }
                            None => {
                                let help = did_you_mean(&e.name.name, c.params.iter().map(|p| p.name.as_str()))
                                    .unwrap_or_else(|| format!("add `{}` to the parameters after WITH in the CAPABILITY header", e.name.name));
                                let d = self.report(
                                    Code::UnknownParameter,
                                    e.name.span,
                                    format!(
                                        "`{}` is not a parameter of `{}`",
                                        e.name.name, c.name.name
                                    ),
                                );
                                d.help = Some(help);
                            }
                        }
                    }
                }
                Section::Perform { body, .. } => self.body(body),
                Section::Exceptions { handlers, .. } => {
                    handlers.iter().for_each(|h| self.exception_handler(h))
                }
            }
        }
        self.scopes.pop();
        self.capability = None;
    }

    /// A body, in a scope of its own for the LETs it holds.
    fn body(&mut self, body: &'a Body) {
        self.scopes.push(Vec::new());
        // Whether every item so far takes no time (LETs, handlers): a LET then is
        // reached before anything in the body can raise a signal.
        let mut at_start = true;
        let mut late: Vec<&'a Let> = Vec::new();
        for stmt in &body.items {
            match stmt {
                Stmt::Let(l) => {
                    self.let_stmt(l);
                    if !at_start {
                        late.push(l);
                    }
                }
                Stmt::Handler(_) | Stmt::ExceptionHandler(_) if !late.is_empty() => {
                    let saved = self.hide(&late);
                    self.stmt(stmt);
                    self.unhide(saved);
                }
                Stmt::Handler(_)
                | Stmt::ExceptionHandler(_)
                | Stmt::OperatorSignals(_)
                | Stmt::Error(_) => self.stmt(stmt),
                Stmt::Block(_)
                | Stmt::Statement(_)
                | Stmt::Leash(_)
                | Stmt::Api(_)
                | Stmt::Requirement(_)
                | Stmt::For(_)
                | Stmt::Signal(_)
                | Stmt::Throw(_)
                | Stmt::If(_)
                | Stmt::Any(_)
                | Stmt::Allow(_)
                | Stmt::StopBlock(_) => {
                    at_start = false;
                    self.stmt(stmt);
                }
            }
        }
        self.scopes.pop();
    }

    fn stmt(&mut self, stmt: &'a Stmt) {
        match stmt {
            Stmt::Block(b) => self.body(&b.body),
            Stmt::Statement(s) => self.statement(s),
            Stmt::Leash(l) => self.leash(l),
            Stmt::Api(a) => self.api_call(a),
            Stmt::Requirement(r) => {
                self.condition(&r.condition);
                if let Some(b) = &r.body {
                    self.body(b);
                }
            }
            Stmt::For(f) => self.for_block(f),
            Stmt::Any(a) => self.any_block(a),
            Stmt::Signal(r) | Stmt::Throw(r) => r.args.iter().for_each(|a| {
                self.value(&a.value, None, "a value");
            }),
            Stmt::Handler(h) => {
                if let Some(by) = &h.by {
                    self.by_filter(by);
                }
                let values = self
                    .api
                    .signal(&h.signal.name)
                    .map(|s| s.values().to_vec())
                    .unwrap_or_default();
                let scope = h
                    .bindings
                    .iter()
                    .enumerate()
                    .map(|(i, b)| (b.name.as_str(), Binding::Value(values.get(i).map(|v| v.1))))
                    .collect();
                self.scopes.push(scope);
                self.body(&h.body);
                self.scopes.pop();
            }
            Stmt::ExceptionHandler(h) => self.exception_handler(h),
            Stmt::If(i) => {
                for (c, b) in &i.branches {
                    self.condition(c);
                    self.body(b);
                }
                if let Some(b) = &i.otherwise {
                    self.body(b);
                }
            }
            // Those directly in the MISSION body are checked by `operator_signals`.
            Stmt::OperatorSignals(o) if !self.top_level.contains(&(self.file.0, o.span.start)) => {
                let d = self.report(
                    Code::MisplacedItem,
                    o.span,
                    "OPERATOR SIGNAL declares the signals of the whole mission, and is allowed only directly in the MISSION body",
                );
                d.help = Some(format!(
                    "move `OPERATOR SIGNAL {}` to the MISSION body, indented by 4 spaces under `MISSION Name:`",
                    o.names.iter().map(|n| n.name.as_str()).collect::<Vec<_>>().join(", ")
                ));
            }
            Stmt::StopBlock(s) if !self.blocks.contains(&s.block.name.as_str()) => {
                let name = s.block.name.clone();
                let guess = did_you_mean(&name, self.blocks.iter().copied());
                let d = self.report(
                    Code::UnknownBlock,
                    s.block.span,
                    format!("no named SEQUENTIAL or PARALLEL block is called `{name}`"),
                );
                let help = "`Name ABORT` stops a block by its name, written `SEQUENTIAL Name:`; to stop an activity, tag its statement and write `Capability-Tag ABORT`";
                d.help = Some(match guess {
                    Some(g) => format!("{g} ({help})"),
                    None => help.to_string(),
                });
            }
            // Bound by `body`, which sees where in its body the LET stands.
            Stmt::Let(_) => {}
            // ALLOW lines are read by `crate::allow`.
            Stmt::OperatorSignals(_) | Stmt::Allow(_) | Stmt::StopBlock(_) | Stmt::Error(_) => {}
        }
    }

    /// The `OPERATOR SIGNAL` lines of the MISSION body: a built-in signal cannot be one
    /// (E130), and a name declared twice is said (W208).
    fn operator_signals(&mut self, body: &'a Body) {
        let mut seen: Vec<&Ident> = Vec::new();
        for stmt in &body.items {
            let Stmt::OperatorSignals(o) = stmt else { continue };
            self.top_level.insert((self.file.0, o.span.start));
            for name in &o.names {
                if self.api.signal(&name.name).is_some() {
                    let d = self.report(
                        Code::OperatorSignalBuiltin,
                        name.span,
                        format!("`{}` is a built-in signal, which only a drone raises", name.name),
                    );
                    d.help = Some(format!(
                        "handle it with `ON {} BY drone:`; for the operator, declare a signal of your own, such as `OPERATOR SIGNAL Operator_{}`",
                        name.name, name.name
                    ));
                    continue;
                }
                if let Some(first) = seen.iter().find(|s| s.name == name.name) {
                    let (file, first) = (self.file, first.span);
                    let d = self.report(
                        Code::OperatorSignalTwice,
                        name.span,
                        format!("`{}` is declared as an operator signal twice", name.name),
                    );
                    d.secondary.push(aviary_diagnostics::Label {
                        file,
                        span: first,
                        message: "first declared here".into(),
                    });
                    d.help = Some(format!("remove this `{}`: once is enough", name.name));
                    continue;
                }
                seen.push(name);
            }
        }
    }

    fn exception_handler(&mut self, h: &'a ExceptionHandler) {
        if let Some(by) = &h.by {
            self.by_filter(by);
        }
        self.scopes
            .push(h.bindings.iter().map(|b| (b.name.as_str(), Binding::Value(None))).collect());
        self.body(&h.body);
        self.scopes.pop();
    }

    fn for_block(&mut self, f: &'a ForBlock) {
        let mut kinds: Vec<Option<Kind>> = vec![None; f.params.len()];
        for inst in &f.instances {
            self.actor(&inst.actor);
            if inst.values.len() != f.params.len() {
                let names: Vec<&str> = f.params.iter().map(|p| p.name.as_str()).collect();
                let code = if inst.values.len() > f.params.len() {
                    Code::TooManyArguments
                } else {
                    Code::MissingArgument
                };
                let message = if names.is_empty() {
                    format!(
                        "`{}` is given {}, but the FOR names no parameters after its alias",
                        inst.actor.name,
                        count(inst.values.len(), "value")
                    )
                } else {
                    format!(
                        "`{}` is given {}, but the FOR names {} ({})",
                        inst.actor.name,
                        count(inst.values.len(), "value"),
                        count(f.params.len(), "parameter"),
                        names.join(", ")
                    )
                };
                let d = self.report(code, inst.span, message);
                d.help = Some(if names.is_empty() {
                    "name the parameters after the alias: `AS d WITH p:`".into()
                } else {
                    match names.as_slice() {
                        [one] => format!(
                            "give each instance a value for `{one}`: `{} WITH ...`",
                            inst.actor.name
                        ),
                        _ => format!(
                            "give each instance one value for each of {}, in that order",
                            quoted(&names)
                        ),
                    }
                });
            }
            for (i, v) in inst.values.iter().enumerate() {
                let k = self.value(v, None, "a value");
                if let Some(slot) = kinds.get_mut(i) {
                    if slot.is_none() {
                        *slot = k;
                    }
                }
            }
        }
        let mut scope = vec![(f.alias.name.as_str(), Binding::Actor)];
        scope.extend(f.params.iter().zip(kinds).map(|(p, k)| (p.name.as_str(), Binding::Value(k))));
        self.scopes.push(scope);
        self.body(&f.body);
        self.scopes.pop();
    }

    /// `ANY [k] d IN group WHERE c NEAREST TO p WITHIN t:`: the group is one of the world's,
    /// `k` a whole number it can give; `c` reads `d`, which the body holds.
    fn any_block(&mut self, a: &'a AnyBlock) {
        let size = self.any_group(&a.group);
        if let Some(k) = &a.count {
            let fits = match (&k.kind, size) {
                (ExprKind::Number { value, unit: None, .. }, size) => {
                    value.fract() == 0.0 && *value >= 1.0 && size.is_none_or(|n| *value <= n as f64)
                }
                _ => false,
            };
            if !fits {
                let group = &a.group.name;
                let d = self.report(
                    Code::AnyCount,
                    k.span,
                    match size {
                        Some(n) => format!(
                            "`{group}` has {}, so ANY can take from 1 to {n} of them",
                            count(n, "drone")
                        ),
                        None => "ANY takes a whole number of drones, 1 or more".into(),
                    },
                );
                d.help = Some(format!(
                    "write a plain whole number before the alias: `ANY 2 {} IN {group}:`",
                    a.alias.name
                ));
            }
        }
        if let Some(p) = &a.nearest {
            self.value(p, Some(Kind::Position), "the place after NEAREST TO");
        }
        if let Some(t) = &a.within {
            self.value(t, Some(Kind::Duration), "the time after WITHIN");
        }
        self.scopes.push(vec![(a.alias.name.as_str(), Binding::Actor)]);
        if let Some(c) = &a.condition {
            self.condition(c);
        }
        self.body(&a.body);
        self.scopes.pop();
    }

    /// The group an ANY chooses from: its size, when the world is known and it is one.
    fn any_group(&mut self, id: &Ident) -> Option<usize> {
        let what = match self.lookup(&id.name) {
            Meaning::Group => {
                return self.world.and_then(|w| w.group(&id.name)).map(|g| g.members.len())
            }
            Meaning::Unbound if !self.names_are_known() => return None,
            Meaning::Drone => "a drone, not a group: ANY chooses one drone of a group",
            Meaning::Local(_) => "an alias or a parameter, not a group of the world",
            Meaning::Place => "a place, not a group",
            Meaning::Area => "an area, not a group",
            Meaning::Line => "a line, not a group",
            Meaning::Unbound => "no group of the world",
        };
        let groups: Vec<&str> = self
            .world
            .map(|w| w.groups.iter().map(|g| g.name.as_str()).collect())
            .unwrap_or_default();
        let help = did_you_mean(&id.name, groups.iter().copied()).unwrap_or_else(|| {
            if groups.is_empty() {
                "declare the drones to choose from as a group in the world file: `[groups] couriers = [\"c1\", \"c2\"]`".into()
            } else {
                format!("the groups of the world are: {}", groups.join(", "))
            }
        });
        let d = self.report(Code::AnyNotGroup, id.span, format!("`{}` is {what}", id.name));
        d.help = Some(help);
        None
    }

    /// A name used as an actor: a drone, a group, an alias or a BY parameter.
    fn actor(&mut self, id: &Ident) {
        let what = match self.lookup(&id.name) {
            Meaning::Local(Binding::Actor) | Meaning::Drone | Meaning::Group => return,
            // A bound value of unknown kind may well hold a drone (`SIGNAL Here WITH d`).
            Meaning::Local(Binding::Value(None)) => return,
            Meaning::Local(Binding::Value(_)) => "a value, not a drone",
            Meaning::Place => "a place, not a drone",
            Meaning::Area => "an area, not a drone",
            Meaning::Line => "a line, not a drone",
            // Without a world, a name that no scope binds may still be a drone of the world.
            Meaning::Unbound if !self.names_are_known() => return,
            Meaning::Unbound => "no drone, group or alias",
        };
        let mut candidates = self.actor_candidates();
        candidates.extend(self.local_names(|b| *b == Binding::Actor));
        let help = did_you_mean(&id.name, candidates.iter().copied()).or_else(|| {
            (!candidates.is_empty())
                .then(|| format!("the actors here are: {}", candidates.join(", ")))
        });
        let d = self.report(Code::UnknownActor, id.span, format!("`{}` is {what}", id.name));
        Self::help(d, help);
    }

    /// `BY x`: an actor, a group, or any FOR alias of the mission.
    fn by_filter(&mut self, id: &Ident) {
        if self.aliases.contains(id.name.as_str()) {
            return;
        }
        self.actor(id);
    }
}

/// `1 argument`, `2 arguments`, `no arguments`.
fn count(n: usize, word: &str) -> String {
    match n {
        0 => format!("no {word}s"),
        1 => format!("1 {word}"),
        n => format!("{n} {word}s"),
    }
}

/// A short expression as written, for messages: `drone.battery`, `ELAPSED`, `25%`.
fn shown(e: &Expr) -> Option<String> {
    match &e.kind {
        ExprKind::Name(id) => Some(id.name.clone()),
        ExprKind::Path(a, f) => Some(format!("{}.{}", a.name, f.name)),
        ExprKind::Elapsed => Some("ELAPSED".into()),
        ExprKind::Number { digits, unit, .. } => {
            Some(format!("{digits}{}", unit.map_or("", |u| u.as_str())))
        }
        ExprKind::Received(id) => Some(format!("RECEIVED({})", id.name)),
        ExprKind::Distance(a, b) => Some(format!("distance({}, {})", shown(a)?, shown(b)?)),
        ExprKind::Paren(inner) => shown(inner).map(|s| format!("({s})")),
        ExprKind::String(_)
        | ExprKind::Bool(_)
        | ExprKind::Coordinates(_)
        | ExprKind::Geo(_)
        | ExprKind::Arith(..)
        | ExprKind::Offset(..)
        | ExprKind::Midpoint(..)
        | ExprKind::Not(_)
        | ExprKind::Binary(..)
        | ExprKind::Error => None,
    }
}

/// `` `a`, `b` `` for a list of names in a message.
fn quoted(names: &[&str]) -> String {
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}
