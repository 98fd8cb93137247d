//! From a checked program to the IR.

use std::collections::BTreeMap;

use aviary_api::{
    arith, BuiltinException, BuiltinLeash, BuiltinSignal, Descriptor, DroneId, Function,
    FunctionCall, Point, Value,
};
use aviary_check::{bind_args, Program};
use aviary_diagnostics::FileId;
use aviary_syntax::ast;
use aviary_world::{AttributeValue, World};

use aviary_ir::*;

/// Compiles the checked `program` for the fleet of `world`. `None` when the program
/// holds no MISSION (a library of capabilities has nothing to run), or something the
/// checker refuses (compile only a program without errors).
pub fn compile(program: &Program, world: &World) -> Option<Mission> {
    let api = Descriptor::standard();
    let mission = program.mission()?;
    let mission_file = program.mission.map(|r| r.file).unwrap_or_default();
    let mut c = Compiler::new(program, world, api);
    c.collect_aliases(&mission.body);
    let actives: Vec<(FileId, &ast::Capability)> = program.active_capabilities().collect();
    for (i, (_, cap)) in actives.iter().enumerate() {
        c.caps.insert(cap.name.name.clone(), CapId(i));
    }
    c.defaults = actives.iter().map(|(_, cap)| c.defaults_of(cap)).collect();
    let capabilities: TiVec<CapId, Capability> =
        actives.iter().map(|(file, cap)| c.capability(*file, cap)).collect();
    c.file = mission_file;
    c.scopes.clear();
    c.frame_size = 0;
    let body = c.body(&mission.body, &mission.name.name, BlockKind::Sequential, true);
    // Declared only directly in the MISSION body (the checker refuses it elsewhere).
    let mut operator_signals = Vec::new();
    for stmt in &mission.body.items {
        if let ast::Stmt::OperatorSignals(o) = stmt {
            for name in &o.names {
                let id = c.signals.id(&name.name);
                if !operator_signals.contains(&id) {
                    operator_signals.push(id);
                }
            }
        }
    }
    // Interned, so never missing: a descriptor without one gets it added, not another
    // name's id.
    let builtins = Builtins {
        signals: BuiltinSignal::ALL.map(|s| c.signals.id(s.name())),
        exceptions: BuiltinException::ALL.map(|e| c.exceptions.id(e.name())),
    };
    let signal_values = c
        .signals
        .names
        .iter()
        .map(|s| program.signal_values.get(s).cloned().unwrap_or_default())
        .collect();
    let mut out = Mission {
        name: mission.name.name.clone(),
        body,
        frame_size: c.frame_size,
        capabilities,
        drones: aviary_api::Names::new(world.drones.iter().map(|d| d.name.as_str())),
        signals: c.signals.names,
        signal_values,
        operator_signals,
        exceptions: c.exceptions.names,
        tags: c.tags.names,
        attribute_names: c.attribute_names.clone(),
        attributes: attribute_table(world, &c.attribute_names),
        origin: world.site.origin.as_ref().map(|o| aviary_api::geo::Origin {
            lat: o.lat,
            lon: o.lon,
            alt: o.alt,
        }),
        builtins,
        lines: program
            .mission_file()
            .map(|(file, tree)| Lines { file, starts: tree.line_offsets.clone() })
            .unwrap_or_default(),
    };
    compute_claims(&mut out.capabilities);
    (!c.unresolved).then_some(out)
}

/// Names (signals, exceptions, tags) to indices, in order of first use. Looked up by
/// hash: a scan of the names so far would make a mission of N signals cost N².
struct Interner<I> {
    names: TiVec<I, String>,
    index: foldhash::HashMap<String, I>,
}

impl<I> Default for Interner<I> {
    fn default() -> Self {
        Interner { names: TiVec::new(), index: foldhash::HashMap::default() }
    }
}

impl<I: From<usize> + Copy> Interner<I> {
    fn id(&mut self, name: &str) -> I {
        if let Some(&i) = self.index.get(name) {
            return i;
        }
        let i = self.names.push_and_get_key(name.to_string());
        self.index.insert(name.to_string(), i);
        i
    }
}

struct Compiler<'a> {
    program: &'a Program,
    world: &'a World,
    caps: foldhash::HashMap<String, CapId>,
    defaults: TiVec<CapId, Vec<Option<Expr>>>,
    signals: Interner<SignalId>,
    exceptions: Interner<ExceptionId>,
    tags: Interner<TagId>,
    attribute_names: Vec<String>,
    /// The world's names, looked up once each: a scan per name would make a group of N
    /// drones cost N² to compile.
    index: WorldIndex<'a>,
    /// Every FOR alias of the mission and the drones its instances stand for.
    aliases: BTreeMap<String, Vec<DroneId>>,
    /// Names bound in the current frame: (name, slot, is an actor).
    scopes: Vec<Vec<(String, Slot, bool)>>,
    frame_size: usize,
    file: FileId,
    /// Something the checker refuses was met: no mission comes out.
    unresolved: bool,
}

