//! The one walk over the tree (`aviary_syntax::visit`): what it reaches and in what order.

use aviary_diagnostics::FileId;
use aviary_syntax::ast::{Expr, ExprKind, SourceFile, Stmt};
use aviary_syntax::visit::{self, Visitor};

fn tree(text: &str) -> SourceFile {
    let parsed = aviary_syntax::parse(FileId(0), text);
    assert!(!parsed.has_errors(), "{:?}", parsed.diagnostics);
    parsed.tree
}

/// The names, numbers and statements met, in order.
#[derive(Default)]
struct Trail(Vec<String>);

impl<'a> Visitor<'a> for Trail {
    fn visit_stmt(&mut self, stmt: &'a Stmt) {
        let text = format!("{stmt:?}");
        self.0.push(text.split('(').next().unwrap_or_default().to_string());
        visit::walk_stmt(self, stmt);
    }
    fn visit_expr(&mut self, expr: &'a Expr) {
        match &expr.kind {
            ExprKind::Name(n) => self.0.push(n.name.clone()),
            ExprKind::Number { digits, .. } => self.0.push(digits.clone()),
            _ => {}
        }
        visit::walk_expr(self, expr);
    }
}

#[test]
fn the_walk_goes_in_source_order_outer_first() {
    let file = tree(
        "MISSION M:\n    IF a:\n        d Go WITH b\n    ELSE IF distance(c, e) < 3:\n        LET x = 4\n    ELSE:\n        d Go WITH f\n    ON Done:\n        d Go WITH g\n",
    );
    let mut trail = Trail::default();
    visit::walk_source_file(&mut trail, &file);
    assert_eq!(trail.0.join(" "), "If a Statement b c e 3 Let 4 Statement f Handler Statement g");
}

#[test]
fn a_capability_s_sections_are_walked() {
    let file = tree(
        "CAPABILITY C BY d WITH p:\n    REQUIREMENTS:\n        p\n    DEFAULTS:\n        p: 5\n    PERFORM:\n        d Go WITH q\n    EXCEPTIONS:\n        ON EXCEPTION E:\n            d Go WITH r\n",
    );
    let mut trail = Trail::default();
    visit::walk_source_file(&mut trail, &file);
    assert_eq!(trail.0.join(" "), "p 5 Statement q Statement r");
}

#[test]
fn the_helpers_see_what_they_say() {
    let file = tree("MISSION M:\n    ANY 2 d IN g WHERE d.battery > 50% WITHIN 10s:\n        d Go WITH (1, 2)\n");
    let aviary_syntax::ast::Item::Mission(m) = &file.items[0] else { panic!("a mission") };
    let mut stmts = 0;
    visit::for_each_stmt(&m.body, |_| stmts += 1);
    assert_eq!(stmts, 2);
    let any = &m.body.items[0];
    let own: Vec<String> = visit::stmt_exprs(any).iter().map(|e| format!("{:?}", e.kind)).collect();
    assert_eq!(own.len(), 3, "count, WHERE and WITHIN: {own:?}");
    let mut bodies = 0;
    any.for_each_body(|_| bodies += 1);
    assert_eq!(bodies, 1);
    let mut exprs = 0;
    visit::for_each_expr(visit::stmt_exprs(any)[1], |_| exprs += 1);
    assert_eq!(exprs, 3, "the comparison, the path and the number");
}
