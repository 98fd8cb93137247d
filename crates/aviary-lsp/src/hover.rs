//! Hover: what a name means (a capability's signature with its parameters' kinds,
//! defaults and comment; a place's coordinates; a drone's group, sensors and battery; a
//! signal's values; a middle-layer function or telemetry field), and the explanation of
//! each diagnostic at the position.

use aviary_check::Program;
use aviary_diagnostics::FileId;
use aviary_syntax::ast::{Capability, Item, Section};
use lsp_types::{Hover, HoverContents, HoverParams, MarkupContent, MarkupKind};

use crate::analysis::Analysis;
use crate::index::{self, Sym};
use crate::text::{word_at, LineIndex};
use crate::Server;

pub fn hover(server: &Server, p: HoverParams) -> Option<Hover> {
    let at = p.text_document_position_params;
    let (_, a, file) = server.lookup(&at.text_document.uri)?;
    let text = a.sources.text(file);
    let lines = LineIndex::new(text);
    let offset = lines.offset(at.position);
    let mut parts = Vec::new();
    let mut range = None;
    if let Some(o) = index::at(&a.occurrences, file, offset as u32) {
        parts.push(describe(a, &o.sym));
        range = Some(lines.range(o.span));
    } else if let Some((start, end)) = word_at(text, offset) {
        let word = &text[start..end];
        let api = aviary_api::Descriptor::standard();
        if start > 0 && text.as_bytes()[start - 1] == b'.' {
            if let Some(f) = api.function(word) {
                let params: Vec<String> = f
                    .params
                    .iter()
                    .map(|p| format!("- `{}`: {}", p.name, p.kind.describe()))
                    .collect();
                parts.push(format!(
                    "```aviary\n{}\n```\nmiddle-layer function: {}\n\n{}",
                    f.signature(),
                    f.summary,
                    params.join("\n")
                ));
            } else if let Some(kind) = api.telemetry(word) {
                parts.push(format!("```aviary\n{word}\n```\ntelemetry: {}", kind.describe()));
            }
        } else if let Some(c) = a.program.as_ref().and_then(|p| p.capability(word)) {
            parts.push(capability(a, c));
        }
        if !parts.is_empty() {
            range = Some(lines.range(aviary_diagnostics::Span::new(start, end)));
        }
    }
    for d in &a.diagnostics {
        let span = d.primary.span;
        if d.primary.file == file && span.start as usize <= offset && offset <= span.end as usize {
            parts.push(crate::explain::markdown(d.code));
            range.get_or_insert_with(|| lines.range(span));
        }
    }
    (!parts.is_empty()).then(|| Hover {
        contents: HoverContents::Markup(MarkupContent {
            kind: MarkupKind::Markdown,
            value: parts.join("\n\n---\n\n"),
        }),
        range,
    })
}

fn num(x: f64) -> String {
    let r = (x * 100.0).round() / 100.0;
    if r.fract() == 0.0 {
        format!("{r:.0}")
    } else {
        format!("{r}")
    }
}

fn point(p: &[f64]) -> String {
    let parts: Vec<String> = p.iter().map(|x| num(*x)).collect();
    format!("({})", parts.join(", "))
}

pub fn describe(a: &Analysis, sym: &Sym) -> String {
    let world = a.world.as_ref();
    match sym {
        Sym::Capability(name) => match a.program.as_ref().and_then(|p| p.capability(name)) {
            Some(c) => capability(a, c),
            None => format!("```aviary\n{name}\n```\nno capability of this name is defined"),
        },
        Sym::Param { capability: cap, name } => {
            let kind = a.program.as_ref().and_then(|p| param_kind(p, cap, name));
            format!("```aviary\n{name}\n```\nparameter of `{cap}`: {}", kind.unwrap_or("its kind follows from its use"))
        }
        Sym::Place(name) => match world.and_then(|w| w.places.iter().find(|p| &p.name == name)) {
            Some(p) => {
                let at = if p.has_z { point(&p.at) } else { point(&p.at[..2]) };
                format!("```aviary\n{name}\n```\nplace at {at} (metres east, north{} of the origin)", if p.has_z { ", up" } else { "" })
            }
            None => format!("place `{name}`"),
        },
        Sym::Area(name) => match world.and_then(|w| w.areas.iter().find(|x| &x.name == name)) {
            Some(area) => {
                let corners: Vec<String> = area.polygon.iter().map(|c| point(c)).collect();
                format!("```aviary\n{name}\n```\narea of {} corners: {}\n\ncentroid {}", area.polygon.len(), corners.join(", "), point(&area.centroid()))
            }
            None => format!("area `{name}`"),
        },
        Sym::Drone(name) => match world.and_then(|w| w.drones.iter().find(|d| &d.name == name)) {
            Some(d) => {
                let list = |v: &[String]| if v.is_empty() { "none".to_string() } else { v.join(", ") };
                format!(
                    "```aviary\n{name}\n```\ndrone of group {}\n\n- home: {}\n- sensors: {}\n- payload: {}\n- battery: {}% at the start, {} s of flight on a full one\n- max speed: {} m/s",
                    d.group.as_deref().map_or("(none)".to_string(), |g| format!("`{g}`")),
                    point(&d.home), list(&d.sensors), list(&d.payload), num(d.battery), num(d.endurance), num(d.max_speed)
                )
            }
            None => format!("drone `{name}`"),
        },
        Sym::Group(name) => match world.and_then(|w| w.groups.iter().find(|g| &g.name == name)) {
            Some(g) => {
                let members: Vec<&str> = g.members.iter().filter_map(|&i| world.and_then(|w| w.drones.get(i)).map(|d| d.name.as_str())).collect();
                format!("```aviary\n{name}\n```\ngroup of {} drones: {}", members.len(), members.join(", "))
            }
            None => format!("group `{name}`"),
        },
        Sym::Signal(name) => {
            let raised = a.occurrences.iter().filter(|o| o.definition && o.sym == *sym).count();
            let handled = a.occurrences.iter().filter(|o| !o.definition && o.sym == *sym).count();
            let api = aviary_api::Descriptor::standard();
            let builtin = api.signal(name).map(|_| " (built in: raised by the drones)").unwrap_or("");
            let values = a.program.as_ref().and_then(|p| p.signal_values.get(name)).map(|v| {
                let kinds: Vec<&str> = v.iter().map(|k| k.map_or("a value", |k| k.describe())).collect();
                if kinds.is_empty() { "no values".to_string() } else { format!("values: {}", kinds.join("; ")) }
            });
            let places = |n: usize| if n == 1 { "1 place".to_string() } else { format!("{n} places") };
            format!(
                "```aviary\nSIGNAL {name}\n```\nsignal{builtin}: raised in {}, heard or tested in {}{}",
                places(raised),
                places(handled),
                values.map(|v| format!("\n\n{v}")).unwrap_or_default()
            )
        }
        Sym::Exception(name) => {
            let api = aviary_api::Descriptor::standard();
            let origin = if api.is_exception(name) { "built-in exception" } else { "exception" };
            format!("```aviary\nEXCEPTION {name}\n```\n{origin}")
        }
        Sym::Local { name, what, .. } => format!("```aviary\n{name}\n```\n{what}"),
        Sym::Tag(name) => format!("```aviary\n{name}\n```\nactivity tag: a leash (`{name} PAUSE`, `ABORT`, `RESUME`) names the activity by it"),
    }
}