impl<'a> Compiler<'a> {
    fn new(program: &'a Program, world: &'a World, api: &'a Descriptor) -> Self {
        let mut signals = Interner::default();
        for s in &api.signals {
            signals.id(s.name());
        }
        let mut exceptions = Interner::default();
        for e in &api.exceptions {
            exceptions.id(e.name());
        }
        let mut attribute_names: Vec<String> = Vec::new();
        for d in &world.drones {
            for (k, _) in &d.attributes {
                if !attribute_names.iter().any(|n| **n == **k) {
                    attribute_names.push(k.to_string());
                }
            }
        }
        Compiler {
            program,
            world,
            caps: foldhash::HashMap::default(),
            defaults: TiVec::new(),
            signals,
            exceptions,
            tags: Interner::default(),
            attribute_names,
            index: WorldIndex::new(world),
            aliases: BTreeMap::new(),
            scopes: Vec::new(),
            frame_size: 0,
            file: FileId::default(),
            unresolved: false,
        }
    }

    fn origin(&self, span: aviary_diagnostics::Span) -> Origin {
        Origin { file: self.file, span }
    }

    fn slot(&mut self) -> Slot {
        self.frame_size += 1;
        Slot(self.frame_size - 1)
    }

    fn local(&self, name: &str) -> Option<(Slot, bool)> {
        self.scopes
            .iter()
            .rev()
            .flat_map(|s| s.iter().rev())
            .find(|(n, _, _)| n == name)
            .map(|&(_, s, a)| (s, a))
    }

    fn collect_aliases(&mut self, body: &ast::Body) {
        aviary_syntax::visit::for_each_stmt(body, |stmt| {
            if let ast::Stmt::For(f) = stmt {
                let mut drones = Vec::new();
                for inst in &f.instances {
                    match self.actor(&inst.actor.name) {
                        ActorRef::Drone(d) => drones.push(d),
                        ActorRef::Group(g) => drones.extend(g),
                        ActorRef::Slot(_) => {}
                    }
                }
                self.aliases.entry(f.alias.name.clone()).or_default().extend(drones);
            }
            if let ast::Stmt::Any(a) = stmt {
                if let ActorRef::Group(g) = self.actor(&a.group.name) {
                    self.aliases.entry(a.alias.name.clone()).or_default().extend(g);
                }
            }
        });
    }

    fn actor(&self, name: &str) -> ActorRef {
        if let Some((slot, _)) = self.local(name) {
            return ActorRef::Slot(slot);
        }
        if let Some(&i) = self.index.drones.get(name) {
            return ActorRef::Drone(i);
        }
        let members =
            self.index.groups.get(name).map(|g| g.members.iter().map(|&d| DroneId(d)).collect());
        ActorRef::Group(members.unwrap_or_default())
    }

    fn filter(&self, by: &Option<ast::Ident>) -> Option<ActorFilter> {
        let by = by.as_ref()?;
        if let Some((slot, true)) = self.local(&by.name) {
            return Some(ActorFilter::Slot(slot));
        }
        if let Some(drones) = self.aliases.get(&by.name) {
            return Some(ActorFilter::Drones(drones.clone()));
        }
        Some(match self.actor(&by.name) {
            ActorRef::Drone(d) => ActorFilter::Drones(vec![d]),
            ActorRef::Group(g) => ActorFilter::Drones(g),
            ActorRef::Slot(s) => ActorFilter::Slot(s),
        })
    }

    fn defaults_of(&mut self, cap: &ast::Capability) -> Vec<Option<Expr>> {
        let saved = std::mem::take(&mut self.scopes);
        let mut out = vec![None; cap.params.len()];
        for section in &cap.sections {
            if let ast::Section::Defaults { entries, .. } = section {
                for e in entries {
                    if let Some(i) = cap.params.iter().position(|p| p.name == e.name.name) {
                        out[i] = Some(self.expr(&e.value));
                    }
                }
            }
        }
        self.scopes = saved;
        out
    }

