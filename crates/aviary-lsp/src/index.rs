//! What each name in a mission's files means: one walk over every syntax tree of an
//! analysis, giving each occurrence of a capability, parameter, signal, exception,
//! place, area, drone, group or tag, definitions marked. Hover, go to definition, find
//! references, rename and semantic tokens all read it.

// Each statement and expression is named: a new one is a compile error here.
#![deny(clippy::wildcard_enum_match_arm)]

use aviary_diagnostics::{FileId, Span};
use aviary_syntax::ast::{Arg, Body, Capability, Expr, ExprKind, Item, Section, SourceFile, Stmt};
use aviary_syntax::visit::{walk_expr, Visitor};
use aviary_world::World;

#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Sym {
    Capability(String),
    /// A capability's `WITH` parameter.
    Param {
        capability: String,
        name: String,
    },
    Signal(String),
    Exception(String),
    Place(String),
    Area(String),
    Drone(String),
    Group(String),
    /// An activity's tag (`FlyCircle-C1`): the capability's name with its tag.
    Tag(String),
    /// A name bound in one place (a `FOR` alias or parameter, a handler's binding, a
    /// capability's actor), known by where it is bound.
    Local {
        name: String,
        what: &'static str,
        file: FileId,
        at: Span,
    },
}

impl Sym {
    pub fn name(&self) -> &str {
        match self {
            Sym::Capability(n)
            | Sym::Signal(n)
            | Sym::Exception(n)
            | Sym::Place(n)
            | Sym::Area(n)
            | Sym::Drone(n)
            | Sym::Group(n)
            | Sym::Tag(n) => n,
            Sym::Param { name, .. } | Sym::Local { name, .. } => name,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Occurrence {
    pub file: FileId,
    pub span: Span,
    pub sym: Sym,
    pub definition: bool,
}

/// Every occurrence in `files` (the program's, the standard library's included) and the
/// definitions in the world file `world_file`.
pub fn index(files: &[(FileId, &SourceFile)], world: Option<(FileId, &World)>) -> Vec<Occurrence> {
    let api = aviary_api::Descriptor::standard();
    let mut walk = Walk {
        out: Vec::new(),
        file: FileId(0),
        world: world.map(|(_, w)| w),
        cap: None,
        api,
        locals: Vec::new(),
    };
    if let Some((file, w)) = world {
        for p in &w.places {
            walk.push_at(file, p.span, Sym::Place(p.name.clone()), true);
        }
        for a in &w.areas {
            walk.push_at(file, a.span, Sym::Area(a.name.clone()), true);
        }
        for d in &w.drones {
            walk.push_at(file, d.span, Sym::Drone(d.name.clone()), true);
        }
        // A group is defined by each `group = "NAME"` that names it: the name inside the
        // quotes.
        for g in &w.groups {
            for s in &g.spans {
                let inner =
                    Span { start: s.start + 1, end: s.end.saturating_sub(1).max(s.start + 1) };
                walk.push_at(file, inner, Sym::Group(g.name.clone()), true);
            }
        }
    }
    for (file, tree) in files {
        walk.file = *file;
        for item in &tree.items {
            match item {
                Item::Use(_) => {}
                Item::Mission(m) => {
                    walk.cap = None;
                    walk.locals.clear();
                    walk.body(&m.body);
                }
                Item::Capability(c) => walk.capability(c),
            }
        }
    }
    walk.out
}

struct Walk<'a> {
    out: Vec<Occurrence>,
    file: FileId,
    world: Option<&'a World>,
    /// The capability being walked, with its actors and parameters.
    cap: Option<&'a Capability>,
    api: &'a aviary_api::Descriptor,
    /// The names bound around the walk, innermost last.
    locals: Vec<Sym>,
}

impl<'a> Walk<'a> {
    fn push_at(&mut self, file: FileId, span: Span, sym: Sym, definition: bool) {
        self.out.push(Occurrence { file, span, sym, definition });
    }
    fn push(&mut self, span: Span, sym: Sym, definition: bool) {
        self.push_at(self.file, span, sym, definition);
    }

    /// Binds `ids` (definitions) for the walk of `inner`.
    fn bind(
        &mut self,
        ids: &[aviary_syntax::ast::Ident],
        what: &'static str,
        inner: impl FnOnce(&mut Self),
    ) {
        let depth = self.locals.len();
        for id in ids {
            let sym = Sym::Local { name: id.name.clone(), what, file: self.file, at: id.span };
            self.push(id.span, sym.clone(), true);
            self.locals.push(sym);
        }
        inner(self);
        self.locals.truncate(depth);
    }

    /// The local `name` bound around the walk, if any.
    fn bound(&self, name: &str) -> Option<Sym> {
        self.locals.iter().rev().find(|s| s.name() == name).cloned()
    }

    fn capability(&mut self, c: &'a Capability) {
        self.locals.clear();
        self.bind(&c.actors, "actor of the capability", |w| w.capability_inner(c));
    }

    fn capability_inner(&mut self, c: &'a Capability) {
        self.cap = Some(c);
        self.push(c.name.span, Sym::Capability(c.name.name.clone()), true);
        for p in &c.params {
            let sym = Sym::Param { capability: c.name.name.clone(), name: p.name.clone() };
            self.push(p.span, sym, true);
        }
        for s in &c.sections {
            match s {
                Section::Requirements { conditions, .. } => {
                    conditions.iter().for_each(|e| self.expr(e));
                }
                Section::Defaults { entries, .. } => {
                    for e in entries {
                        let sym = Sym::Param {
                            capability: c.name.name.clone(),
                            name: e.name.name.clone(),
                        };
                        self.push(e.name.span, sym, false);
                        self.expr(&e.value);
                    }
                }
                Section::Perform { body, .. } => self.body(body),
                Section::Exceptions { handlers, .. } => {
                    for h in handlers {
                        self.push(
                            h.exception.span,
                            Sym::Exception(h.exception.name.clone()),
                            false,
                        );
                        self.actor(h.by.as_ref());
                        self.body(&h.body);
                    }
                }
            }
        }
        self.cap = None;
    }

    /// A name that stands for a drone or a group of the world (else a variable).
    fn actor(&mut self, id: Option<&aviary_syntax::ast::Ident>) {
        if let Some(sym) = id.and_then(|i| self.bound(&i.name)) {
            self.push(id.map_or(Span::default(), |i| i.span), sym, false);
            return;
        }
        let (Some(id), Some(world)) = (id, self.world) else { return };
        if world.drones.iter().any(|d| d.name == id.name) {
            self.push(id.span, Sym::Drone(id.name.clone()), false);
        } else if world.groups.iter().any(|g| g.name == id.name) {
            self.push(id.span, Sym::Group(id.name.clone()), false);
        }
    }

    fn local(&self, name: &str) -> bool {
        self.cap.is_some_and(|c| {
            c.params.iter().any(|p| p.name == name) || c.actors.iter().any(|a| a.name == name)
        })
    }

    /// A body's items; the LETs it binds are seen to its end.
    fn body(&mut self, body: &'a Body) {
        let depth = self.locals.len();
        for s in &body.items {
            self.stmt(s);
        }
        self.locals.truncate(depth);
    }

    fn args(&mut self, capability: &str, args: &'a [Arg]) {
        for a in args {
            if let Some(n) = &a.name {
                let sym = Sym::Param { capability: capability.to_string(), name: n.name.clone() };
                self.push(n.span, sym, false);
            }
            self.expr(&a.value);
        }
    }

    fn stmt(&mut self, s: &'a Stmt) {
        match s {
            Stmt::Block(b) => self.body(&b.body),
            Stmt::Statement(st) => {
                st.actors.iter().for_each(|a| self.actor(Some(a)));
                self.push(st.capability.span, Sym::Capability(st.capability.name.clone()), false);
                if let Some(tag) = &st.tag {
                    let name = format!("{}-{}", st.capability.name, tag.name);
                    self.push(tag.span, Sym::Tag(name), true);
                }
                self.args(&st.capability.name, &st.args);
            }
            Stmt::Leash(l) => {
                self.push(l.capability.span, Sym::Capability(l.capability.name.clone()), false);
                let name = format!("{}-{}", l.capability.name, l.tag.name);
                self.push(l.tag.span, Sym::Tag(name), false);
                self.args(&l.capability.name, &l.args);
            }
            Stmt::Api(call) => {
                self.actor(Some(&call.actor));
                call.args.iter().for_each(|e| self.expr(e));
            }
            Stmt::Requirement(r) => {
                self.expr(&r.condition);
                if let Some(b) = &r.body {
                    self.body(b);
                }
            }
            Stmt::For(f) => {
                for i in &f.instances {
                    self.actor(Some(&i.actor));
                    i.values.iter().for_each(|e| self.expr(e));
                }
                let mut bound = vec![f.alias.clone()];
                bound.extend(f.params.iter().cloned());
                self.bind(&bound, "bound by FOR", |w| w.body(&f.body));
            }
            Stmt::Any(a) => {
                self.actor(Some(&a.group));
                [&a.count, &a.nearest, &a.within].into_iter().flatten().for_each(|e| self.expr(e));
                self.bind(std::slice::from_ref(&a.alias), "the drone ANY takes", |w| {
                    if let Some(c) = &a.condition {
                        w.expr(c);
                    }
                    w.body(&a.body)
                });
            }
            Stmt::Signal(r) => {
                self.push(r.name.span, Sym::Signal(r.name.name.clone()), true);
                r.args.iter().for_each(|a| self.expr(&a.value));
            }
            Stmt::Throw(r) => {
                self.push(r.name.span, Sym::Exception(r.name.name.clone()), true);
                r.args.iter().for_each(|a| self.expr(&a.value));
            }
            Stmt::Handler(h) => {
                self.push(h.signal.span, Sym::Signal(h.signal.name.clone()), false);
                self.actor(h.by.as_ref());
                self.bind(&h.bindings, "value of the signal", |w| w.body(&h.body));
            }
            Stmt::ExceptionHandler(h) => {
                self.push(h.exception.span, Sym::Exception(h.exception.name.clone()), false);
                self.actor(h.by.as_ref());
                self.bind(&h.bindings, "value of the exception", |w| w.body(&h.body));
            }
            Stmt::If(i) => {
                for (c, b) in &i.branches {
                    self.expr(c);
                    self.body(b);
                }
                if let Some(b) = &i.otherwise {
                    self.body(b);
                }
            }
            Stmt::OperatorSignals(o) => {
                for n in &o.names {
                    self.push(n.span, Sym::Signal(n.name.clone()), true);
                }
            }
            Stmt::Let(l) => {
                self.expr(&l.value);
                let (name, at) = (l.name.name.clone(), l.name.span);
                let sym = Sym::Local { name, what: "value of a LET", file: self.file, at };
                self.push(at, sym.clone(), true);
                self.locals.push(sym);
            }
            // A block's name is no symbol the index follows (blocks are not definitions).
            Stmt::StopBlock(_) | Stmt::Allow(_) | Stmt::Error(_) => {}
        }
    }

    fn expr(&mut self, e: &'a Expr) {
        match &e.kind {
            ExprKind::Name(id) => {
                if let Some(sym) = self.bound(&id.name) {
                    self.push(id.span, sym, false);
                    return;
                }
                if let Some(c) = self.cap.filter(|_| self.local(&id.name)) {
                    if c.params.iter().any(|p| p.name == id.name) {
                        let sym =
                            Sym::Param { capability: c.name.name.clone(), name: id.name.clone() };
                        self.push(id.span, sym, false);
                    }
                    return;
                }
                let Some(world) = self.world else { return };
                if world.places.iter().any(|p| p.name == id.name) {
                    self.push(id.span, Sym::Place(id.name.clone()), false);
                } else if world.areas.iter().any(|a| a.name == id.name) {
                    self.push(id.span, Sym::Area(id.name.clone()), false);
                } else {
                    self.actor(Some(id));
                }
            }
            ExprKind::Path(a, _) => self.actor(Some(a)),
            ExprKind::Received(id) => {
                let sym = if self.api.is_exception(&id.name) {
                    Sym::Exception(id.name.clone())
                } else {
                    Sym::Signal(id.name.clone())
                };
                self.push(id.span, sym, false);
            }
            ExprKind::Coordinates(_)
            | ExprKind::Geo(_)
            | ExprKind::Distance(..)
            | ExprKind::Binary(..)
            | ExprKind::Arith(..)
            | ExprKind::Midpoint(..)
            | ExprKind::Offset(..)
            | ExprKind::Not(_)
            | ExprKind::Paren(_) => walk_expr(self, e),
            ExprKind::Number { .. }
            | ExprKind::String(_)
            | ExprKind::Bool(_)
            | ExprKind::Elapsed
            | ExprKind::Error => {}
        }
    }
}

/// The expressions inside an expression: the tree's own walk, back into `Walk::expr`.
impl<'a> Visitor<'a> for Walk<'a> {
    fn visit_expr(&mut self, e: &'a Expr) {
        self.expr(e);
    }
}

/// The occurrence whose span holds `offset` in `file`, the narrowest.
pub fn at(occurrences: &[Occurrence], file: FileId, offset: u32) -> Option<&Occurrence> {
    occurrences
        .iter()
        .filter(|o| o.file == file && o.span.start <= offset && offset <= o.span.end)
        .min_by_key(|o| o.span.end - o.span.start)
}
