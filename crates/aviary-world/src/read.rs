//! Typed readers over the spanned tree: each one either returns the value or records a
//! located diagnostic and returns `None`, so that one pass reports every problem.

use aviary_api::show::number;
use std::fmt::Display;

use aviary_diagnostics::{Code, Diagnostic, FileId, Span};

use crate::node::{Entry, Node, Value};

/// Gathers the diagnostics of one world file.
pub(crate) struct Ctx<'a> {
    pub file: FileId,
    pub text: &'a str,
    pub diags: Vec<Diagnostic>,
}

impl Ctx<'_> {
    pub fn error(&mut self, span: Span, message: impl Into<String>, help: impl Into<String>) {
        let d = Diagnostic::new(Code::WorldFile, self.file, span, message).with_help(help);
        self.diags.push(d);
    }

    pub fn push(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    /// The first line of a table's span: `[[faults]]` rather than the whole entry.
    pub fn header(&self, span: Span) -> Span {
        let Some(text) = self.text.get(span.range()) else {
            return span;
        };
        if !text.starts_with('[') {
            return span;
        }
        let len = text.find(['\n', '\r']).unwrap_or(text.len());
        Span::new(span.start as usize, span.start as usize + len)
    }

    pub fn table<'n>(
        &mut self,
        what: &dyn Display,
        node: &'n Node,
        help: &str,
    ) -> Option<&'n [Entry]> {
        match &node.value {
            Value::Table(entries) => Some(entries),
            _ => {
                let msg = format!("{what} must be a table, found {}", node.describe());
                self.error(node.span, msg, help);
                None
            }
        }
    }

    /// Reports every key of `entries` that is not in `known`.
    pub fn known_keys(&mut self, entries: &[Entry], known: &[&str], place: &str) {
        for e in entries.iter().filter(|e| !known.contains(&e.key.as_str())) {
            let list = quoted(known);
            let help = match suggest(&e.key, known.iter().copied()) {
                Some(s) => format!("did you mean `{s}`? The known keys are {list}"),
                None => format!("remove it; the known keys are {list}"),
            };
            self.error(e.key_span, format!("unknown key `{}` in {place}", e.key), help);
        }
    }

    pub fn number(&mut self, what: &dyn Display, node: &Node) -> Option<f64> {
        let value = match node.value {
            Value::Int(i) => i as f64,
            Value::Float(f) => f,
            _ => {
                let msg = format!("{what} must be a number, found {}", node.describe());
                self.error(node.span, msg, "write a number such as `10` or `2.5`");
                return None;
            }
        };
        if !value.is_finite() {
            let msg = format!("{what} must be a finite number");
            self.error(node.span, msg, "write a number such as `10` or `2.5`, not inf or nan");
            return None;
        }
        Some(value)
    }

    /// A number that must be greater than zero.
    pub fn positive(&mut self, what: &dyn Display, node: &Node) -> Option<f64> {
        let value = self.number(what, node)?;
        if value <= 0.0 {
            let msg = format!("{what} must be greater than zero, found {}", number(value));
            self.error(node.span, msg, "write a positive number");
            return None;
        }
        Some(value)
    }

    /// A number that must not be below zero.
    pub fn non_negative(&mut self, what: &dyn Display, node: &Node) -> Option<f64> {
        let value = self.number(what, node)?;
        if value < 0.0 {
            let msg = format!("{what} must not be below zero, found {}", number(value));
            self.error(node.span, msg, "write zero or a positive number");
            return None;
        }
        Some(value)
    }

    /// A number in `min..=max`.
    pub fn within(&mut self, what: &dyn Display, node: &Node, min: f64, max: f64) -> Option<f64> {
        let value = self.number(what, node)?;
        if !(min..=max).contains(&value) {
            let msg = format!(
                "{what} must be between {} and {}, found {}",
                number(min),
                number(max),
                number(value)
            );
            self.error(
                node.span,
                msg,
                format!("write a number from {} to {}", number(min), number(max)),
            );
            return None;
        }
        Some(value)
    }

    pub fn string(&mut self, what: &dyn Display, node: &Node) -> Option<String> {
        match &node.value {
            Value::Str(s) => Some(s.clone()),
            _ => {
                let msg = format!("{what} must be a string, found {}", node.describe());
                self.error(node.span, msg, "write it in quotes, e.g. `\"text\"`");
                None
            }
        }
    }

    /// A list of strings, each with its span.
    pub fn strings(&mut self, what: &dyn Display, node: &Node) -> Option<Vec<(String, Span)>> {
        let help = "write a list of strings, e.g. `[\"Body\", \"Radiation\"]`";
        let Value::Array(items) = &node.value else {
            let msg = format!("{what} must be a list of strings, found {}", node.describe());
            self.error(node.span, msg, help);
            return None;
        };
        let mut out = Some(Vec::new());
        for item in items {
            match (&item.value, out.as_mut()) {
                (Value::Str(s), Some(out)) => out.push((s.clone(), item.span)),
                (Value::Str(_), None) => {}
                _ => {
                    let msg = format!("{what} must hold strings, found {}", item.describe());
                    self.error(item.span, msg, help);
                    out = None;
                }
            }
        }
        out
    }

    /// A polygon's outline must enclose an area and not cross itself: a fence or area
    /// whose corners lie on one line holds nothing, and one whose edges cross (corners
    /// listed out of order) has no clear inside. Reported at the polygon; false then.
    pub fn outline(&mut self, what: &dyn Display, node: &Node, polygon: &[[f64; 2]]) -> bool {
        self.outline_at(what, node.span, polygon)
    }

    /// [`Ctx::outline`], reported at `span`.
    pub fn outline_at(&mut self, what: &dyn Display, span: Span, polygon: &[[f64; 2]]) -> bool {
        let help = "list the corners in order around the area, clockwise or counter-clockwise, e.g. `[[0, 0], [100, 0], [100, 100], [0, 100]]`";
        if let Some((i, j)) = aviary_api::geometry::self_crossing(polygon) {
            let n = polygon.len();
            let msg = format!(
                "{what} crosses itself: its edge from {} to {} crosses its edge from {} to {}",
                shown(polygon[i]),
                shown(polygon[(i + 1) % n]),
                shown(polygon[j]),
                shown(polygon[(j + 1) % n])
            );
            self.error(span, msg, help);
            return false;
        }
        // Square metres: less than this is a line, whatever the units' rounding.
        if aviary_api::geometry::signed_area(polygon).abs() < 1e-6 {
            self.error(span, format!("{what} encloses no area: its corners lie on one line"), help);
            return false;
        }
        true
    }

    /// A height `z` that is below the ground: reported at `node` (the position).
    pub fn above_ground(&mut self, what: &dyn Display, node: &Node, z: f64) -> bool {
        if z < 0.0 {
            let msg = format!("{what} is below the ground: z = {} m", number(z));
            self.error(node.span, msg, "heights are metres above the ground, 0 or more; write `[x, y]` for a point on the ground");
            return false;
        }
        true
    }

    /// A position: `[x, y]` (z = 0) or `[x, y, z]`. Returns the point and whether z was given.
    pub fn point(&mut self, what: &dyn Display, node: &Node) -> Option<([f64; 3], bool)> {
        let help = "write `[x, y]` or `[x, y, z]` in metres, e.g. `[150, 100]`";
        let Value::Array(items) = &node.value else {
            let msg =
                format!("{what} must be a position [x, y] or [x, y, z], found {}", node.describe());
            self.error(node.span, msg, help);
            return None;
        };
        if !(2..=3).contains(&items.len()) {
            let msg =
                format!("{what} must be 2 or 3 numbers, found {}", count(items.len(), "number"));
            self.error(node.span, msg, help);
            return None;
        }
        let mut p = [0.0; 3];
        let mut ok = true;
        for (slot, item) in p.iter_mut().zip(items) {
            match self.number(what, item) {
                Some(v) => *slot = v,
                None => ok = false,
            }
        }
        ok.then_some((p, items.len() == 3))
    }

    /// A polygon `[[x, y], ...]` of at least three points.
    pub fn polygon(&mut self, what: &dyn Display, node: &Node) -> Option<Vec<[f64; 2]>> {
        let help = "write at least three corners, e.g. `[[0, 0], [100, 0], [100, 100]]`";
        let Value::Array(items) = &node.value else {
            let msg = format!("{what} must be a polygon [[x, y], ...], found {}", node.describe());
            self.error(node.span, msg, help);
            return None;
        };
        let mut out = Some(Vec::new());
        for item in items {
            let corner = match &item.value {
                Value::Array(xy) if xy.len() == 2 => {
                    let x = self.number(what, &xy[0]);
                    let y = self.number(what, &xy[1]);
                    x.zip(y).map(|(x, y)| [x, y])
                }
                Value::Array(xy) => {
                    let msg = format!(
                        "a corner of {what} must be 2 numbers [x, y], found {}",
                        count(xy.len(), "number")
                    );
                    self.error(item.span, msg, "write each corner as `[x, y]`");
                    None
                }
                _ => {
                    let msg =
                        format!("a corner of {what} must be [x, y], found {}", item.describe());
                    self.error(item.span, msg, "write each corner as `[x, y]`");
                    None
                }
            };
            match (corner, out.as_mut()) {
                (Some(c), Some(out)) => out.push(c),
                (None, _) => out = None,
                _ => {}
            }
        }
        if items.len() < 3 {
            let msg =
                format!("{what} has {}; a polygon needs at least 3", count(items.len(), "point"));
            self.error(node.span, msg, help);
            return None;
        }
        out
    }

    /// Checks that mission code can refer to `name`.
    pub fn identifier(&mut self, what: &str, name: &str, span: Span) -> bool {
        if is_identifier(name) {
            return true;
        }
        let msg =
            format!("{what} `{name}` is not a valid name, so mission code could not refer to it");
        let help = format!(
            "use letters, digits and `_`, not starting with a digit, e.g. `{}`",
            to_identifier(name)
        );
        self.error(span, msg, help);
        false
    }
}