    fn capability(&mut self, file: FileId, cap: &ast::Capability) -> Capability {
        self.file = file;
        let mut scope: Vec<(String, Slot, bool)> =
            cap.actors.iter().enumerate().map(|(i, a)| (a.name.clone(), Slot(i), true)).collect();
        scope.extend(
            cap.params
                .iter()
                .enumerate()
                .map(|(i, p)| (p.name.clone(), Slot::param(cap.actors.len(), i), false)),
        );
        self.frame_size = scope.len();
        self.scopes.clear();
        self.scopes.push(scope);
        let name = &cap.name.name;
        let mut out = Capability {
            name: name.clone(),
            actors: cap.actors.len(),
            params: cap.params.iter().map(|p| p.name.clone()).collect(),
            param_kinds: self
                .program
                .param_kinds
                .get(name)
                .cloned()
                .unwrap_or_else(|| vec![None; cap.params.len()]),
            frame_size: 0,
            requirements: Vec::new(),
            perform: empty_block(name),
            sections: Vec::new(),
            abort_section: None,
            exception_handlers: Vec::new(),
            claims: Vec::new(),
        };
        for section in &cap.sections {
            match section {
                ast::Section::Requirements { conditions, .. } => {
                    out.requirements = conditions.iter().map(|c| self.expr(c)).collect()
                }
                ast::Section::Defaults { .. } => {}
                ast::Section::Perform { name: None, body, .. } => {
                    out.perform = self.body(body, name, BlockKind::Sequential, false)
                }
                ast::Section::Perform { name: Some(section), body, .. } => {
                    let path = format!("{name}/PERFORM {}", section.name);
                    let block = self.body(body, &path, BlockKind::Sequential, false);
                    if BuiltinLeash::parse(&section.name) == Some(BuiltinLeash::Abort) {
                        out.abort_section = Some(out.sections.len());
                    }
                    out.sections.push((section.name.clone(), block));
                }
                ast::Section::Exceptions { handlers, .. } => {
                    out.exception_handlers =
                        handlers.iter().map(|h| self.exception_handler(h, name)).collect();
                }
            }
        }
        out.frame_size = self.frame_size;
        out
    }

    fn body(&mut self, body: &ast::Body, path: &str, kind: BlockKind, traced: bool) -> Block {
        // Room for every statement at once: a long block would otherwise grow (and copy)
        // its vector a score of times.
        let mut block = Block {
            kind,
            path: path.to_string(),
            traced,
            items: Vec::with_capacity(body.items.len()),
            handlers: Vec::new(),
            exception_handlers: Vec::new(),
        };
        // The LETs of this body, seen to its end.
        self.scopes.push(Vec::new());
        for stmt in &body.items {
            match stmt {
                ast::Stmt::Let(l) => {
                    let value = self.expr(&l.value);
                    let slot = self.slot();
                    if let Some(scope) = self.scopes.last_mut() {
                        scope.push((l.name.name.clone(), slot, false));
                    }
                    block.items.push(Node::Let { slot, value, origin: self.origin(l.span) });
                }
                ast::Stmt::Handler(h) => {
                    let handler = self.handler(h, path);
                    block.handlers.push(handler);
                }
                ast::Stmt::ExceptionHandler(h) => {
                    let handler = self.exception_handler(h, path);
                    block.exception_handlers.push(handler);
                }
                other @ (ast::Stmt::Block(_)
                | ast::Stmt::Statement(_)
                | ast::Stmt::Leash(_)
                | ast::Stmt::Api(_)
                | ast::Stmt::Requirement(_)
                | ast::Stmt::For(_)
                | ast::Stmt::Signal(_)
                | ast::Stmt::Throw(_)
                | ast::Stmt::If(_)
                | ast::Stmt::OperatorSignals(_)
                | ast::Stmt::Any(_)
                | ast::Stmt::Allow(_)
                | ast::Stmt::StopBlock(_)
                | ast::Stmt::Error(_)) => {
                    if let Some(node) = self.node(other, path) {
                        block.items.push(node);
                    }
                }
            }
        }
        self.scopes.pop();
        block
    }

    fn bound_scope<T>(
        &mut self,
        names: impl IntoIterator<Item = (String, bool)>,
        f: impl FnOnce(&mut Self, Vec<Slot>) -> T,
    ) -> T {
        let mut scope = Vec::new();
        let mut slots = Vec::new();
        for (name, actor) in names {
            let s = self.slot();
            slots.push(s);
            scope.push((name, s, actor));
        }
        self.scopes.push(scope);
        let out = f(self, slots);
        self.scopes.pop();
        out
    }

