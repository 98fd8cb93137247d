//! `LET name = value`: where a LET's name is seen, what it may not reuse (E132), and a
//! name read where its LET does not reach (E133). A name is seen from the item after its
//! LET to the end of the LET's body, nested bodies included; a handler of that body sees
//! it only when nothing that takes time comes before the LET, since the handler listens
//! from the start of the body and may fire before the LET is reached.

use aviary_api::Kind;
use aviary_diagnostics::{Code, Label};
use aviary_syntax::ast::*;
use aviary_syntax::visit::for_each_stmt;

use super::Checker;
use crate::env::*;

/// The bindings a handler may not see, and how many LETs were hidden before.
pub(super) type Hidden<'a> = (Vec<(&'a str, Binding)>, usize);

/// Every LET in `bodies`, nested bodies included, in source order.
pub(super) fn all_lets<'a>(bodies: &[&'a Body]) -> Vec<&'a Let> {
    let mut out = Vec::new();
    for body in bodies {
        for_each_stmt(body, |stmt| {
            if let Stmt::Let(l) = stmt {
                out.push(l);
            }
        });
    }
    out
}

impl<'a> Checker<'a> {
    /// Checks a LET's value and binds its name in the innermost scope (the body's).
    pub(super) fn let_stmt(&mut self, l: &'a Let) {
        let mut kind = self.value(&l.value, None, "the LET's value");
        if kind == Some(Kind::Actor) {
            let d = self.report(
                Code::WrongKind,
                l.value.span,
                "a LET names a value, and this is a drone or group, which has a name already",
            );
            d.primary.message = "a drone or group".into();
            d.help = Some(format!(
                "use the drone's own name where it is needed; for where it is now, write `LET {} = DRONE.position`",
                l.name.name
            ));
            kind = None;
        }
        if self.taken(l) {
            return;
        }
        if let Some(scope) = self.scopes.last_mut() {
            scope.push((l.name.name.as_str(), Binding::Value(kind)));
        }
    }

    /// Whether the LET's name is bound here already (reported, E132).
    fn taken(&mut self, l: &'a Let) -> bool {
        let name = l.name.name.as_str();
        let what = match self.lookup(name) {
            Meaning::Unbound => return false,
            Meaning::Local(_) => {
                let earlier = self
                    .lets
                    .iter()
                    .find(|e| e.name.name == name && e.span.start < l.span.start)
                    .filter(|e| self.in_scope(e));
                if let Some(first) = earlier {
                    let (file, span) = (self.file, first.name.span);
                    let d = self.report(
                        Code::LetTaken,
                        l.name.span,
                        format!(
                            "`{name}` is already defined by a LET, and a LET's value never changes"
                        ),
                    );
                    d.secondary.push(Label { file, span, message: "first defined here".into() });
                    d.help = Some(format!(
                        "give the new value a name of its own, such as `{name}_2`; or, for a value that changes, read it where it is needed"
                    ));
                    return true;
                }
                "a parameter, a FOR alias or a handler's value here"
            }
            Meaning::Drone => "a drone of the world",
            Meaning::Group => "a group of the world",
            Meaning::Place => "a place of the world",
            Meaning::Area => "an area of the world",
            Meaning::Line => "a line of the world",
        };
        let d = self.report(
            Code::LetTaken,
            l.name.span,
            format!("`{name}` is {what}, so a LET cannot name a value `{name}`"),
        );
        d.help = Some(format!(
            "give the LET a name of its own, such as `my_{name}`: a LET never hides another name"
        ));
        true
    }

    /// Whether a LET's name is bound in the scopes open now (and not hidden).
    fn in_scope(&self, l: &Let) -> bool {
        self.scopes.iter().flatten().any(|(n, _)| *n == l.name.name)
    }

    /// Takes `late` LETs out of the innermost scope while a handler of that body is
    /// checked; what `unhide` puts back.
    pub(super) fn hide(&mut self, late: &[&'a Let]) -> Hidden<'a> {
        let before = self.hidden.len();
        let mut taken = Vec::new();
        if let Some(scope) = self.scopes.last_mut() {
            scope.retain(|(n, b)| {
                let hide = late.iter().any(|l| l.name.name == *n);
                if hide {
                    taken.push((*n, *b));
                }
                !hide
            });
        }
        self.hidden.extend_from_slice(late);
        (taken, before)
    }

    pub(super) fn unhide(&mut self, (taken, before): Hidden<'a>) {
        self.hidden.truncate(before);
        if let Some(scope) = self.scopes.last_mut() {
            scope.extend(taken);
        }
    }

    /// A name that no scope binds, but that a LET of this mission or capability defines
    /// elsewhere: reported (E133), and `true`.
    pub(super) fn let_not_here(&mut self, id: &Ident) -> bool {
        let name = id.name.as_str();
        if let Some(l) = self.hidden.iter().find(|l| l.name.name == name).copied() {
            let line = self.line(l.span.start);
            let d = self.report(
                Code::LetNotHere,
                id.span,
                format!("this handler may run before `LET {name}` (line {line}) is reached"),
            );
            d.primary.message = format!("`{name}` may not be set yet");
            d.help = Some(format!(
                "a handler listens from the start of its body: move `LET {name} = ...` up, before the first item that takes time, or write the LET inside the handler"
            ));
            return true;
        }
        let Some(l) = self.lets.iter().find(|l| l.name.name == name).copied() else {
            return false;
        };
        let line = self.line(l.span.start);
        if l.span.start > id.span.start {
            let d = self.report(
                Code::LetNotHere,
                id.span,
                format!("`{name}` is used before its LET (line {line})"),
            );
            d.primary.message = format!("`{name}` is not defined yet");
            d.help = Some(format!("move `LET {name} = ...` before this line: a LET's name is seen from the next line on"));
        } else {
            let d = self.report(
                Code::LetNotHere,
                id.span,
                format!("`{name}` is defined by a LET (line {line}) whose body ends before this"),
            );
            d.primary.message = format!("`{name}` is not defined here");
            d.help = Some(format!(
                "a LET's name is seen from the next line to the end of its body: move `LET {name} = ...` out to a body that holds this line too"
            ));
        }
        true
    }

    /// The line (from 1) of a byte of the file being checked.
    fn line(&self, at: u32) -> u32 {
        let tree = self.program.files.iter().find(|(f, _)| *f == self.file);
        tree.map_or(0, |(_, t)| t.line_of(at))
    }
}