pub(crate) fn is_identifier(name: &str) -> bool {
    // Byte by byte: a character outside ASCII is none of these, and neither is any of
    // its bytes.
    let mut bytes = name.bytes();
    matches!(bytes.next(), Some(c) if c.is_ascii_alphabetic() || c == b'_')
        && bytes.all(|c| c.is_ascii_alphanumeric() || c == b'_')
}

fn to_identifier(name: &str) -> String {
    let mut out: String =
        name.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '_' }).collect();
    if !out.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_') {
        out.insert(0, '_');
    }
    out
}

/// "1 point", "4 points".
pub(crate) fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

/// "`a`, `b`, `c`".
pub(crate) fn quoted<'a>(names: impl IntoIterator<Item = &'a &'a str>) -> String {
    names.into_iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}

/// The closest of `candidates` to `name`, if it is close enough to be a likely typo.
pub(crate) fn suggest<'a>(
    name: &str,
    candidates: impl Iterator<Item = &'a str>,
) -> Option<&'a str> {
    let len = name.chars().count();
    let limit = match len {
        0..=2 => 0,
        3..=5 => 1,
        _ => (len / 3).max(2),
    };
    candidates
        .map(|c| (distance(&name.to_lowercase(), &c.to_lowercase()), c))
        .filter(|(d, _)| *d <= limit)
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| c)
}