    fn handler(&mut self, h: &ast::Handler, parent: &str) -> Handler {
        let signal = self.signals.id(&h.signal.name);
        let by = self.filter(&h.by);
        let path = format!("{parent}/ON {}", h.signal.name);
        let names = h.bindings.iter().map(|b| (b.name.clone(), false));
        let line = self.line_of(h.span.start);
        self.bound_scope(names, |c, bindings| Handler {
            signal,
            every: h.every,
            sequential: h.mode == Some(ast::BlockKind::Sequential),
            one_at_a_time: h.every && h.one_at_a_time.is_some(),
            by,
            bindings,
            body: c.body(&h.body, &path, BlockKind::Sequential, false),
            line,
        })
    }

    /// The line (from 1) of a byte of the file being compiled; 0 if unknown.
    fn line_of(&self, at: u32) -> u32 {
        self.program
            .files
            .iter()
            .find(|(f, _)| *f == self.file)
            .map_or(0, |(_, tree)| tree.line_of(at))
    }

    fn exception_handler(&mut self, h: &ast::ExceptionHandler, parent: &str) -> ExceptionHandler {
        let exception = self.exceptions.id(&h.exception.name);
        let by = self.filter(&h.by);
        let path = format!("{parent}/ON EXCEPTION {}", h.exception.name);
        let names = h.bindings.iter().map(|b| (b.name.clone(), false));
        let line = self.line_of(h.span.start);
        self.bound_scope(names, |c, bindings| ExceptionHandler {
            exception,
            by,
            bindings,
            body: c.body(&h.body, &path, BlockKind::Sequential, false),
            line,
        })
    }

    fn node(&mut self, stmt: &ast::Stmt, parent: &str) -> Option<Node> {
        Some(match stmt {
            ast::Stmt::Block(b) => {
                let kind = if b.kind == ast::BlockKind::Parallel {
                    BlockKind::Parallel
                } else {
                    BlockKind::Sequential
                };
                let path = match &b.name {
                    Some(n) => n.name.clone(),
                    None => format!("{parent}/{}", b.kind.as_str()),
                };
                Node::Block(self.body(&b.body, &path, kind, true))
            }
            ast::Stmt::Statement(s) => Node::Call(self.call(s)?),
            ast::Stmt::Leash(l) => Node::Leash(self.leash(l)?),
            ast::Stmt::StopBlock(s) => {
                Node::StopBlock { block: s.block.name.clone(), origin: self.origin(s.span) }
            }
            ast::Stmt::Api(a) => {
                let function = self.program.api_function(self.file, a)?.function;
                let args: Vec<Expr> = a.args.iter().map(|e| self.expr(e)).collect();
                Node::Api(ApiCall {
                    actor: self.actor(&a.actor.name),
                    function,
                    read: read_when_compiled(function, &args),
                    args,
                    origin: self.origin(a.span),
                })
            }
            ast::Stmt::Signal(r) => Node::Signal {
                signal: self.signals.id(&r.name.name),
                args: self.args(&r.args),
                origin: self.origin(r.span),
            },
            ast::Stmt::Throw(r) => Node::Throw {
                exception: self.exceptions.id(&r.name.name),
                args: self.args(&r.args),
                origin: self.origin(r.span),
            },
            ast::Stmt::Requirement(r) => {
                let condition = self.expr(&r.condition);
                let path = format!("{parent}/{}", r.kind.as_str());
                let body =
                    r.body.as_ref().map(|b| self.body(b, &path, BlockKind::Sequential, false));
                match r.kind {
                    ast::RequirementKind::StartIf => Node::StartIf {
                        condition,
                        body: body.unwrap_or_else(|| empty_block(&path)),
                    },
                    ast::RequirementKind::WaitFor => Node::WaitFor { condition, body },
                    ast::RequirementKind::DoWhile => Node::DoWhile {
                        condition,
                        body: body.unwrap_or_else(|| empty_block(&path)),
                    },
                }
            }
            ast::Stmt::For(f) => {
                let instances = f
                    .instances
                    .iter()
                    .map(|i| {
                        (self.actor(&i.actor.name), i.values.iter().map(|v| self.expr(v)).collect())
                    })
                    .collect();
                let path = format!("{parent}/FOR {}", f.alias.name);
                let names = std::iter::once((f.alias.name.clone(), true))
                    .chain(f.params.iter().map(|p| (p.name.clone(), false)));
                self.bound_scope(names, |c, slots| {
                    Node::For(For {
                        parallel: f.kind == ast::BlockKind::Parallel,
                        instances,
                        alias: slots[0],
                        params: slots[1..].to_vec(),
                        body: c.body(&f.body, &path, BlockKind::Sequential, false),
                    })
                })
            }
            ast::Stmt::Any(a) => {
                let candidates = match self.actor(&a.group.name) {
                    ActorRef::Group(g) => g,
                    ActorRef::Drone(d) => vec![d],
                    ActorRef::Slot(_) => Vec::new(),
                };
                let count = match a.count.as_ref().map(|c| &c.kind) {
                    Some(ast::ExprKind::Number { value, .. }) => *value as usize,
                    _ => 1,
                };
                let nearest = a.nearest.as_ref().map(|p| self.expr(p));
                let within = a.within.as_ref().map(|t| self.expr(t));
                let path = format!("{parent}/ANY {}", a.alias.name);
                let origin = self.origin(a.span);
                self.bound_scope([(a.alias.name.clone(), true)], |c, slots| {
                    Node::Any(Any {
                        group: a.group.name.clone(),
                        candidates,
                        count,
                        alias: slots[0],
                        condition: a.condition.as_ref().map(|e| c.expr(e)),
                        nearest,
                        within,
                        body: c.body(&a.body, &path, BlockKind::Sequential, false),
                        origin,
                    })
                })
            }
            ast::Stmt::If(i) => {
                let path = format!("{parent}/IF");
                let branches = i
                    .branches
                    .iter()
                    .map(|(c, b)| (self.expr(c), self.body(b, &path, BlockKind::Sequential, false)))
                    .collect();
                let otherwise = i
                    .otherwise
                    .as_ref()
                    .map(|b| self.body(b, &format!("{parent}/ELSE"), BlockKind::Sequential, false));
                Node::If { branches, otherwise }
            }
            // Handlers and LETs are `body`'s, which sees their place in the body.
            ast::Stmt::Handler(_)
            | ast::Stmt::ExceptionHandler(_)
            | ast::Stmt::Let(_)
            | ast::Stmt::OperatorSignals(_)
            // An ALLOW is for the checks before flight only.
            | ast::Stmt::Allow(_)
            | ast::Stmt::Error(_) => return None,
        })
    }

