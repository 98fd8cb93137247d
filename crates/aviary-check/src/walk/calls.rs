//! The calls of the mission and its capabilities: a capability statement (its
//! capability, actors and arguments), a leash call, and a middle-layer call.

use aviary_api::{BuiltinLeash, Kind};
use aviary_diagnostics::{Code, Span};
use aviary_syntax::ast::*;

use super::{count, quoted, Checker};
use crate::env::*;
use aviary_diagnostics::suggest::did_you_mean;

impl<'a> Checker<'a> {
    pub(super) fn statement(&mut self, s: &'a Statement) {
        let Some(cap) = self.program.capability(&s.capability.name) else {
            self.unknown_capability(s);
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

    /// A statement whose capability no one defines: arguments without WITH, another name
    /// of the world where the capability should be, or a name that is nothing.
    fn unknown_capability(&mut self, s: &'a Statement) {
        // The paper's `drone FlyTo Body_Beacon_Inventory`: the arguments lack WITH.
        if let Some(i) = s.actors.iter().rposition(|a| self.program.capability(&a.name).is_some()) {
            self.arguments_without_with(s, i);
            return;
        }
        let help = did_you_mean(&s.capability.name, self.program.capability_names())
            .unwrap_or_else(|| match self.program.unreadable.as_slice() {
                [] => {
                    "define it with `CAPABILITY Name BY drone:`, or USE the file that does".into()
                }
                [one] => format!("it may be defined in `{one}`, which could not be read"),
                many => format!(
                    "it may be defined in one of {}, which could not be read",
                    many.iter().map(|m| format!("`{m}`")).collect::<Vec<_>>().join(", ")
                ),
            });
        // The last name is something else of the world: say what, and what is missing.
        let actors: Vec<&str> = s.actors.iter().map(|a| a.name.as_str()).collect();
        let all = format!("{} {}", actors.join(" "), s.capability.name);
        let fly_there =
            format!("to fly there, write `{} FlyTo WITH {}`", actors.join(" "), s.capability.name);
        let names_no_capability =
            format!("a statement ends with the capability: `{all} FlyTo WITH ...`");
        // What a name means, not a construct: the rest (an unbound name, a value) has no
        // hint of its own.
        #[allow(clippy::wildcard_enum_match_arm)]
        let what = match self.lookup(&s.capability.name) {
            Meaning::Drone => Some(("a drone, not a capability", names_no_capability)),
            Meaning::Group => Some(("a group of drones, not a capability", names_no_capability)),
            Meaning::Local(Binding::Actor) => {
                Some(("an actor, not a capability", names_no_capability))
            }
            Meaning::Place => Some(("a place, not a capability", fly_there)),
            Meaning::Area => Some(("an area, not a capability", fly_there)),
            Meaning::Line => Some((
                "a line, not a capability",
                format!(
                    "to fly along it, write `{} FollowPath WITH {}`",
                    actors.join(" "),
                    s.capability.name
                ),
            )),
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
    }

    /// `drone FlyTo Body_Beacon_Inventory`: actor `i` is the capability, and the names
    /// after it were meant as its arguments.
    fn arguments_without_with(&mut self, s: &'a Statement, i: usize) {
        let real = &s.actors[i];
        let actors: Vec<&str> = s.actors[..i].iter().map(|a| a.name.as_str()).collect();
        let rest: Vec<&str> = s.actors[i + 1..]
            .iter()
            .map(|a| a.name.as_str())
            .chain([s.capability.name.as_str()])
            .collect();
        let span =
            s.actors[i + 1..].first().map_or(s.capability.span, |a| a.span).to(s.capability.span);
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
    }

    /// The arguments of a call of `cap`: bound to its parameters, each of the kind its
    /// parameter takes, and, when `need_all`, every parameter without a default given one
    /// (a leash call gives only what it changes).
    fn arguments(&mut self, cap: &'a Capability, args: &'a [Arg], at: Span, need_all: bool) {
        let kinds = self.program.param_kinds.get(&cap.name.name).cloned().unwrap_or_default();
        let binding = bind_args(&cap.params, args);
        let params: Vec<&str> = cap.params.iter().map(|p| p.name.as_str()).collect();
        for problem in &binding.problems {
            self.binding_problem(cap, &params, &binding.bound, problem);
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
                Section::Requirements { .. }
                | Section::Perform { .. }
                | Section::Exceptions { .. } => None,
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

    /// An argument that binds to no parameter of `cap`, or to one already bound (`bound`:
    /// the arguments by parameter), or one too many.
    fn binding_problem(
        &mut self,
        cap: &Capability,
        params: &[&str],
        bound: &[Option<&Expr>],
        problem: &BindProblem,
    ) {
        match problem {
            BindProblem::UnknownName(n) => {
                let help = did_you_mean(&n.name, params.iter().copied()).unwrap_or_else(|| {
                    if params.is_empty() {
                        format!("`{}` takes no arguments", cap.name.name)
                    } else {
                        format!("the parameters of `{}` are {}", cap.name.name, params.join(", "))
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
                let first =
                    params.iter().position(|p| *p == n.name).and_then(|i| bound[i]).map(|e| e.span);
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
                    format!("its parameters are {}", quoted(params))
                });
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

    pub(super) fn leash(&mut self, l: &'a LeashCall) {
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
                Section::Requirements { .. }
                | Section::Defaults { .. }
                | Section::Perform { .. }
                | Section::Exceptions { .. } => None,
            })
            .collect();
        let builtin = BuiltinLeash::ALL.map(BuiltinLeash::as_str);
        if BuiltinLeash::parse(&l.action.name).is_none()
            && !sections.contains(&l.action.name.as_str())
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

    pub(super) fn api_call(&mut self, call: &'a ApiCall) {
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
        let Some(f) = self.program.api_function(self.file, call) else {
            self.unknown_api_function(call);
            return;
        };
        self.api_argument_count(call, f);
        let kinds: Vec<Option<Kind>> = call.args.iter().map(|arg| self.kind_of(arg)).collect();
        let (n, last) = (call.args.len(), kinds.last().copied().flatten());
        for ((j, arg), actual) in call.args.iter().enumerate().zip(kinds) {
            let p = f.param_at(j, n, last);
            let what = p.map_or(format!("`{}`'s argument", f.name()), |p| {
                format!("`{}`'s `{}`", f.name(), p.name)
            });
            if let (Some(p), Some(k)) = (p, actual) {
                if f.accepts(p, k) {
                    continue;
                }
            }
            self.fits(arg, actual, p.map(|p| p.kind), &what);
        }
    }

    fn unknown_api_function(&mut self, call: &ApiCall) {
        let names: Vec<&str> = self.api.functions.iter().map(|f| f.name()).collect();
        let help = did_you_mean(&call.function.name, names.iter().copied())
            .or_else(|| {
                same_start(&call.function.name, names.iter().copied())
                    .map(|c| format!("did you mean `{c}`?"))
            })
            .unwrap_or_else(|| format!("the middle layer's functions are {}", names.join(", ")));
        let d = self.report(
            Code::UnknownApiFunction,
            call.function.span,
            format!("the middle layer has no function `{}`", call.function.name),
        );
        d.help = Some(help);
    }

    /// Too few arguments for `f`, or too many.
    fn api_argument_count(&mut self, call: &ApiCall, f: &aviary_api::Signature) {
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
