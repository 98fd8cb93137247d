//! The name, argument and kind checks: one walk over the mission and every capability.

use aviary_api::{Descriptor, Kind};
use aviary_diagnostics::{Code, Diagnostic, FileId, Span};
use aviary_syntax::ast::*;
use aviary_world::{AttributeValue, World};

use crate::env::*;
use crate::suggest::did_you_mean;
use crate::Program;

pub(crate) fn check_program(program: &Program, world: Option<&World>, api: &Descriptor, root: FileId, diagnostics: &mut Vec<Diagnostic>) {
    let mut tags = Vec::new();
    let mut aliases = Vec::new();
    for (_, tree) in &program.files {
        for item in &tree.items {
            let bodies = match item {
                Item::Mission(m) => vec![&m.body],
                Item::Capability(c) => capability_bodies(c),
                Item::Use(_) => vec![],
            };
            for body in bodies {
                visit_stmts(body, &mut |stmt| match stmt {
                    Stmt::Statement(Statement { capability, tag: Some(tag), .. }) => tags.push((capability.name.clone(), tag.name.clone())),
                    Stmt::For(f) => aliases.push(f.alias.name.clone()),
                    _ => {}
                });
            }
        }
    }
    let mut checker = Checker { program, world, api, diagnostics, file: root, capability: None, scopes: Vec::new(), tags, aliases };
    for (file, tree) in &program.files {
        checker.file = *file;
        for item in &tree.items {
            match item {
                Item::Mission(m) if program.mission().map(|x| x.span) == Some(m.span) => {
                    if world.is_none() {
                        let d = Diagnostic::new(Code::NoWorld, *file, m.name.span, "no world file, so actors, places and areas were not checked")
                            .with_help("put NAME.world.toml beside the mission, or pass `--world FILE`");
                        checker.diagnostics.push(d);
                    }
                    checker.capability = None;
                    checker.body(&m.body);
                }
                // Overridden library capabilities are never run, so never checked here.
                Item::Capability(c) if program.capabilities.get(&c.name.name).map(|r| r.file) == Some(*file) || checker.is_user_file(*file) => {
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
    scopes: Vec<Vec<(String, Binding)>>,
    /// Every `Capability-Tag` that some statement starts.
    tags: Vec<(String, String)>,
    /// Every FOR alias of the mission: a `BY` filter may name one from anywhere.
    aliases: Vec<String>,
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
            if let Some((_, b)) = scope.iter().rev().find(|(n, _)| n == name) {
                return Meaning::Local(*b);
            }
        }
        let Some(w) = self.world else { return Meaning::Unbound };
        if w.drone(name).is_some() {
            Meaning::Drone
        } else if w.group(name).is_some() {
            Meaning::Group
        } else if w.place(name).is_some() {
            Meaning::Place
        } else if w.area(name).is_some() {
            Meaning::Area
        } else {
            Meaning::Unbound
        }
    }

    /// Whether an unbound name is known to be a mistake (not merely unknowable).
    fn names_are_known(&self) -> bool {
        self.world.is_some()
    }

    fn local_names(&self, want: impl Fn(&Binding) -> bool) -> Vec<&str> {
        self.scopes.iter().flatten().filter(|(_, b)| want(b)).map(|(n, _)| n.as_str()).collect()
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
                self.report(Code::DuplicateParameter, p.span, format!("`{}` is declared twice in `{}`", p.name, c.name.name))
                    .secondary
                    .push(aviary_diagnostics::Label { file, span: first, message: "first declared here".into() });
            }
            declared.push(p);
        }
        let kinds = self.program.param_kinds.get(&c.name.name).cloned().unwrap_or_default();
        let mut scope: Vec<(String, Binding)> = c.actors.iter().map(|a| (a.name.clone(), Binding::Actor)).collect();
        scope.extend(c.params.iter().enumerate().map(|(i, p)| (p.name.clone(), Binding::Value(kinds.get(i).copied().flatten()))));
        self.scopes.push(scope);
        for section in &c.sections {
            match section {
                Section::Requirements { conditions, .. } => conditions.iter().for_each(|e| self.condition(e)),
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
                                let d = self.report(Code::UnknownParameter, e.name.span, format!("`{}` is not a parameter of `{}`", e.name.name, c.name.name));
                                d.help = Some(help);
                            }
                        }
                    }
                }
                Section::Perform { body, .. } => self.body(body),
                Section::Exceptions { handlers, .. } => handlers.iter().for_each(|h| self.exception_handler(h)),
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
                let values = self.api.signal(&h.signal.name).map(|s| s.values.clone()).unwrap_or_default();
                let scope = h.bindings.iter().enumerate().map(|(i, b)| (b.name.clone(), Binding::Value(values.get(i).map(|v| v.1)))).collect();
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
        self.scopes.push(h.bindings.iter().map(|b| (b.name.clone(), Binding::Value(None))).collect());
        self.body(&h.body);
        self.scopes.pop();
    }

    fn for_block(&mut self, f: &'a ForBlock) {
        let mut kinds: Vec<Option<Kind>> = vec![None; f.params.len()];
        for inst in &f.instances {
            self.actor(&inst.actor);
            if inst.values.len() != f.params.len() {
                let names: Vec<&str> = f.params.iter().map(|p| p.name.as_str()).collect();
                let code = if inst.values.len() > f.params.len() { Code::TooManyArguments } else { Code::MissingArgument };
                let d = self.report(code, inst.span, format!("this instance gives {} value(s) for {} parameter(s)", inst.values.len(), f.params.len()));
                d.help = Some(if names.is_empty() {
                    "name the parameters after the alias: `AS d WITH p:`".into()
                } else {
                    format!("give one value for each of {}", names.join(", "))
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
        let mut scope = vec![(f.alias.name.clone(), Binding::Actor)];
        scope.extend(f.params.iter().zip(kinds).map(|(p, k)| (p.name.clone(), Binding::Value(k))));
        self.scopes.push(scope);
        self.body(&f.body);
        self.scopes.pop();
    }

    /// A name used as an actor: a drone, a group, an alias or a BY parameter.
    fn actor(&mut self, id: &Ident) {
        let what = match self.lookup(&id.name) {
            Meaning::Local(Binding::Actor) | Meaning::Drone | Meaning::Group => return,
            Meaning::Local(Binding::Value(_)) => "a value, not a drone",
            Meaning::Place => "a place, not a drone",
            Meaning::Area => "an area, not a drone",
            Meaning::Unbound if !self.names_are_known() && self.capability.is_none() => return,
            Meaning::Unbound => "no drone, group or alias",
        };
        let mut candidates = self.actor_candidates();
        candidates.extend(self.local_names(|b| *b == Binding::Actor));
        let help = did_you_mean(&id.name, candidates.iter().copied()).or_else(|| {
            (!candidates.is_empty()).then(|| format!("the actors here are: {}", candidates.join(", ")))
        });
        let d = self.report(Code::UnknownActor, id.span, format!("`{}` is {what}", id.name));
        Self::help(d, help);
    }

    /// `BY x`: an actor, a group, or any FOR alias of the mission.
    fn by_filter(&mut self, id: &Ident) {
        if self.aliases.contains(&id.name) {
            return;
        }
        self.actor(id);
    }

    fn statement(&mut self, s: &'a Statement) {
        let Some(cap) = self.program.capability(&s.capability.name) else {
            // The paper's `drone FlyTo Body_Beacon_Inventory`: the arguments lack WITH.
            if let Some(i) = s.actors.iter().rposition(|a| self.program.capability(&a.name).is_some()) {
                let real = &s.actors[i];
                let actors: Vec<&str> = s.actors[..i].iter().map(|a| a.name.as_str()).collect();
                let rest: Vec<&str> = s.actors[i + 1..].iter().map(|a| a.name.as_str()).chain([s.capability.name.as_str()]).collect();
                let span = s.actors[i + 1..].first().map_or(s.capability.span, |a| a.span).to(s.capability.span);
                let all: Vec<&str> = s.actors.iter().map(|a| a.name.as_str()).collect();
                let d = self.report(
                    Code::ArgumentsWithoutWith,
                    span,
                    format!("this reads as actors `{}` and capability `{}`", all.join(" "), s.capability.name),
                );
                d.help = Some(format!("arguments follow WITH: write `{} {} WITH {}`", actors.join(" "), real.name, rest.join(", ")));
                return;
            }
            let help = did_you_mean(&s.capability.name, self.program.capabilities.keys().map(String::as_str))
                .unwrap_or_else(|| "define it with `CAPABILITY Name BY drone:`, or USE the file that does".into());
            let d = self.report(Code::UnknownCapability, s.capability.span, format!("no capability is called `{}`", s.capability.name));
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
                format!("`{}` takes {} actors (BY {}), this statement names {}", cap.name.name, by.len(), by.join(", "), s.actors.len()),
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
                            format!("the parameters of `{}` are {}", cap.name.name, params.join(", "))
                        }
                    });
                    let d = self.report(Code::UnknownArgument, n.span, format!("`{}` has no parameter `{}`", cap.name.name, n.name));
                    d.help = Some(help);
                }
                BindProblem::Twice(n) => {
                    let d = self.report(Code::DuplicateArgument, n.span, format!("`{}` is given twice", n.name));
                    d.help = Some("give each parameter one argument".into());
                }
                BindProblem::TooMany(e) => {
                    let d = self.report(Code::TooManyArguments, e.span, format!("`{}` takes {} argument(s), this is one more", cap.name.name, params.len()));
                    d.help = Some(if params.is_empty() { "remove the arguments".into() } else { format!("its parameters are {}", params.join(", ")) });
                }
            }
        }
        for (i, value) in binding.bound.iter().enumerate() {
            if let Some(v) = value {
                let what = format!("`{}`'s `{}`", cap.name.name, params[i]);
                self.value(v, kinds.get(i).copied().flatten(), &what);
            }
        }
        if !need_all {
            return;
        }
        let defaults: Vec<&str> = cap
            .sections
            .iter()
            .filter_map(|s| match s {
                Section::Defaults { entries, .. } => Some(entries.iter().map(|e| e.name.name.as_str())),
                _ => None,
            })
            .flatten()
            .collect();
        for (i, p) in params.iter().enumerate() {
            if binding.bound[i].is_none() && !defaults.contains(p) {
                let example = kinds.get(i).copied().flatten().map_or("...", |k| k.example());
                let d = self.report(Code::MissingArgument, at, format!("`{}` needs an argument for `{p}`", cap.name.name));
                d.help = Some(format!("add `{p}={example}` after WITH, or give `{p}` a default in the capability's DEFAULTS"));
            }
        }
    }

    fn leash(&mut self, l: &'a LeashCall) {
        let tagged = format!("{}-{}", l.capability.name, l.tag.name);
        if !self.tags.iter().any(|(c, t)| *c == l.capability.name && *t == l.tag.name) {
            let known: Vec<String> = self.tags.iter().map(|(c, t)| format!("{c}-{t}")).collect();
            let help = did_you_mean(&tagged, known.iter().map(String::as_str))
                .unwrap_or_else(|| format!("tag the statement that starts the activity: `drone {tagged} WITH ...`"));
            let span = l.capability.span.to(l.tag.span);
            let d = self.report(Code::UnknownTag, span, format!("no statement starts an activity tagged `{tagged}`"));
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
        if !builtin.contains(&l.action.name.as_str()) && !sections.contains(&l.action.name.as_str()) {
            let all: Vec<&str> = builtin.iter().copied().chain(sections.iter().copied().filter(|s| !builtin.contains(s))).collect();
            let help = did_you_mean(&l.action.name, all.iter().copied()).unwrap_or_else(|| format!("`{}` can be told: {}", cap.name.name, all.join(", ")));
            let d = self.report(Code::UnknownLeashSection, l.action.span, format!("`{}` has no section `PERFORM {}`", cap.name.name, l.action.name));
            d.help = Some(help);
        }
        self.arguments(cap, &l.args, l.action.span, false);
    }

    fn api_call(&mut self, call: &'a ApiCall) {
        let Some(cap) = self.capability else {
            let d = self.report(
                Code::ApiCallOutsideCapability,
                call.span,
                format!("`{}.{}(...)` calls the middle layer, which only capabilities may do", call.actor.name, call.function.name),
            );
            d.help = Some(format!(
                "call a capability instead (`{} {}`), or put this call in a CAPABILITY's PERFORM section",
                call.actor.name, call.function.name
            ));
            return;
        };
        if !matches!(self.lookup(&call.actor.name), Meaning::Local(Binding::Actor)) {
            let actors: Vec<&str> = cap.actors.iter().map(|a| a.name.as_str()).collect();
            let d = self.report(Code::ApiCallOnNonActor, call.actor.span, format!("`{}` is not an actor of `{}`", call.actor.name, cap.name.name));
            d.help = Some(format!("call the API on the capability's actor: `{}.{}(...)`", actors.first().unwrap_or(&"drone"), call.function.name));
        }
        let Some(f) = self.api.function(&call.function.name) else {
            let help = did_you_mean(&call.function.name, self.api.functions.iter().map(|f| f.name))
                .unwrap_or_else(|| "the middle-layer functions are listed in docs/LANGUAGE.md".into());
            let d = self.report(Code::UnknownApiFunction, call.function.span, format!("the middle layer has no function `{}`", call.function.name));
            d.help = Some(help);
            return;
        };
        let n = call.args.len();
        if n < f.required() {
            let d = self.report(Code::MissingArgument, call.span, format!("`{}` needs {} argument(s), this call gives {n}", f.name, f.required()));
            d.help = Some(format!("call it as `{}.{}`", call.actor.name, f.signature()));
        } else if n > f.params.len() && !f.variadic {
            let extra = call.args[f.params.len()].span;
            let d = self.report(Code::TooManyArguments, extra, format!("`{}` takes at most {} argument(s), this call gives {n}", f.name, f.params.len()));
            d.help = Some(format!("call it as `{}.{}`", call.actor.name, f.signature()));
        }
        for (j, arg) in call.args.iter().enumerate() {
            let p = f.params.get(j).or(if f.variadic { f.params.last() } else { None });
            let what = p.map_or(format!("`{}`'s argument", f.name), |p| format!("`{}`'s `{}`", f.name, p.name));
            self.value(arg, p.map(|p| p.kind), &what);
        }
    }

    fn condition(&mut self, e: &'a Expr) {
        let k = self.value(e, None, "a condition");
        if let Some(k) = k {
            if k != Kind::Bool {
                let d = self.report(Code::WrongKind, e.span, format!("a condition must be true or false, and this is {}", k.describe()));
                d.help = Some("compare it with something: `drone.battery > 25%`, `type = Body`".into());
            }
        }
    }

    /// The kind of a value, checked against `expected` when given. Reports what is wrong.
    fn value(&mut self, e: &'a Expr, expected: Option<Kind>, what: &str) -> Option<Kind> {
        let actual = self.kind_of(e);
        let (Some(expected), Some(actual)) = (expected, actual) else { return actual };
        if expected.accepts(actual) {
            return Some(actual);
        }
        if let ExprKind::Name(id) = &e.kind {
            if actual == Kind::Symbol && matches!(expected, Kind::Position | Kind::Area) {
                let noun = if expected == Kind::Area { "area" } else { "place" };
                let candidates: Vec<&str> = self.world.map_or(Vec::new(), |w| {
                    let areas = w.areas.iter().map(|a| a.name.as_str());
                    if expected == Kind::Area {
                        areas.collect()
                    } else {
                        w.places.iter().map(|p| p.name.as_str()).chain(areas).collect()
                    }
                });
                let help = did_you_mean(&id.name, candidates.iter().copied())
                    .unwrap_or_else(|| format!("define it in the world file's [{noun}s], or use coordinates such as (100, 50)"));
                let d = self.report(Code::UnknownPlace, id.span, format!("unknown {noun} `{}`", id.name));
                d.help = Some(help);
                return Some(actual);
            }
        }
        if actual == Kind::Number {
            if let (Some(unit), ExprKind::Number { digits, .. }) = (unit_for(expected), &e.kind) {
                let d = self.report(Code::WrongKind, e.span, format!("`{digits}` has no unit, and {what} is {}", expected.describe()));
                d.help = Some(format!("write `{digits}{unit}`"));
                return Some(actual);
            }
        }
        let d = self.report(Code::WrongKind, e.span, format!("{what} is {}, but this is {}", expected.describe(), actual.describe()));
        d.primary.message = format!("expected {}", expected.describe());
        d.help = Some(format!("write {}, such as `{}`", expected.describe(), expected.example()));
        Some(actual)
    }

    fn kind_of(&mut self, e: &'a Expr) -> Option<Kind> {
        match &e.kind {
            ExprKind::Name(id) => match self.lookup(&id.name) {
                Meaning::Local(Binding::Actor) | Meaning::Drone | Meaning::Group => Some(Kind::Actor),
                Meaning::Local(Binding::Value(k)) => k,
                Meaning::Place => Some(Kind::Position),
                Meaning::Area => Some(Kind::Area),
                Meaning::Unbound if self.names_are_known() => Some(Kind::Symbol),
                Meaning::Unbound => None,
            },
            ExprKind::Path(a, field) => self.path(a, field),
            ExprKind::Coordinates(parts) => {
                for p in parts {
                    if let Some(k) = self.kind_of(p) {
                        if !matches!(k, Kind::Number | Kind::Length) {
                            let d = self.report(Code::WrongKind, p.span, format!("a coordinate is a number of metres, and this is {}", k.describe()));
                            d.help = Some("write coordinates as `(x, y)` or `(x, y, z)` in metres".into());
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
                self.value(a, Some(Kind::Position), "`distance`'s first place");
                self.value(b, Some(Kind::Position), "`distance`'s second place");
                Some(Kind::Length)
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
                    // A symbol on the left (`x = Hoem` reads fine either way): check the right against it.
                    Some(k) => {
                        let what = format!("the other side of `{}`", op.as_str());
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
            _ => literal_kind(e),
        }
    }

    /// `a.field`: telemetry, or an attribute from the world file.
    fn path(&mut self, a: &'a Ident, field: &'a Ident) -> Option<Kind> {
        self.actor(a);
        if let Some(k) = self.api.telemetry(&field.name) {
            return Some(k);
        }
        let world = self.world?;
        let found = world.drones.iter().find_map(|d| d.attributes.iter().find(|(k, _)| *k == field.name).map(|(_, v)| v));
        match found {
            Some(AttributeValue::Number(_)) => Some(Kind::Number),
            Some(AttributeValue::Text(_)) => Some(Kind::Text),
            Some(AttributeValue::Bool(_)) => Some(Kind::Bool),
            Some(AttributeValue::Other(_)) => None,
            None => {
                let mut names: Vec<&str> = self.api.telemetry.iter().map(|(n, _)| *n).collect();
                for d in &world.drones {
                    names.extend(d.attributes.iter().map(|(k, _)| k.as_str()));
                }
                names.sort_unstable();
                names.dedup();
                let help = did_you_mean(&field.name, names.iter().copied()).unwrap_or_else(|| format!("telemetry and attributes: {}", names.join(", ")));
                let d = self.report(Code::UnknownTelemetry, field.span, format!("`{}` is no telemetry field and no attribute of `{}`", field.name, a.name));
                d.help = Some(help);
                None
            }
        }
    }
}