    fn args(&mut self, args: &[ast::Arg]) -> Vec<Expr> {
        args.iter().map(|a| self.expr(&a.value)).collect()
    }

    fn call(&mut self, s: &ast::Statement) -> Option<Call> {
        let capability = *self.caps.get(&s.capability.name)?;
        let callee = self.program.capability(&s.capability.name)?;
        let binding = bind_args(&callee.params, &s.args);
        let mut args = Vec::with_capacity(binding.bound.len());
        for (i, e) in binding.bound.iter().enumerate() {
            args.push(match e {
                Some(e) => self.expr(e),
                None => self.default_of(capability, i),
            });
        }
        Some(Call {
            actors: s.actors.iter().map(|a| self.actor(&a.name)).collect(),
            capability,
            args,
            tag: s.tag.as_ref().map(|t| self.tags.id(&t.name)),
            origin: self.origin(s.span),
        })
    }

    /// The default of parameter `i` of a capability, for a call that leaves it out (none:
    /// no value).
    fn default_of(&self, capability: CapId, i: usize) -> Expr {
        let default = self.defaults.get(capability).and_then(|d| d.get(i)).cloned().flatten();
        default.unwrap_or(Expr::Const(Value::Absent))
    }

    fn leash(&mut self, l: &ast::LeashCall) -> Option<Leash> {
        let capability = *self.caps.get(&l.capability.name)?;
        let callee = self.program.capability(&l.capability.name)?;
        let name = l.action.name.as_str();
        let action = match BuiltinLeash::parse(name) {
            Some(builtin) => LeashAction::Builtin(builtin),
            None => {
                let sections = callee.sections.iter().filter_map(|s| match s {
                    ast::Section::Perform { name: Some(n), .. } => Some(n.name.as_str()),
                    ast::Section::Requirements { .. }
                    | ast::Section::Defaults { .. }
                    | ast::Section::Perform { .. }
                    | ast::Section::Exceptions { .. } => None,
                });
                LeashAction::Section(sections.enumerate().find(|(_, n)| *n == name)?.0)
            }
        };
        let binding = bind_args(&callee.params, &l.args);
        let args = binding
            .bound
            .iter()
            .enumerate()
            .filter_map(|(i, e)| e.map(|e| (i, self.expr(e))))
            .collect();
        Some(Leash {
            capability,
            tag: self.tags.id(&l.tag.name),
            action,
            args,
            origin: self.origin(l.span),
        })
    }