/// Edit distance by characters, a swap of two neighbours counting as one edit.
fn distance(a: &str, b: &str) -> usize {
    let (a, b): (Vec<char>, Vec<char>) = (a.chars().collect(), b.chars().collect());
    let mut d = vec![vec![0usize; b.len() + 1]; a.len() + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    for (j, cell) in d[0].iter_mut().enumerate() {
        *cell = j;
    }
    for i in 1..=a.len() {
        for j in 1..=b.len() {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut best = (d[i - 1][j] + 1).min(d[i][j - 1] + 1).min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = best;
        }
    }
    d[a.len()][b.len()]
}

/// A ground point as messages show it: `(x, y)`.
pub(crate) fn shown(p: [f64; 2]) -> String {
    format!("({}, {})", number(p[0]), number(p[1]))
}

/// The TOML text of a value, for attributes that are lists or tables.
pub(crate) fn toml_text(node: &Node) -> String {
    match &node.value {
        Value::Str(s) => toml::Value::String(s.clone()).to_string(),
        Value::Int(i) => i.to_string(),
        Value::Float(f) if f.is_nan() => "nan".into(),
        Value::Float(f) if f.is_infinite() => if *f > 0.0 { "inf" } else { "-inf" }.into(),
        Value::Float(f) => format!("{f:?}"),
        Value::Bool(b) => b.to_string(),
        Value::Datetime(d) => d.clone(),
        Value::Array(items) => {
            format!("[{}]", items.iter().map(toml_text).collect::<Vec<_>>().join(", "))
        }
        Value::Table(entries) if entries.is_empty() => "{}".into(),
        Value::Table(entries) => {
            let body: Vec<String> = entries
                .iter()
                .map(|e| format!("{} = {}", key_text(&e.key), toml_text(&e.node)))
                .collect();
            format!("{{ {} }}", body.join(", "))
        }
    }
}

fn key_text(key: &str) -> String {
    let bare =
        !key.is_empty() && key.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
    if bare {
        key.to_owned()
    } else {
        toml::Value::String(key.to_owned()).to_string()
    }
}
