//! The text of values, arguments and conditions: one line each, tokens in source order.

use crate::ast::{Arg, Expr, ExprKind, Ident};

/// Writes an expression. Binary chains (`a AND b AND c`, nested on the left) are walked
/// without recursion along their left spine, so a long chain costs no stack.
pub(super) fn write_expr(out: &mut String, e: &Expr, source: &str) {
    match &e.kind {
        ExprKind::Number { digits, unit, .. } => {
            out.push_str(digits);
            if let Some(unit) = unit {
                out.push_str(unit.as_str());
            }
        }
        ExprKind::String(s) => {
            out.push('"');
            out.push_str(s);
            out.push('"');
        }
        ExprKind::Bool(b) => out.push_str(if *b { "TRUE" } else { "FALSE" }),
        ExprKind::Coordinates(parts) => {
            out.push('(');
            write_list(out, parts, source);
            out.push(')');
        }
        ExprKind::Geo(parts) => {
            out.push_str("GEO(");
            write_list(out, parts, source);
            out.push(')');
        }
        ExprKind::Name(name) => out.push_str(&name.name),
        ExprKind::Path(a, b) => {
            out.push_str(&a.name);
            out.push('.');
            out.push_str(&b.name);
        }
        ExprKind::Distance(a, b) => write_call(out, "distance", &[a, b], source),
        ExprKind::Arith(..) => write_chain(out, e, source, |x| match &x.kind {
            ExprKind::Arith(left, op, right) => Some((&**left, op.as_str(), &**right)),
            _ => None,
        }),
        ExprKind::Offset(p, d, b) => write_call(out, "OFFSET", &[p, d, b], source),
        ExprKind::Midpoint(a, b) => write_call(out, "MIDPOINT", &[a, b], source),
        ExprKind::Received(signal) => {
            out.push_str("RECEIVED(");
            out.push_str(&signal.name);
            out.push(')');
        }
        ExprKind::Elapsed => out.push_str("ELAPSED"),
        ExprKind::Not(inner) => {
            out.push_str("NOT ");
            write_expr(out, inner, source);
        }
        ExprKind::Binary(..) => write_chain(out, e, source, |x| match &x.kind {
            ExprKind::Binary(left, op, right) => Some((&**left, op.as_str(), &**right)),
            _ => None,
        }),
        ExprKind::Paren(inner) => {
            out.push('(');
            write_expr(out, inner, source);
            out.push(')');
        }
        // Only in trees with errors, which are never formatted: the text as written.
        ExprKind::Error => {
            out.push_str(&verbatim(source, e.span.start as usize, e.span.end as usize))
        }
    }
}

pub(super) fn expr_text(e: &Expr, source: &str) -> String {
    let mut out = String::new();
    write_expr(&mut out, e, source);
    out
}

pub(super) fn write_list(out: &mut String, parts: &[Expr], source: &str) {
    for (i, part) in parts.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        write_expr(out, part, source);
    }
}

/// ` WITH a, name=b`, or nothing.
pub(super) fn write_args(out: &mut String, args: &[Arg], source: &str) {
    if args.is_empty() {
        return;
    }
    out.push_str(" WITH ");
    for (i, arg) in args.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        if let Some(name) = &arg.name {
            out.push_str(&name.name);
            out.push('=');
        }
        write_expr(out, &arg.value, source);
    }
}

/// `a, b, c`.
pub(super) fn names(list: &[Ident]) -> String {
    list.iter().map(|i| i.name.as_str()).collect::<Vec<_>>().join(", ")
}

/// Source text on one line, white space collapsed (for nodes that could not be read).
pub(super) fn verbatim(source: &str, start: usize, end: usize) -> String {
    source.get(start..end).unwrap_or("").split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A chain of one kind of operator, left-leaning as the parser builds it (`a + b - c`,
/// `x AND y OR z`), written left to right without recursing down the left side: a long
/// chain must not take a frame per operator.
fn write_chain<'e>(
    out: &mut String,
    e: &'e Expr,
    source: &str,
    split: impl Fn(&'e Expr) -> Option<(&'e Expr, &'static str, &'e Expr)>,
) {
    let mut rights = Vec::new();
    let mut leftmost = e;
    while let Some((left, op, right)) = split(leftmost) {
        rights.push((op, right));
        leftmost = left;
    }
    write_expr(out, leftmost, source);
    for (op, right) in rights.into_iter().rev() {
        out.push(' ');
        out.push_str(op);
        out.push(' ');
        write_expr(out, right, source);
    }
}

/// `name(a, b, ...)`: a form written as a call (`distance`, `OFFSET`, `MIDPOINT`).
fn write_call(out: &mut String, name: &str, args: &[&Expr], source: &str) {
    out.push_str(name);
    out.push('(');
    for (i, a) in args.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        write_expr(out, a, source);
    }
    out.push(')');
}