    fn expr(&mut self, e: &ast::Expr) -> Expr {
        use ast::ExprKind as K;
        match &e.kind {
            K::Number { value, unit, .. } => {
                Expr::Const(Value::Number(value * unit.map_or(1.0, |u| u.to_si())))
            }
            K::String(s) => Expr::Const(Value::Text(s.clone())),
            K::Bool(b) => Expr::Const(Value::Bool(*b)),
            K::Coordinates(parts) => {
                let Some(parts) = self.parts(parts) else { return self.unresolved() };
                match parts.borrowed().try_map(literal_number) {
                    Some(n) => Expr::Const(Value::Position(Point { x: n.x, y: n.y, z: n.z })),
                    None => Expr::Point(Box::new(parts)),
                }
            }
            K::Geo(parts) => {
                let Some(parts) = self.parts(parts) else { return self.unresolved() };
                match (parts.borrowed().try_map(literal_number), self.world.site.origin.as_ref()) {
                    (Some(n), Some(o)) => {
                        let o = aviary_api::geo::Origin { lat: o.lat, lon: o.lon, alt: o.alt };
                        let [x, y, z] = o.place(n.x, n.y, n.z);
                        Expr::Const(Value::Position(Point { x, y, z: (!z.is_nan()).then_some(z) }))
                    }
                    _ => Expr::Geo(Box::new(parts)),
                }
            }
            K::Name(id) => self.name(&id.name),
            K::Path(a, field) => {
                let actor = self.actor(&a.name);
                match telemetry_field(&field.name) {
                    Some(f) => Expr::Telemetry(actor, f),
                    None => match self.attribute_names.iter().position(|n| n == &field.name) {
                        Some(index) => Expr::Attribute(actor, index),
                        None => self.unresolved(),
                    },
                }
            }
            K::Distance(a, b) => Expr::Distance(Box::new(self.expr(a)), Box::new(self.expr(b))),
            K::Arith(l, op, r) => {
                let (l, r) = (self.expr(l), self.expr(r));
                let sign = if *op == ast::ArithOp::Add { 1.0 } else { -1.0 };
                // What is known now is worked out now: the plan and the geofence see it.
                if let (Expr::Const(a), Expr::Const(b)) = (&l, &r) {
                    if let Some(v) = arith::add(a, b, sign) {
                        return Expr::Const(v);
                    }
                }
                let (l, r) = (Box::new(l), Box::new(r));
                match op {
                    ast::ArithOp::Add => Expr::Add(l, r),
                    ast::ArithOp::Sub => Expr::Sub(l, r),
                }
            }
            K::Offset(p, d, b) => {
                let (p, d, b) = (self.expr(p), self.expr(d), self.expr(b));
                if let (
                    Expr::Const(p),
                    Expr::Const(Value::Number(d)),
                    Expr::Const(Value::Number(b)),
                ) = (&p, &d, &b)
                {
                    if let Some(p) = arith::point_of(p) {
                        return Expr::Const(Value::Position(arith::offset(p, *d, *b)));
                    }
                }
                Expr::Offset(Box::new(p), Box::new(d), Box::new(b))
            }
            K::Midpoint(a, b) => {
                let (a, b) = (self.expr(a), self.expr(b));
                if let (Expr::Const(x), Expr::Const(y)) = (&a, &b) {
                    if let (Some(x), Some(y)) = (arith::point_of(x), arith::point_of(y)) {
                        return Expr::Const(Value::Position(arith::midpoint(x, y)));
                    }
                }
                Expr::Midpoint(Box::new(a), Box::new(b))
            }
            K::Received(s) => Expr::Received(self.signals.id(&s.name)),
            K::Elapsed => Expr::Elapsed,
            K::Not(inner) => Expr::Not(Box::new(self.expr(inner))),
            K::Paren(inner) => self.expr(inner),
            K::Binary(l, op, r) => {
                let (l, r) = (Box::new(self.expr(l)), Box::new(self.expr(r)));
                match op {
                    ast::BinaryOp::And => Expr::And(l, r),
                    ast::BinaryOp::Or => Expr::Or(l, r),
                    ast::BinaryOp::Eq => Expr::Compare(l, Compare::Eq, r),
                    ast::BinaryOp::Ne => Expr::Compare(l, Compare::Ne, r),
                    ast::BinaryOp::Lt => Expr::Compare(l, Compare::Lt, r),
                    ast::BinaryOp::Le => Expr::Compare(l, Compare::Le, r),
                    ast::BinaryOp::Gt => Expr::Compare(l, Compare::Gt, r),
                    ast::BinaryOp::Ge => Expr::Compare(l, Compare::Ge, r),
                }
            }
            K::Error => self.unresolved(),
        }
    }

