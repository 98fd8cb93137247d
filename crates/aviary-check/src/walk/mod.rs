//! The name, argument and kind checks: one walk over the mission and every capability.

use std::collections::HashSet;

use aviary_api::{Descriptor, Kind};
use aviary_diagnostics::{Code, Diagnostic, FileId, Span};
use aviary_syntax::ast::*;
use aviary_world::World;

use crate::env::*;
use crate::suggest::did_you_mean;
use crate::Program;

mod kinds;

pub(crate) fn check_program(
    program: &Program,
    world: Option<&World>,
    api: &Descriptor,
    root: FileId,
    diagnostics: &mut Vec<Diagnostic>,
) {
    let mut tags = Vec::new();
    let mut aliases = HashSet::new();
    for (_, tree) in &program.files {
        for item in &tree.items {
            let bodies = match item {
                Item::Mission(m) => vec![&m.body],
                Item::Capability(c) => capability_bodies(c),
                Item::Use(_) => vec![],
            };
            for body in bodies {
                visit_stmts(body, &mut |stmt| match stmt {
                    Stmt::Statement(Statement { capability, tag: Some(tag), .. }) => {
                        tags.push((capability.name.as_str(), tag.name.as_str()))
                    }
                    Stmt::For(f) => {
                        aliases.insert(f.alias.name.as_str());
                    }
                    _ => {}
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
        world_names,
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
                    checker.body(&m.body);
                }
                // Overridden library capabilities are never run, so never checked here.
                Item::Capability(c)
                    if program.is_active(*file, c) || checker.is_user_file(*file) =>
                {
                    checker.capability_def(c);
                }
                _ => {}
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
    /// What each name of the world means (see [`world_names`]).
    world_names: foldhash::HashMap<&'a str, Meaning>,
}

/// The world's names: a drone before a group of the same name, then places, then
/// areas, as [`Checker::lookup`] has always read them; a table, so that a lookup does
/// not scan every drone of a large world. Hashed with foldhash (seeded per process):
/// SipHash was most of building it for 100,000 drones.
fn world_names(w: &World) -> foldhash::HashMap<&str, Meaning> {
    let count = w.drones.len() + w.groups.len() + w.places.len() + w.areas.len();
    let mut names = foldhash::HashMap::with_capacity_and_hasher(count, Default::default());
    let drones = w.drones.iter().map(|d| (d.name.as_str(), Meaning::Drone));
    let groups = w.groups.iter().map(|g| (g.name.as_str(), Meaning::Group));
    let places = w.places.iter().map(|p| (p.name.as_str(), Meaning::Place));
    let areas = w.areas.iter().map(|a| (a.name.as_str(), Meaning::Area));
    for (name, meaning) in drones.chain(groups).chain(places).chain(areas) {
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

    fn body(&mut self, body: &'a Body) {
        for stmt in &body.items {
            self.stmt(stmt);
        }
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
            Stmt::Error(_) => {}
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

    /// A name used as an actor: a drone, a group, an alias or a BY parameter.
    fn actor(&mut self, id: &Ident) {
        let what = match self.lookup(&id.name) {
            Meaning::Local(Binding::Actor) | Meaning::Drone | Meaning::Group => return,
            // A bound value of unknown kind may well hold a drone (`SIGNAL Here WITH d`).
            Meaning::Local(Binding::Value(None)) => return,
            Meaning::Local(Binding::Value(_)) => "a value, not a drone",
            Meaning::Place => "a place, not a drone",
            Meaning::Area => "an area, not a drone",
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

    fn statement(&mut self, s: &'a Statement) {
        let Some(cap) = self.program.capability(&s.capability.name) else {
            // The paper's `drone FlyTo Body_Beacon_Inventory`: the arguments lack WITH.
            if let Some(i) =
                s.actors.iter().rposition(|a| self.program.capability(&a.name).is_some())
            {
                let real = &s.actors[i];
                let actors: Vec<&str> = s.actors[..i].iter().map(|a| a.name.as_str()).collect();
                let rest: Vec<&str> = s.actors[i + 1..]
                    .iter()
                    .map(|a| a.name.as_str())
                    .chain([s.capability.name.as_str()])
                    .collect();
                let span = s.actors[i + 1..]
                    .first()
                    .map_or(s.capability.span, |a| a.span)
                    .to(s.capability.span);
                let all: Vec<&str> = s.actors.iter().map(|a| a.name.as_str()).collect();
                let d = self.report(
                    Code::ArgumentsWithoutWith,
                    span,
                    format!(
                        "this reads as actors `{}` and capability `{}`",
                        all.join(" "),
                        s.capability.name
                    ),
                );
                let more = if s.args.is_empty() { "" } else { ", ..." };
                d.help = Some(format!(
                    "arguments follow WITH: write `{} {} WITH {}{more}`",
                    actors.join(" "),
                    real.name,
                    rest.join(", ")
                ));
                return;
            }
            let help = did_you_mean(&s.capability.name, self.program.capability_names())
                .unwrap_or_else(|| match self.program.unreadable.as_slice() {
                    [] => "define it with `CAPABILITY Name BY drone:`, or USE the file that does"
                        .into(),
                    [one] => format!("it may be defined in `{one}`, which could not be read"),
                    many => format!(
                        "it may be defined in one of {}, which could not be read",
                        many.iter().map(|m| format!("`{m}`")).collect::<Vec<_>>().join(", ")
                    ),
                });
            // The last name is something else of the world: say what, and what is missing.
            let actors: Vec<&str> = s.actors.iter().map(|a| a.name.as_str()).collect();
            let all = format!("{} {}", actors.join(" "), s.capability.name);
            let fly_there = format!(
                "to fly there, write `{} FlyTo WITH {}`",
                actors.join(" "),
                s.capability.name
            );
            let names_no_capability =
                format!("a statement ends with the capability: `{all} FlyTo WITH ...`");
            let what = match self.lookup(&s.capability.name) {
                Meaning::Drone => Some(("a drone, not a capability", names_no_capability)),
                Meaning::Group => {
                    Some(("a group of drones, not a capability", names_no_capability))
                }
                Meaning::Local(Binding::Actor) => {
                    Some(("an actor, not a capability", names_no_capability))
                }
                Meaning::Place => Some(("a place, not a capability", fly_there)),
                Meaning::Area => Some(("an area, not a capability", fly_there)),
                _ => None,
            };
            if let Some((what, help)) = what {
                let d = self.report(
                    Code::UnknownCapability,
                    s.capability.span,
                    format!("`{}` is {what}", s.capability.name),
                );
                d.help = Some(help);
                return;
            }
            let d = self.report(
                Code::UnknownCapability,
                s.capability.span,
                format!("no capability is called `{}`", s.capability.name),
            );
            d.help = Some(help);
            return;
        };
        for a in &s.actors {
            self.actor(a);
        }
        if cap.actors.len() > 1 && s.actors.len() != cap.actors.len() {
            let by: Vec<&str> = cap.actors.iter().map(|a| a.name.as_str()).collect();
            let span = s.actors.first().map_or(s.span, |a| a.span).to(s.capability.span);
            let d = self.report(
                Code::ActorCount,
                span,
                format!(
                    "`{}` takes {} actors (BY {}), this statement names {}",
                    cap.name.name,
                    by.len(),
                    by.join(", "),
                    s.actors.len()
                ),
            );
            d.help = Some(format!("name one actor for each of {}", by.join(", ")));
        }
        self.arguments(cap, &s.args, s.capability.span, true);
    }

    fn arguments(&mut self, cap: &'a Capability, args: &'a [Arg], at: Span, need_all: bool) {
        let kinds = self.program.param_kinds.get(&cap.name.name).cloned().unwrap_or_default();
        let binding = bind_args(&cap.params, args);
        let params: Vec<&str> = cap.params.iter().map(|p| p.name.as_str()).collect();
        for problem in &binding.problems {
            match problem {
                BindProblem::UnknownName(n) => {
                    let help = did_you_mean(&n.name, params.iter().copied()).unwrap_or_else(|| {
                        if params.is_empty() {
                            format!("`{}` takes no arguments", cap.name.name)
                        } else {
                            format!(
                                "the parameters of `{}` are {}",
                                cap.name.name,
                                params.join(", ")
                            )
                        }
                    });
                    let d = self.report(
                        Code::UnknownArgument,
                        n.span,
                        format!("`{}` has no parameter `{}`", cap.name.name, n.name),
                    );
                    d.help = Some(help);
                }
                BindProblem::Twice(n) => {
                    // The first argument stays bound; the second is the one reported.
                    let first = params
                        .iter()
                        .position(|p| *p == n.name)
                        .and_then(|i| binding.bound[i])
                        .map(|e| e.span);
                    let file = self.file;
                    let d = self.report(
                        Code::DuplicateArgument,
                        n.span,
                        format!("`{}` is given twice", n.name),
                    );
                    if let Some(span) = first {
                        d.secondary.push(aviary_diagnostics::Label {
                            file,
                            span,
                            message: format!("`{}` is already given here", n.name),
                        });
                    }
                    d.help = Some("give each parameter one argument; positional arguments fill the parameters in order".into());
                }
                BindProblem::TooMany(e) => {
                    let message = if params.is_empty() {
                        format!("`{}` takes no arguments", cap.name.name)
                    } else {
                        format!(
                            "`{}` takes {}, and this is one too many",
                            cap.name.name,
                            count(params.len(), "argument")
                        )
                    };
                    let d = self.report(Code::TooManyArguments, e.span, message);
                    d.help = Some(if params.is_empty() {
                        "remove the arguments".into()
                    } else {
                        format!("its parameters are {}", quoted(&params))
                    });
                }
            }
        }
        for (i, value) in binding.bound.iter().enumerate() {
            if let Some(v) = value {
                let what = format!("`{}`'s `{}`", cap.name.name, params[i]);
                let before = self.diagnostics.len();
                self.value(v, kinds.get(i).copied().flatten(), &what);
                if self.diagnostics.len() > before
                    && self.diagnostics[before].code == Code::WrongKind
                {
                    let chain = self.kind_chain(&cap.name.name, i);
                    self.diagnostics[before].secondary.extend(chain);
                }
            }
        }
        if !need_all {
            return;
        }
        let defaults: Vec<&str> = cap
            .sections
            .iter()
            .filter_map(|s| match s {
                Section::Defaults { entries, .. } => {
                    Some(entries.iter().map(|e| e.name.name.as_str()))
                }
                _ => None,
            })
            .flatten()
            .collect();
        for (i, p) in params.iter().enumerate() {
            if binding.bound[i].is_none() && !defaults.contains(p) {
                let example = kinds.get(i).copied().flatten().map_or("...", |k| k.example());
                let d = self.report(
                    Code::MissingArgument,
                    at,
                    format!("`{}` needs an argument for `{p}`", cap.name.name),
                );
                d.help = Some(format!("add `{p}={example}` after WITH, or give `{p}` a default in the capability's DEFAULTS"));
            }
        }
    }

    /// The uses that fixed the kind of `capability`'s parameter `index`, outermost first,
    /// through the capabilities it is passed on to.
    fn kind_chain(&self, capability: &str, index: usize) -> Vec<aviary_diagnostics::Label> {
        let mut labels = Vec::new();
        let mut at = Some((capability.to_string(), index));
        while let Some((cap, i)) = at.take() {
            let origin =
                self.program.param_origins.get(&cap).and_then(|o| o.get(i)).cloned().flatten();
            let (Some(origin), Some(file)) = (origin, self.program.capability_file(&cap)) else {
                break;
            };
            labels.push(aviary_diagnostics::Label { file, span: origin.span, message: origin.why });
            // Bounded: a chain never passes through more capabilities than there are.
            if labels.len() > self.program.capability_count() {
                break;
            }
            at = origin.from;
        }
        labels
    }

    fn leash(&mut self, l: &'a LeashCall) {
        let tagged = format!("{}-{}", l.capability.name, l.tag.name);
        if !self.tag_set.contains(&(l.capability.name.as_str(), l.tag.name.as_str())) {
            let known: Vec<String> = self.tags.iter().map(|(c, t)| format!("{c}-{t}")).collect();
            let help =
                did_you_mean(&tagged, known.iter().map(String::as_str)).unwrap_or_else(|| {
                    format!("tag the statement that starts the activity: `drone {tagged} WITH ...`")
                });
            let span = l.capability.span.to(l.tag.span);
            let d = self.report(
                Code::UnknownTag,
                span,
                format!("no statement starts an activity tagged `{tagged}`"),
            );
            d.help = Some(help);
        }
        let Some(cap) = self.program.capability(&l.capability.name) else { return };
        let sections: Vec<&str> = cap
            .sections
            .iter()
            .filter_map(|s| match s {
                Section::Perform { name: Some(n), .. } => Some(n.name.as_str()),
                _ => None,
            })
            .collect();
        let builtin = ["ABORT", "PAUSE", "RESUME"];
        if !builtin.contains(&l.action.name.as_str()) && !sections.contains(&l.action.name.as_str())
        {
            let all: Vec<&str> = builtin
                .iter()
                .copied()
                .chain(sections.iter().copied().filter(|s| !builtin.contains(s)))
                .collect();
            let help = did_you_mean(&l.action.name, all.iter().copied())
                .unwrap_or_else(|| format!("`{}` can be told: {}", cap.name.name, all.join(", ")));
            let d = self.report(
                Code::UnknownLeashSection,
                l.action.span,
                format!("`{}` has no section `PERFORM {}`", cap.name.name, l.action.name),
            );
            d.help = Some(help);
        }
        self.arguments(cap, &l.args, l.action.span, false);
    }

    fn api_call(&mut self, call: &'a ApiCall) {
        let Some(cap) = self.capability else {
            let d = self.report(
                Code::ApiCallOutsideCapability,
                call.span,
                format!(
                    "`{}.{}(...)` calls the middle layer, which only capabilities may do",
                    call.actor.name, call.function.name
                ),
            );
            d.help = Some(format!(
                "call a capability instead (`{} {}`), or put this call in a CAPABILITY's PERFORM section",
                call.actor.name, call.function.name
            ));
            return;
        };
        if !matches!(self.lookup(&call.actor.name), Meaning::Local(Binding::Actor)) {
            let actors: Vec<&str> = cap.actors.iter().map(|a| a.name.as_str()).collect();
            let d = self.report(
                Code::ApiCallOnNonActor,
                call.actor.span,
                format!("`{}` is not an actor of `{}`", call.actor.name, cap.name.name),
            );
            d.help = Some(format!(
                "call the API on the capability's actor: `{}.{}(...)`",
                actors.first().unwrap_or(&"drone"),
                call.function.name
            ));
        }
        let Some(f) = self.api.function(&call.function.name) else {
            let names: Vec<&str> = self.api.functions.iter().map(|f| f.name()).collect();
            let help = did_you_mean(&call.function.name, names.iter().copied())
                .or_else(|| {
                    same_start(&call.function.name, names.iter().copied())
                        .map(|c| format!("did you mean `{c}`?"))
                })
                .unwrap_or_else(|| {
                    format!("the middle layer's functions are {}", names.join(", "))
                });
            let d = self.report(
                Code::UnknownApiFunction,
                call.function.span,
                format!("the middle layer has no function `{}`", call.function.name),
            );
            d.help = Some(help);
            return;
        };
        let n = call.args.len();
        if n < f.required() {
            let d = self.report(
                Code::MissingArgument,
                call.span,
                format!(
                    "`{}` needs {}, and this call gives {}",
                    f.name(),
                    count(f.required(), "argument"),
                    count_bare(n)
                ),
            );
            d.help = Some(format!("call it as `{}.{}`", call.actor.name, f.signature()));
        } else if n > f.params.len() && !f.variadic {
            let extra = call.args[f.params.len()].span;
            let message = if f.params.is_empty() {
                format!("`{}` takes no arguments", f.name())
            } else {
                format!(
                    "`{}` takes at most {}, and this call gives {n}",
                    f.name(),
                    count(f.params.len(), "argument")
                )
            };
            let d = self.report(Code::TooManyArguments, extra, message);
            d.help = Some(format!("call it as `{}.{}`", call.actor.name, f.signature()));
        }
        for (j, arg) in call.args.iter().enumerate() {
            let p = f.params.get(j).or(if f.variadic { f.params.last() } else { None });
            let what = p.map_or(format!("`{}`'s argument", f.name()), |p| {
                format!("`{}`'s `{}`", f.name(), p.name)
            });
            self.value(arg, p.map(|p| p.kind), &what);
        }
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

/// `none`, or the number.
fn count_bare(n: usize) -> String {
    if n == 0 {
        "none".into()
    } else {
        n.to_string()
    }
}

/// A candidate that starts with `name`, or with which `name` starts (`FlyToPos` for
/// `FlyToPosition`), ignoring case; only for names long enough to mean something.
fn same_start<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let lower = name.to_ascii_lowercase();
    if lower.len() < 4 {
        return None;
    }
    candidates
        .into_iter()
        .filter(|c| {
            let c = c.to_ascii_lowercase();
            c.len() >= 4 && (c.starts_with(&lower) || lower.starts_with(&c))
        })
        .min_by_key(|c| (c.len().abs_diff(name.len()), c.to_string()))
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
        _ => None,
    }
}

/// `` `a`, `b` `` for a list of names in a message.
fn quoted(names: &[&str]) -> String {
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}
