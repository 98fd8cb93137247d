//! One walk over the syntax tree. A pass overrides the `Visitor` methods for the nodes it
//! cares about and calls the matching `walk_*` function to go on below them; the `walk_*`
//! functions match every variant by name (no `_` arm), so a new statement or expression
//! is a compile error here, not a node that some pass silently skips.
//!
//! Order is the source order: a statement's expressions and bodies as they are written
//! (an `IF`'s first condition, its body, the next condition, ...), outer before inner.

#![deny(clippy::wildcard_enum_match_arm)]

use crate::ast::*;

pub trait Visitor<'a> {
    fn visit_item(&mut self, item: &'a Item) {
        walk_item(self, item)
    }
    fn visit_capability(&mut self, capability: &'a Capability) {
        walk_capability(self, capability)
    }
    fn visit_section(&mut self, section: &'a Section) {
        walk_section(self, section)
    }
    fn visit_body(&mut self, body: &'a Body) {
        walk_body(self, body)
    }
    fn visit_stmt(&mut self, stmt: &'a Stmt) {
        walk_stmt(self, stmt)
    }
    fn visit_expr(&mut self, expr: &'a Expr) {
        walk_expr(self, expr)
    }
}

pub fn walk_source_file<'a, V: Visitor<'a> + ?Sized>(v: &mut V, file: &'a SourceFile) {
    file.items.iter().for_each(|item| v.visit_item(item));
}

pub fn walk_item<'a, V: Visitor<'a> + ?Sized>(v: &mut V, item: &'a Item) {
    match item {
        Item::Use(_) => {}
        Item::Capability(c) => v.visit_capability(c),
        Item::Mission(m) => v.visit_body(&m.body),
    }
}

pub fn walk_capability<'a, V: Visitor<'a> + ?Sized>(v: &mut V, capability: &'a Capability) {
    capability.sections.iter().for_each(|s| v.visit_section(s));
}

pub fn walk_section<'a, V: Visitor<'a> + ?Sized>(v: &mut V, section: &'a Section) {
    match section {
        Section::Requirements { conditions, .. } => conditions.iter().for_each(|c| v.visit_expr(c)),
        Section::Defaults { entries, .. } => entries.iter().for_each(|e| v.visit_expr(&e.value)),
        Section::Perform { body, .. } => v.visit_body(body),
        Section::Exceptions { handlers, .. } => handlers.iter().for_each(|h| v.visit_body(&h.body)),
    }
}

pub fn walk_body<'a, V: Visitor<'a> + ?Sized>(v: &mut V, body: &'a Body) {
    body.items.iter().for_each(|stmt| v.visit_stmt(stmt));
}

/// The statement's own expressions and bodies, in source order.
pub fn walk_stmt<'a, V: Visitor<'a> + ?Sized>(v: &mut V, stmt: &'a Stmt) {
    let args = |v: &mut V, args: &'a [Arg]| args.iter().for_each(|a| v.visit_expr(&a.value));
    match stmt {
        Stmt::Block(b) => v.visit_body(&b.body),
        Stmt::Statement(s) => args(v, &s.args),
        Stmt::Leash(l) => args(v, &l.args),
        Stmt::Api(a) => a.args.iter().for_each(|e| v.visit_expr(e)),
        Stmt::Requirement(r) => {
            v.visit_expr(&r.condition);
            if let Some(body) = &r.body {
                v.visit_body(body);
            }
        }
        Stmt::For(f) => {
            f.instances.iter().flat_map(|i| &i.values).for_each(|e| v.visit_expr(e));
            v.visit_body(&f.body);
        }
        Stmt::Signal(r) | Stmt::Throw(r) => args(v, &r.args),
        Stmt::Handler(h) => v.visit_body(&h.body),
        Stmt::ExceptionHandler(h) => v.visit_body(&h.body),
        Stmt::If(i) => {
            for (condition, body) in &i.branches {
                v.visit_expr(condition);
                v.visit_body(body);
            }
            if let Some(body) = &i.otherwise {
                v.visit_body(body);
            }
        }
        Stmt::Any(a) => {
            [&a.count, &a.condition, &a.nearest, &a.within]
                .into_iter()
                .flatten()
                .for_each(|e| v.visit_expr(e));
            v.visit_body(&a.body);
        }
        Stmt::Let(l) => v.visit_expr(&l.value),
        Stmt::OperatorSignals(_) | Stmt::Allow(_) | Stmt::StopBlock(_) | Stmt::Error(_) => {}
    }
}