    /// The parts of coordinates or of a `GEO`, lowered: two or three of them.
    fn parts(&mut self, parts: &[ast::Expr]) -> Option<Parts<Expr>> {
        Parts::of(parts.iter().map(|p| self.expr(p)).collect())
    }

    /// What the checker refuses (an unknown attribute, a malformed point, a parse error):
    /// the program does not compile ([`compile`] gives no mission), so this stand-in
    /// never runs.
    fn unresolved(&mut self) -> Expr {
        self.unresolved = true;
        Expr::Const(Value::Absent)
    }

    fn name(&self, name: &str) -> Expr {
        if let Some((slot, _)) = self.local(name) {
            return Expr::Slot(slot);
        }
        let w = &self.index;
        if let Some(&i) = w.drones.get(name) {
            return Expr::Const(Value::Actor(i));
        }
        if w.groups.contains_key(name) {
            return Expr::Actor(self.actor(name));
        }
        if let Some(p) = w.places.get(name) {
            return Expr::Const(Value::Position(Point {
                x: p.at[0],
                y: p.at[1],
                z: p.has_z.then_some(p.at[2]),
            }));
        }
        if let Some(a) = w.areas.get(name) {
            return Expr::Const(Value::Area(a.polygon.clone()));
        }
        if let Some(l) = w.lines.get(name) {
            // A line runs as a path's points, as what a FollowPath left does: the one
            // value `FollowPath` flies in place of its points (the trace shows it as
            // `{"points": ...}`).
            let path = aviary_api::Remainder::points(l.path());
            return Expr::Const(Value::Remainder(std::sync::Arc::new(path)));
        }
        Expr::Const(Value::Symbol(name.to_string()))
    }
}

fn empty_block(path: &str) -> Block {
    Block {
        kind: BlockKind::Sequential,
        path: path.to_string(),
        traced: false,
        items: Vec::new(),
        handlers: Vec::new(),
        exception_handlers: Vec::new(),
    }
}

/// A literal number's value; `None` for any other expression.
/// A call whose arguments are all constants, read once here rather than each time it is
/// made. One that does not read (a kind the checker let through) is left to the engine,
/// which refuses it in flight as it refuses any call it cannot read.
fn read_when_compiled(function: Function, args: &[Expr]) -> Option<FunctionCall> {
    let values = args
        .iter()
        // Only a constant is known now, whatever expressions come: no match to extend.
        .map(|e| if let Expr::Const(v) = e { Some(v.clone()) } else { None })
        .collect::<Option<Vec<Value>>>()?;
    FunctionCall::new(function, &values).ok()
}

fn literal_number(e: &Expr) -> Option<f64> {
    match e {
        Expr::Const(Value::Number(n)) => Some(*n),
        Expr::Const(_)
        | Expr::Slot(_)
        | Expr::Actor(_)
        | Expr::Telemetry(..)
        | Expr::Attribute(..)
        | Expr::Point(_)
        | Expr::Geo(_)
        | Expr::Distance(..)
        | Expr::Add(..)
        | Expr::Sub(..)
        | Expr::Offset(..)
        | Expr::Midpoint(..)
        | Expr::Elapsed
        | Expr::Received(_)
        | Expr::Not(_)
        | Expr::And(..)
        | Expr::Or(..)
        | Expr::Compare(..) => None,
    }
}

fn telemetry_field(name: &str) -> Option<Field> {
    Some(match name {
        "position" => Field::Position,
        "altitude" => Field::Altitude,
        "speed" => Field::Speed,
        "heading" => Field::Heading,
        "battery" => Field::Battery,
        "state" => Field::State,
        "link" => Field::Link,
        "wind" => Field::Wind,
        "payload" => Field::Payload,
        "remaining" => Field::Remaining,
        _ => return None,
    })
}

fn attribute_table(world: &World, names: &[String]) -> Vec<Column> {
    names
        .iter()
        .map(|name| {
            let values = world
                .drones
                .iter()
                .map(|d| {
                    d.attributes.iter().find(|(k, _)| **k == **name).map(|(_, v)| match v {
                        AttributeValue::Number(n) => Value::Number(*n),
                        AttributeValue::Text(t) => Value::Text(t.clone()),
                        AttributeValue::Bool(b) => Value::Bool(*b),
                        AttributeValue::Other(o) => Value::Text(o.clone()),
                    })
                })
                .collect();
            Column::new(values)
        })
        .collect()
}

