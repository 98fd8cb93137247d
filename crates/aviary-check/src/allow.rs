//! `ALLOW CODE "reason"`: a warning the mission's author expects, acknowledged on the item
//! after the line (docs/LANGUAGE.md, section 22).
//!
//! The checker reads the ALLOW lines once ([`collect`], with the errors of those that
//! cannot apply); [`acknowledge`] applies them where the checker's and the pre-flight
//! analyses' diagnostics are combined. Every front end (`aviary check`, the station, the
//! language server) calls that one function, so they never disagree on what an ALLOW
//! acknowledges.

use aviary_diagnostics::suggest::did_you_mean;
use aviary_diagnostics::{Code, Diagnostic, FileId, Label, Severity, Span};
use aviary_syntax::ast::{Body, Item, Stmt};

use crate::Program;

/// An ALLOW that can apply: its code is a warning's and an item follows it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Allow {
    pub file: FileId,
    pub code: Code,
    pub reason: String,
    /// The ALLOW line.
    pub span: Span,
    /// The item it applies to, its body included: the first after it that is no ALLOW.
    pub item: Span,
}

/// Every ALLOW of the program's files that can apply; the others are reported (E134).
pub(crate) fn collect(program: &Program, diagnostics: &mut Vec<Diagnostic>) -> Vec<Allow> {
    let mut out = Vec::new();
    for (file, tree) in &program.files {
        for item in &tree.items {
            let bodies = match item {
                Item::Mission(m) => vec![&m.body],
                Item::Capability(c) => crate::env::capability_bodies(c),
                Item::Use(_) => Vec::new(),
            };
            for body in bodies {
                in_body(*file, body, &mut out, diagnostics);
            }
        }
    }
    out
}

fn in_body(file: FileId, body: &Body, out: &mut Vec<Allow>, diagnostics: &mut Vec<Diagnostic>) {
    for (i, stmt) in body.items.iter().enumerate() {
        stmt.for_each_body(|inner| in_body(file, inner, out, diagnostics));
        let Stmt::Allow(a) = stmt else { continue };
        let written = a.code.name.to_ascii_uppercase();
        let code = match Code::from_str(&written) {
            Some(code) if code.severity() == Severity::Warning && code != Code::AllowUnused => code,
            Some(code) => {
                let (what, help) = match code.severity() {
                    Severity::Error => ("an error's", "an error stops the mission from flying: fix what it says"),
                    Severity::Note => ("a note's", "a note only informs and does not count against the mission: leave the ALLOW out"),
                    Severity::Warning => ("the unused ALLOW's", "remove the ALLOW that matches nothing instead"),
                };
                diagnostics.push(
                    Diagnostic::new(
                        Code::AllowInvalid,
                        file,
                        a.code.span,
                        format!("`{written}` is {what} code; only a warning can be allowed"),
                    )
                    .label("not a warning")
                    .with_help(help),
                );
                continue;
            }
            None => {
                let warnings = Code::ALL
                    .iter()
                    .filter(|c| c.severity() == Severity::Warning)
                    .map(|c| c.as_str());
                let mut help = "an ALLOW names a warning's code, such as `W203`; `aviary explain CODE` describes one".to_string();
                if let Some(guess) = did_you_mean(&written, warnings) {
                    help = format!("{guess} ({help})");
                }
                diagnostics.push(
                    Diagnostic::new(
                        Code::AllowInvalid,
                        file,
                        a.code.span,
                        format!("no diagnostic has the code `{}`", a.code.name),
                    )
                    .label("unknown code")
                    .with_help(help),
                );
                continue;
            }
        };
        let next = body.items[i + 1..].iter().find(|s| !matches!(s, Stmt::Allow(_)));
        let Some(next) = next else {
            diagnostics.push(
                Diagnostic::new(Code::AllowInvalid, file, a.span, format!("`ALLOW {written}` stands before nothing"))
                    .label("no item after it")
                    .with_help("an ALLOW applies to the item on the line after it: put it directly before the statement, block or handler the warning is about"),
            );
            continue;
        };
        out.push(Allow { file, code, reason: a.reason.clone(), span: a.span, item: next.span() });
    }
}

/// Applies `allows` to the combined diagnostics of a check: a warning of an ALLOW's code
/// whose primary place, or any other place it shows, lies in the ALLOW's item becomes a
/// note "acknowledged: REASON" (its code kept); an ALLOW that acknowledged nothing is a
/// warning (W211). That warning is given only when the analyses that could have found
/// the code ran: no error anywhere (the checker's semantic passes and the pre-flight
/// analyses need none), and `preflight` for the pre-flight analyses' codes
/// ([`Code::PREFLIGHT`]). Sorts the result.
pub fn acknowledge(allows: &[Allow], diagnostics: &mut Vec<Diagnostic>, preflight: bool) {
    let mut used = vec![false; allows.len()];
    for d in diagnostics.iter_mut() {
        if d.severity != Severity::Warning {
            continue;
        }
        let inside = |a: &Allow, l: &Label| {
            l.file == a.file && a.item.start <= l.span.start && l.span.end <= a.item.end
        };
        let found = allows.iter().position(|a| {
            a.code == d.code
                && std::iter::once(&d.primary).chain(&d.secondary).any(|l| inside(a, l))
        });
        let Some(at) = found else { continue };
        let a = &allows[at];
        used[at] = true;
        d.severity = Severity::Note;
        d.message = format!("{} (acknowledged: {})", d.message, a.reason);
        d.secondary.push(Label { file: a.file, span: a.span, message: "acknowledged here".into() });
    }
    let complete = !diagnostics.iter().any(Diagnostic::is_error);
    for (a, used) in allows.iter().zip(used) {
        if used || !complete || (!preflight && Code::PREFLIGHT.contains(&a.code)) {
            continue;
        }
        diagnostics.push(
            Diagnostic::new(Code::AllowUnused, a.file, a.span, format!("ALLOW {} matches no warning here; remove it", a.code))
                .label(format!("no {} on the item after this line", a.code))
                .with_help("the warning it acknowledged is gone (or lies elsewhere): remove the ALLOW, or move it to the line before the item the warning points at"),
        );
    }
    aviary_diagnostics::sort(diagnostics);
}