pub fn walk_expr<'a, V: Visitor<'a> + ?Sized>(v: &mut V, expr: &'a Expr) {
    match &expr.kind {
        ExprKind::Coordinates(parts) | ExprKind::Geo(parts) => {
            parts.iter().for_each(|p| v.visit_expr(p))
        }
        ExprKind::Distance(a, b)
        | ExprKind::Binary(a, _, b)
        | ExprKind::Arith(a, _, b)
        | ExprKind::Midpoint(a, b) => {
            v.visit_expr(a);
            v.visit_expr(b);
        }
        ExprKind::Offset(a, d, b) => {
            v.visit_expr(a);
            v.visit_expr(d);
            v.visit_expr(b);
        }
        ExprKind::Not(e) | ExprKind::Paren(e) => v.visit_expr(e),
        ExprKind::Number { .. }
        | ExprKind::String(_)
        | ExprKind::Bool(_)
        | ExprKind::Name(_)
        | ExprKind::Path(..)
        | ExprKind::Received(_)
        | ExprKind::Elapsed
        | ExprKind::Error => {}
    }
}

/// Calls `f` on every statement in `body`, nested bodies included, outer first; not on
/// expressions.
pub fn for_each_stmt<'a>(body: &'a Body, f: impl FnMut(&'a Stmt)) {
    struct Stmts<F>(F);
    impl<'a, F: FnMut(&'a Stmt)> Visitor<'a> for Stmts<F> {
        fn visit_stmt(&mut self, stmt: &'a Stmt) {
            (self.0)(stmt);
            walk_stmt(self, stmt);
        }
        fn visit_expr(&mut self, _: &'a Expr) {}
    }
    Stmts(f).visit_body(body);
}

/// Calls `f` on `expr` and every expression inside it, outer first.
pub fn for_each_expr<'a>(expr: &'a Expr, f: impl FnMut(&'a Expr)) {
    struct Exprs<F>(F);
    impl<'a, F: FnMut(&'a Expr)> Visitor<'a> for Exprs<F> {
        fn visit_expr(&mut self, expr: &'a Expr) {
            (self.0)(expr);
            walk_expr(self, expr);
        }
    }
    Exprs(f).visit_expr(expr);
}

/// The expressions `stmt` holds itself, in source order: not those of its nested bodies,
/// nor those inside these expressions.
pub fn stmt_exprs(stmt: &Stmt) -> Vec<&Expr> {
    struct Own<'a>(Vec<&'a Expr>);
    impl<'a> Visitor<'a> for Own<'a> {
        fn visit_body(&mut self, _: &'a Body) {}
        fn visit_expr(&mut self, expr: &'a Expr) {
            self.0.push(expr);
        }
    }
    let mut own = Own(Vec::new());
    walk_stmt(&mut own, stmt);
    own.0
}

/// Calls `f` on each body directly inside `stmt`, in source order.
pub fn stmt_bodies<'a>(stmt: &'a Stmt, f: impl FnMut(&'a Body)) {
    struct Bodies<F>(F);
    impl<'a, F: FnMut(&'a Body)> Visitor<'a> for Bodies<F> {
        fn visit_body(&mut self, body: &'a Body) {
            (self.0)(body);
        }
        fn visit_expr(&mut self, _: &'a Expr) {}
    }
    walk_stmt(&mut Bodies(f), stmt);
}