fn param_kind(p: &Program, cap: &str, name: &str) -> Option<&'static str> {
    let c = p.capability(cap)?;
    let i = c.params.iter().position(|x| x.name == name)?;
    p.param_kinds.get(cap)?.get(i).copied().flatten().map(|k| k.describe())
}

/// The file a capability is defined in.
pub fn file_of(a: &Analysis, c: &Capability) -> Option<FileId> {
    let p = a.program.as_ref()?;
    p.files.iter().find_map(|(f, tree)| {
        tree.items
            .iter()
            .any(|i| matches!(i, Item::Capability(x) if std::ptr::eq(x, c)))
            .then_some(*f)
    })
}

/// The comment lines right above `start` in `text` (no blank line between).
pub fn doc_comment(text: &str, start: usize) -> String {
    let mut lines = Vec::new();
    for line in text[..start.min(text.len())].lines().rev() {
        let t = line.trim();
        if let Some(c) = t.strip_prefix("//") {
            lines.push(c.trim().to_string());
        } else if t.is_empty() && lines.is_empty() {
            continue;
        } else {
            break;
        }
    }
    lines.reverse();
    lines.join("\n")
}

/// `CAPABILITY Name BY drone WITH a, b` with each parameter's kind and default, where it
/// is defined, and its comment.
pub fn capability(a: &Analysis, c: &Capability) -> String {
    let file = file_of(a, c);
    let text = file.map(|f| a.sources.text(f)).unwrap_or("");
    let mut head = format!("CAPABILITY {}", c.name.name);
    if !c.actors.is_empty() {
        let actors: Vec<&str> = c.actors.iter().map(|x| x.name.as_str()).collect();
        head.push_str(&format!(" BY {}", actors.join(", ")));
    }
    if !c.params.is_empty() {
        let params: Vec<&str> = c.params.iter().map(|x| x.name.as_str()).collect();
        head.push_str(&format!(" WITH {}", params.join(", ")));
    }
    let mut out = format!("```aviary\n{head}\n```\n");
    let defaults: Vec<(&str, &str)> = c
        .sections
        .iter()
        .flat_map(|s| match s {
            Section::Defaults { entries, .. } => entries.as_slice(),
            _ => &[],
        })
        .map(|e| (e.name.name.as_str(), text.get(e.value.span.range()).unwrap_or("")))
        .collect();
    for x in &c.params {
        let kind = a.program.as_ref().and_then(|p| param_kind(p, &c.name.name, &x.name));
        let default = defaults
            .iter()
            .find(|(n, _)| *n == x.name)
            .map(|(_, v)| format!(", default `{v}`"))
            .unwrap_or_default();
        out.push_str(&format!(
            "- `{}`: {}{default}\n",
            x.name,
            kind.unwrap_or("kind follows from use")
        ));
    }
    let name = file.map(|f| a.sources.name(f)).unwrap_or("");
    if name == aviary_check::STD_NAME {
        out.push_str("\nfrom the standard library\n");
    }
    let doc = doc_comment(text, c.span.start as usize);
    if !doc.is_empty() {
        out.push_str(&format!("\n{doc}\n"));
    }
    out.trim_end().to_string()
}