/// What each capability claims: the resources its own API calls use on its actors, and,
/// through every statement it makes on its actors, what the called capabilities claim.
/// A worklist: when a capability's claims grow, only its callers are looked at again, so
/// a chain of N capabilities costs N steps, not N rounds of N.
fn compute_claims(caps: &mut TiSlice<CapId, Capability>) {
    let mut claims: TiVec<CapId, Vec<(usize, aviary_api::Resource)>> =
        caps.iter().map(direct_claims).collect();
    // Who calls each capability: (caller, the call), in caller order.
    let mut callers: TiVec<CapId, Vec<(CapId, &Call)>> = vec![Vec::new(); caps.len()].into();
    for (i, cap) in caps.iter_enumerated() {
        let mut calls = Vec::new();
        for block in cap.bodies() {
            visit_calls(block, &mut calls);
        }
        for call in calls {
            if let Some(list) = callers.get_mut(call.capability) {
                list.push((i, call));
            }
        }
    }
    let mut pending: Vec<CapId> =
        claims.iter_enumerated().filter(|(_, c)| !c.is_empty()).map(|(id, _)| id).collect();
    let mut queued: TiVec<CapId, bool> = claims.iter().map(|c| !c.is_empty()).collect();
    while let Some(callee) = pending.pop() {
        queued[callee] = false;
        for &(i, call) in &callers[callee] {
            let mut grew = false;
            for k in 0..claims[callee].len() {
                let (j, resource) = claims[callee][k];
                let targets: &[ActorRef] = if caps[callee].actors == 1 {
                    &call.actors
                } else {
                    call.actors.get(j..=j).unwrap_or(&[])
                };
                for target in targets {
                    if let Some(actor) = slot_actor(target, caps[i].actors) {
                        if !claims[i].contains(&(actor, resource)) {
                            claims[i].push((actor, resource));
                            grew = true;
                        }
                    }
                }
            }
            if grew && !queued[i] {
                queued[i] = true;
                pending.push(i);
            }
        }
    }
    for (c, mut cl) in caps.iter_mut().zip(claims) {
        cl.sort();
        cl.dedup();
        c.claims = cl;
    }
}

fn direct_claims(cap: &Capability) -> Vec<(usize, aviary_api::Resource)> {
    let mut out = Vec::new();
    for block in cap.bodies() {
        block.visit(&mut |n| {
            if let Node::Api(a) = n {
                if let Some(actor) = slot_actor(&a.actor, cap.actors) {
                    out.push((actor, a.function.resource()));
                }
            }
        });
    }
    out
}

/// The `BY` actor of a capability with `actors` of them that `r` names, if it names one.
fn slot_actor(r: &ActorRef, actors: usize) -> Option<usize> {
    match r {
        ActorRef::Slot(s) => s.actor(actors),
        ActorRef::Drone(_) | ActorRef::Group(_) => None,
    }
}

fn visit_calls<'b>(block: &'b Block, out: &mut Vec<&'b Call>) {
    block.visit(&mut |n| {
        if let Node::Call(c) = n {
            out.push(c);
        }
    });
}

/// The world's drones, groups, places, areas and lines by name (the first of a name wins, as a
/// scan in file order would find it).
/// Hashed with foldhash (seeded per process): a quick hash for keys no attacker chooses,
/// since the names come from the operator's own world file, and a large world has one a
/// drone.
struct WorldIndex<'w> {
    drones: foldhash::HashMap<&'w str, DroneId>,
    groups: foldhash::HashMap<&'w str, &'w aviary_world::Group>,
    places: foldhash::HashMap<&'w str, &'w aviary_world::Place>,
    areas: foldhash::HashMap<&'w str, &'w aviary_world::Area>,
    lines: foldhash::HashMap<&'w str, &'w aviary_world::Line>,
}

impl<'w> WorldIndex<'w> {
    fn new(w: &'w World) -> Self {
        fn first<'w, T>(
            items: impl ExactSizeIterator<Item = (&'w str, T)>,
        ) -> foldhash::HashMap<&'w str, T> {
            let mut map =
                foldhash::HashMap::with_capacity_and_hasher(items.len(), Default::default());
            for (name, item) in items {
                map.entry(name).or_insert(item);
            }
            map
        }
        WorldIndex {
            drones: first(w.drones.iter().enumerate().map(|(i, d)| (d.name.as_str(), DroneId(i)))),
            groups: first(w.groups.iter().map(|g| (g.name.as_str(), g))),
            places: first(w.places.iter().map(|p| (p.name.as_str(), p))),
            areas: first(w.areas.iter().map(|a| (a.name.as_str(), a))),
            lines: first(w.lines.iter().map(|l| (l.name.as_str(), l))),
        }
    }
}
