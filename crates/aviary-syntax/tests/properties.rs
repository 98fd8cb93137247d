//! Properties of the parser and the formatter: the parser never panics and keeps its
//! spans inside the text; the formatter is idempotent and keeps the tree (spans ignored)
//! on every valid mission; deep nesting is reported, never a stack overflow.

mod common;

use aviary_diagnostics::{Code, FileId};
use aviary_syntax::{parse, parse_bytes, Parse};
use common::check_format;
use proptest::prelude::*;

/// 256 cases per property (a few seconds in a debug build); `PROPTEST_CASES=100000` for
/// a long hunt.
fn config() -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256);
    ProptestConfig { cases, failure_persistence: None, ..ProptestConfig::default() }
}

/// Every span the parse reports lies inside the text; and a parse without errors formats
/// correctly (idempotent, same tree, every comment kept).
fn check_parse(len: usize, text: &str, parse: &Parse) {
    for d in &parse.diagnostics {
        for label in std::iter::once(&d.primary).chain(&d.secondary) {
            assert!(
                label.span.start <= label.span.end && label.span.end as usize <= len,
                "{} at {:?} is outside the text of {len} bytes: {}\n{text:?}",
                d.code.as_str(),
                label.span,
                d.message
            );
        }
    }
    for (start, end) in tree_spans(&format!("{:?}", parse.tree)) {
        assert!(
            start <= end && end <= len,
            "a tree span {start}..{end} outside the text of {len} bytes\n{text:?}"
        );
    }
    for c in &parse.tree.comments {
        assert!(c.span.end as usize <= len, "comment span {:?} outside the text", c.span);
    }
    assert!(parse.line_starts.windows(2).all(|w| w[0] < w[1]), "line starts out of order");
    assert!(
        parse.line_starts.iter().all(|&s| (s as usize) < len.max(1)),
        "a line start outside the text"
    );
    if !parse.has_errors() {
        check_format(text);
    }
}

/// Every `Span { start, end }` in a tree's `Debug` text, and every `header_end` (as an
/// empty span).
fn tree_spans(debug: &str) -> Vec<(usize, usize)> {
    let number = |text: &str| -> Option<usize> {
        text[..text.find(|c: char| !c.is_ascii_digit()).unwrap_or(text.len())].parse().ok()
    };
    let mut spans = Vec::new();
    for (at, _) in debug.match_indices("Span { start: ") {
        let rest = &debug[at + "Span { start: ".len()..];
        let start = number(rest);
        let end = rest.find("end: ").and_then(|i| number(&rest[i + 5..]));
        if let (Some(start), Some(end)) = (start, end) {
            spans.push((start, end));
        }
    }
    for (at, _) in debug.match_indices("header_end: ") {
        if let Some(end) = number(&debug[at + "header_end: ".len()..]) {
            spans.push((end, end));
        }
    }
    spans
}

fn check_bytes(bytes: &[u8]) {
    let (text, parse) = parse_bytes(FileId(0), bytes);
    check_parse(bytes.len(), &text, &parse);
}

// ---------------------------------------------------------------------------------------
// (a) Arbitrary input never panics.

const FRAGMENTS: &[&str] = &[
    "MISSION", "SEQUENTIAL", "PARALLEL", "ON", "EVERY", "BY", "WITH", "FOR", "AND", "AS", "SIGNAL", "THROW", "EXCEPTION",
    "STARTIF", "WAITFOR", "DOWHILE", "IF", "ELSE", "CAPABILITY", "REQUIREMENTS", "DEFAULTS", "PERFORM", "EXCEPTIONS",
    "ABORT", "PAUSE", "RESUME", "USE", "NOT", "OR", "TRUE", "FALSE", "ELAPSED", "RECEIVED(", "distance(", "GEO(", "OFFSET(", "MIDPOINT(", "LET", "+",
    "mission", "With", "drone", "d1", "Area", "Home", "FlyTo", "Cap-Tag", "x.y", "drone.Land()", ":", ":", ",", "(", ")",
    ".", "=", "!=", "<", "<=", ">", ">=", "==", "-", "/", "%", "20m", "20 m", "5m/s", "5 km/h", "25%", "-3", "1.5",
    "1e9", "99999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999999m",
    "20xyz", "\"a string\"", "\"open", "// comment\n", "/* block */", "/*", "*/", "\n", "\n", "\n", "\r\n", " ", " ", "  ",
    "    ", "        ", "\n    ", "\n        ", "\n  ", "\t", "é", "\u{1F681}", "#",
];

fn mission_ish() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(FRAGMENTS), 0..120).prop_map(|parts| {
        let mut text = String::new();
        for (i, p) in parts.iter().enumerate() {
            // Words mostly need a space between them.
            if i % 3 != 0 && !text.ends_with(['\n', ' ']) {
                text.push(' ');
            }
            text.push_str(p);
        }
        text
    })
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        check_bytes(&bytes);
    }

    #[test]
    fn mission_ish_text_never_panics(text in mission_ish()) {
        check_bytes(text.as_bytes());
    }
}

// ---------------------------------------------------------------------------------------
// (b) Mutations of valid files never panic.

fn fixtures() -> Vec<String> {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fmt");
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .expect("the fixture directory")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mission"))
        .map(|p| std::fs::read_to_string(p).expect("read a fixture"))
        .collect();
    files.sort();
    let example = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/search_and_rescue.mission");
    files.push(std::fs::read_to_string(example).expect("read the example"));
    files
}

#[derive(Clone, Debug)]
enum Mutation {
    DeleteChar(usize),
    InsertChar(usize, u8),
    DuplicateChar(usize),
    SwapChars(usize),
    DeleteLine(usize),
    DuplicateLine(usize),
    SwapLines(usize, usize),
    Indent(usize, i8),
}

const INSERTED: &[u8] = b" \n\t:(),.=-/*\"%<>!ABZamz09_\0\xc3\xff";

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::DeleteChar),
        (any::<usize>(), prop::sample::select(INSERTED))
            .prop_map(|(i, b)| Mutation::InsertChar(i, b)),
        any::<usize>().prop_map(Mutation::DuplicateChar),
        any::<usize>().prop_map(Mutation::SwapChars),
        any::<usize>().prop_map(Mutation::DeleteLine),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        (any::<usize>(), -6i8..=6).prop_map(|(i, by)| Mutation::Indent(i, by)),
    ]
}

fn apply(bytes: &mut Vec<u8>, m: &Mutation) {
    let n = bytes.len();
    let mut lines: Vec<Vec<u8>> = bytes.split(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    let l = lines.len();
    match *m {
        Mutation::DeleteChar(i) if n > 0 => {
            bytes.remove(i % n);
        }
        Mutation::InsertChar(i, b) => bytes.insert(i % (n + 1), b),
        Mutation::DuplicateChar(i) if n > 0 => {
            let b = bytes[i % n];
            bytes.insert(i % n, b);
        }
        Mutation::SwapChars(i) if n > 1 => bytes.swap(i % (n - 1), i % (n - 1) + 1),
        Mutation::DeleteLine(i) => {
            lines.remove(i % l);
            *bytes = lines.join(&b'\n');
        }
        Mutation::DuplicateLine(i) => {
            let line = lines[i % l].clone();
            lines.insert(i % l, line);
            *bytes = lines.join(&b'\n');
        }
        Mutation::SwapLines(a, b) => {
            lines.swap(a % l, b % l);
            *bytes = lines.join(&b'\n');
        }
        Mutation::Indent(i, by) => {
            let line = &mut lines[i % l];
            if by >= 0 {
                line.splice(0..0, std::iter::repeat_n(b' ', by as usize));
            } else {
                let spaces =
                    line.iter().take_while(|&&b| b == b' ').count().min(by.unsigned_abs() as usize);
                line.drain(..spaces);
            }
            *bytes = lines.join(&b'\n');
        }
        _ => {}
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn mutated_fixtures_never_panic(file in any::<prop::sample::Index>(), mutations in prop::collection::vec(mutation(), 1..4)) {
        let files = fixtures();
        let mut bytes = file.get(&files).clone().into_bytes();
        for m in &mutations {
            apply(&mut bytes, m);
        }
        check_bytes(&bytes);
    }
}

// ---------------------------------------------------------------------------------------
// (c) Valid missions format idempotently and keep their meaning.

/// Writes a random valid mission file, driven by a seed: nested blocks, statements,
/// handlers, IF chains, FOR blocks, requirements, capabilities with every section,
/// comments (own-line and trailing, line and block), blank lines, odd spacing and
/// indentation, multi-line headers, and CRLF line endings.
struct Gen {
    state: u64,
    out: String,
    newline: &'static str,
}

const NAMES: &[&str] =
    &["drone1", "drone2", "d", "lead", "area", "Home", "Body", "x_1", "_tmp", "Area2", "where"];
const CAPS: &[&str] = &["TakeOff", "FlyTo", "Search", "Hover", "Land", "FlyCircle", "DeployBeacon"];
const SIGNALS: &[&str] = &["Ready", "Found", "Done", "Detected", "BatteryCritical", "Lost"];
const UNITS: &[&str] = &["", "m", "km", "s", "min", "h", "m/s", "km/h", "deg", "%"];
const SPACED_UNITS: &[&str] = &["m", "km", "s", "min", "h", "deg", "m/s", "km/h"];
const DIGITS: &[&str] = &["0", "1", "20", "2.5", "100", "007", "3.14159", "46.61"];
const COMMENTS: &[&str] =
    &["note", "TODO: check this", "a / b * c", "ÄÖÜ 🚁", "", "WITH AND OR: (x)"];

impl Gen {
    fn new(seed: u64) -> Gen {
        let mut g = Gen { state: seed ^ 0x9E37_79B9_7F4A_7C15, out: String::new(), newline: "\n" };
        g.next();
        if g.chance(10) {
            g.newline = "\r\n";
        }
        g
    }
    fn next(&mut self) -> u64 {
        // xorshift64*
        let mut x = self.state.max(1);
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.state = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
    fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }
    fn pick(&mut self, items: &[&'static str]) -> &'static str {
        items[self.below(items.len())]
    }
    fn sp(&mut self) -> &'static str {
        match self.below(10) {
            0 => "  ",
            1 => "   ",
            _ => " ",
        }
    }
    /// Optional space (where the grammar allows none).
    fn osp(&mut self) -> &'static str {
        if self.chance(20) {
            " "
        } else {
            ""
        }
    }
    fn name(&mut self) -> String {
        self.pick(NAMES).to_string()
    }

    fn number(&mut self) -> String {
        let mut text = String::new();
        if self.chance(15) {
            text.push('-');
            text.push_str(self.osp());
        }
        text.push_str(self.pick(DIGITS));
        let unit = self.pick(UNITS);
        if !unit.is_empty() && SPACED_UNITS.contains(&unit) && self.chance(20) {
            text.push(' ');
        }
        text.push_str(unit);
        text
    }

    /// A value, sometimes a sum of terms (`a + (20m, 0m) - b`).
    fn value(&mut self, depth: u32) -> String {
        let mut text = self.term(depth);
        while depth > 0 && self.chance(15) {
            let op = self.pick(&["+", "-"]);
            let (s1, s2) = (self.sp(), self.sp());
            let right = self.term(depth - 1);
            text = format!("{text}{s1}{op}{s2}{right}");
        }
        text
    }

    fn term(&mut self, depth: u32) -> String {
        let choice = if depth == 0 { self.below(5) } else { self.below(12) };
        match choice {
            0 | 1 => self.number(),
            2 => self.name(),
            3 => format!(
                "{}.{}",
                self.name(),
                self.pick(&["position", "battery", "altitude", "kind"])
            ),
            4 => self.pick(&["\"hello, world\"", "\"\"", "TRUE", "FALSE", "\"a  b\""]).to_string(),
            5 | 6 => {
                let n = 2 + self.below(2);
                let parts: Vec<String> = (0..n).map(|_| self.value(depth - 1)).collect();
                let (o1, o2) = (self.osp(), self.osp());
                format!("({o1}{}{o2})", parts.join(&format!("{},{}", self.osp(), self.sp())))
            }
            7 => {
                let n = 2 + self.below(2);
                let parts: Vec<String> = (0..n).map(|_| self.number()).collect();
                format!("GEO({})", parts.join(", "))
            }
            8 => {
                let (a, b) = (self.value(depth - 1), self.value(depth - 1));
                format!("distance({a},{}{b})", self.sp())
            }
            9 => {
                let (a, d, b) = (self.value(depth - 1), self.value(depth - 1), self.number());
                format!("OFFSET({a},{}{d}, {b})", self.sp())
            }
            10 => {
                let (a, b) = (self.value(depth - 1), self.value(depth - 1));
                format!("MIDPOINT({}{a},{}{b})", self.osp(), self.sp())
            }
            _ => self.number(),
        }
    }

    fn condition(&mut self, depth: u32) -> String {
        let n = 1 + if depth > 0 && self.chance(30) { self.below(3) } else { 0 };
        let parts: Vec<String> = (0..n).map(|_| self.and_condition(depth)).collect();
        parts.join(&format!("{}OR{}", self.sp(), self.sp()))
    }
    fn and_condition(&mut self, depth: u32) -> String {
        let n = 1 + if depth > 0 && self.chance(30) { self.below(3) } else { 0 };
        let parts: Vec<String> = (0..n).map(|_| self.not_condition(depth)).collect();
        parts.join(&format!("{}AND{}", self.sp(), self.sp()))
    }
    fn not_condition(&mut self, depth: u32) -> String {
        let mut text = String::new();
        while self.chance(15) {
            text.push_str("NOT");
            text.push_str(self.sp());
        }
        text.push_str(&self.comparison(depth));
        text
    }
    fn comparison(&mut self, depth: u32) -> String {
        let left = self.operand(depth);
        if self.chance(70) {
            let op = self.pick(&["=", "!=", "<", "<=", ">", ">="]);
            let (s1, s2) = (self.osp(), self.osp());
            let right = self.operand(depth);
            format!("{left}{s1}{op}{s2}{right}")
        } else {
            left
        }
    }
    fn operand(&mut self, depth: u32) -> String {
        match self.below(8) {
            0 => format!("RECEIVED({})", self.pick(SIGNALS)),
            1 => "ELAPSED".to_string(),
            2 if depth > 0 => {
                let inner = self.condition(depth - 1);
                let (o1, o2) = (self.osp(), self.osp());
                format!("({o1}{inner}{o2})")
            }
            _ => self.value(depth.min(1)),
        }
    }

    fn args(&mut self) -> String {
        if self.chance(40) {
            return String::new();
        }
        let n = 1 + self.below(3);
        let mut parts = Vec::new();
        for _ in 0..n {
            let value = self.value(2);
            if self.chance(40) {
                let name = self.name();
                let (s1, s2) = (self.osp(), self.osp());
                parts.push(format!("{name}{s1}={s2}{value}"));
            } else {
                parts.push(value);
            }
        }
        let sep = format!(",{}", self.sp());
        format!("{}WITH{}{}", self.sp(), self.sp(), parts.join(&sep))
    }

    fn indent(&mut self, columns: usize) {
        for _ in 0..columns {
            self.out.push(' ');
        }
    }
    fn newline(&mut self) {
        self.out.push_str(self.newline);
    }
    fn comment_text(&mut self) -> String {
        let text = self.pick(COMMENTS);
        match self.below(4) {
            0 => format!("/* {text} */"),
            1 => format!("/* {text}{}   and more */", self.newline),
            _ => format!("//{}{text}", self.osp()),
        }
    }
    /// Blank lines and own-line comments that may stand before a line at `indent`.
    fn before_line(&mut self, indent: usize) {
        while self.chance(12) {
            if self.chance(30) {
                let columns = self.below(3);
                self.indent(columns);
            }
            self.newline();
        }
        while self.chance(12) {
            let column = if self.chance(70) { indent } else { self.below(indent + 6) };
            self.indent(column);
            let text = self.comment_text();
            self.out.push_str(&text);
            self.newline();
        }
    }
    /// One line of code at `indent`, with maybe a trailing comment.
    fn line(&mut self, indent: usize, text: &str) {
        self.before_line(indent);
        self.indent(indent);
        if self.chance(4) {
            self.out.push_str("/* lead */ ");
        }
        self.out.push_str(text);
        if self.chance(12) {
            let space = self.sp();
            self.out.push_str(space);
            let comment = self.comment_text();
            self.out.push_str(&comment);
        } else if self.chance(5) {
            self.out.push_str("   ");
        }
        self.newline();
    }

    fn body(&mut self, indent: usize, depth: u32, in_capability: bool) {
        let inner = indent + 1 + self.below(5);
        let n = 1 + self.below(if depth > 0 { 4 } else { 3 });
        for _ in 0..n {
            self.item(inner, depth, in_capability);
        }
        // A comment at the end of the body, maybe.
        if self.chance(15) {
            let column = self.below(inner + 3);
            self.indent(column);
            let text = self.comment_text();
            self.out.push_str(&text);
            self.newline();
        }
    }

    fn item(&mut self, indent: usize, depth: u32, in_capability: bool) {
        if self.chance(6) {
            let value = self.value(2);
            let text =
                format!("LET{}{}{}={}{value}", self.sp(), self.name(), self.osp(), self.osp());
            self.line(indent, &text);
            return;
        }
        let choice = if depth == 0 { self.below(6) } else { self.below(16) };
        match choice {
            0 | 1 => {
                let actors: Vec<String> = (0..1 + self.below(2)).map(|_| self.name()).collect();
                let mut cap = self.pick(CAPS).to_string();
                if self.chance(15) {
                    cap.push_str("-T");
                    cap.push_str(&self.below(3).to_string());
                }
                let args = self.args();
                let text = format!("{}{}{cap}{args}", actors.join(self.sp()), self.sp());
                self.line(indent, &text);
            }
            2 if self.chance(20) => {
                let code = self.pick(&["W203", "W201", "W204"]);
                let text = format!("ALLOW{}{code}{}\"expected here\"", self.sp(), self.sp());
                self.line(indent, &text);
            }
            2 if self.chance(20) => {
                let text = format!("{}{}ABORT", self.name(), self.sp());
                self.line(indent, &text);
            }
            2 => {
                let action = self.pick(&["PAUSE", "RESUME", "ABORT", "Widen"]);
                let args = self.args();
                let text = format!("{}-C1{}{action}{args}", self.pick(CAPS), self.sp());
                self.line(indent, &text);
            }
            3 => {
                let n = self.below(3);
                let args: Vec<String> = (0..n).map(|_| self.value(1)).collect();
                let text = format!(
                    "{}.{}({}{})",
                    self.name(),
                    self.pick(&["Land", "DescendTo", "Sweep"]),
                    self.osp(),
                    args.join(", ")
                );
                self.line(indent, &text);
            }
            4 => {
                let keyword = self.pick(&["SIGNAL", "THROW EXCEPTION"]);
                let args = self.args();
                let text = format!("{keyword}{}{}{args}", self.sp(), self.pick(SIGNALS));
                self.line(indent, &text);
            }
            5 => {
                let cond = self.condition(1);
                let text = format!("WAITFOR{}{cond}", self.sp());
                self.line(indent, &text);
            }
            6 | 7 => {
                let kind = self.pick(&["SEQUENTIAL", "PARALLEL"]);
                let name = if self.chance(60) {
                    format!("{}{}", self.sp(), self.pick(&["Launch", "Main", "Search_1"]))
                } else {
                    String::new()
                };
                let text = format!("{kind}{name}{}:", self.osp());
                self.line(indent, &text);
                self.body(indent, depth - 1, in_capability);
            }
            8 => {
                let mut text = String::new();
                if self.chance(30) {
                    text.push_str(self.pick(&["SEQUENTIAL ", "PARALLEL "]));
                }
                text.push_str("ON ");
                if self.chance(50) {
                    text.push_str("EVERY ");
                }
                text.push_str(self.pick(SIGNALS));
                let split = self.chance(20);
                let continuation = indent + 1 + self.below(6);
                let mut tail = String::new();
                if self.chance(40) {
                    tail.push_str(&format!(" BY {}", self.name()));
                }
                if self.chance(40) {
                    tail.push_str(&format!(" WITH {}, {}", self.name(), self.name()));
                }
                if split && !tail.is_empty() {
                    self.line(indent, &text);
                    // The newline ended the first line; the rest continues deeper.
                    let rest = format!("{}:", tail.trim_start());
                    self.line(continuation, &rest);
                } else {
                    let text = format!("{text}{tail}:");
                    self.line(indent, &text);
                }
                self.body(indent, depth - 1, in_capability);
            }
            9 => {
                let mut text = format!("ON EXCEPTION {}", self.pick(SIGNALS));
                if self.chance(30) {
                    text.push_str(&format!(" BY {}", self.name()));
                }
                if self.chance(30) {
                    text.push_str(&format!(" WITH {}", self.name()));
                }
                text.push(':');
                self.line(indent, &text);
                self.body(indent, depth - 1, in_capability);
            }
            10 | 11 => {
                let keyword = self.pick(&["STARTIF", "WAITFOR", "DOWHILE"]);
                let cond = self.condition(2);
                if self.chance(15) {
                    // A condition over two lines, inside parentheses.
                    let second = self.condition(1);
                    let text = format!("{keyword} ({cond} AND");
                    self.line(indent, &text);
                    let more = indent + 1 + self.below(8);
                    let text = format!("{second}):");
                    self.line(more, &text);
                } else {
                    let text = format!("{keyword}{}{cond}{}:", self.sp(), self.osp());
                    self.line(indent, &text);
                }
                self.body(indent, depth - 1, in_capability);
            }
            12 | 13 => {
                let cond = self.condition(2);
                let text = format!("IF{}{cond}:", self.sp());
                self.line(indent, &text);
                self.body(indent, depth - 1, in_capability);
                for _ in 0..self.below(3) {
                    let cond = self.condition(1);
                    let text = format!("ELSE{}IF {cond}:", self.sp());
                    self.line(indent, &text);
                    self.body(indent, depth - 1, in_capability);
                }
                if self.chance(40) {
                    let text = format!("ELSE{}:", self.osp());
                    self.line(indent, &text);
                    self.body(indent, depth - 1, in_capability);
                }
            }
            _ => self.for_block(indent, depth, in_capability),
        }
    }

    fn for_block(&mut self, indent: usize, depth: u32, in_capability: bool) {
        let kind = self.pick(&["SEQUENTIAL", "PARALLEL"]);
        let n = 1 + self.below(3);
        let mut instances = Vec::new();
        for _ in 0..n {
            let mut text = self.name();
            if self.chance(70) {
                let values: Vec<String> = (0..1 + self.below(2)).map(|_| self.value(1)).collect();
                text.push_str(&format!(" WITH {}", values.join(", ")));
            }
            instances.push(text);
        }
        let mut tail = format!("AS {}", self.name());
        if self.chance(60) {
            tail.push_str(&format!(" WITH {}", self.name()));
        }
        tail.push(':');
        if self.chance(50) {
            self.line(indent, &format!("{kind} FOR"));
            let continuation = indent + 1 + self.below(6);
            for (i, instance) in instances.iter().enumerate() {
                let text = if i + 1 < n { format!("{instance} AND") } else { instance.clone() };
                let column = continuation + self.below(3);
                self.line(column, &text);
            }
            self.line(continuation, &tail);
        } else {
            let text = format!("{kind}{}FOR {} {tail}", self.sp(), instances.join(" AND "));
            self.line(indent, &text);
        }
        self.body(indent, depth - 1, in_capability);
    }

    fn capability(&mut self, depth: u32) {
        let params = if self.chance(60) {
            format!(" WITH {}, {}", self.name(), self.name())
        } else {
            String::new()
        };
        let actors = if self.chance(20) { "lead, wing" } else { "d" };
        let text = format!(
            "CAPABILITY{}{}{}BY {actors}{params}{}:",
            self.sp(),
            self.pick(CAPS),
            self.sp(),
            self.osp()
        );
        self.line(0, &text);
        let section = 1 + self.below(4);
        if self.chance(40) {
            self.line(section, "REQUIREMENTS:");
            let inner = section + 1 + self.below(4);
            for _ in 0..1 + self.below(3) {
                let cond = self.condition(2);
                self.line(inner, &cond);
            }
        }
        if self.chance(40) {
            self.line(section, "DEFAULTS:");
            let inner = section + 1 + self.below(4);
            for _ in 0..1 + self.below(3) {
                let text = format!("{}{}:{}{}", self.name(), self.osp(), self.sp(), self.value(1));
                self.line(inner, &text);
            }
        }
        self.line(section, "PERFORM:");
        self.body(section, depth, true);
        let offset = self.below(4);
        for k in 0..self.below(3) {
            let name = ["ABORT", "PAUSE", "RESUME", "Widen"][(offset + k) % 4];
            let text = format!("PERFORM {name}:");
            self.line(section, &text);
            self.body(section, depth, true);
        }
        if self.chance(40) {
            self.line(section, "EXCEPTIONS:");
            let inner = section + 1 + self.below(4);
            for _ in 0..1 + self.below(2) {
                let text = format!("ON EXCEPTION {}:", self.pick(SIGNALS));
                self.line(inner, &text);
                self.body(inner, depth, true);
            }
        }
    }

    fn file(mut self) -> String {
        for _ in 0..self.below(3) {
            let text = format!("USE{}\"lib/{}.mission\"", self.sp(), self.name());
            self.line(0, &text);
        }
        for _ in 0..self.below(2) {
            self.capability(2);
        }
        let text =
            format!("MISSION{}{}{}:", self.sp(), self.pick(&["Rescue", "M", "Test_1"]), self.osp());
        self.line(0, &text);
        self.body(0, 4, false);
        for _ in 0..self.below(2) {
            self.capability(2);
        }
        if self.chance(20) {
            let text = self.comment_text();
            self.out.push_str(&text);
        }
        if self.chance(15) {
            // No newline at the end of the file.
            while self.out.ends_with(['\n', '\r']) {
                self.out.pop();
            }
        }
        self.out
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn valid_missions_format_well(seed in any::<u64>()) {
        let text = Gen::new(seed).file();
        check_format(&text);
    }
}

// ---------------------------------------------------------------------------------------
// (d) Deep nesting is reported, not a stack overflow; and the file-level errors.

fn codes(text: &str) -> Vec<Code> {
    parse(FileId(0), text).diagnostics.iter().map(|d| d.code).collect()
}

#[test]
fn ten_thousand_parentheses() {
    let text = format!("MISSION M:\n    WAITFOR {}x{}\n", "(".repeat(10_000), ")".repeat(10_000));
    assert!(codes(&text).contains(&Code::NestingTooDeep));
}

#[test]
fn ten_thousand_parentheses_in_a_value() {
    let text =
        format!("MISSION M:\n    d FlyTo WITH {}1, 2{}\n", "(".repeat(10_000), ")".repeat(10_000));
    assert!(codes(&text).contains(&Code::NestingTooDeep));
}

#[test]
fn ten_thousand_nots() {
    let text = format!("MISSION M:\n    WAITFOR {}x\n", "NOT ".repeat(10_000));
    assert!(codes(&text).contains(&Code::NestingTooDeep));
}

#[test]
fn ten_thousand_ands_and_ten_thousand_pluses() {
    let messages = |text: &str| -> Vec<(Code, String)> {
        parse(FileId(0), text).diagnostics.iter().map(|d| (d.code, d.message.clone())).collect()
    };
    let ands = format!("MISSION M:\n    WAITFOR x{}\n", " AND x".repeat(10_000));
    let found = messages(&ands);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, Code::NestingTooDeep);
    assert!(found[0].1.contains("joins more than"), "{found:?}");
    // A sum in a header: reported once, and the header's `:` is still its own.
    let sum =
        format!("MISSION M:\n    IF d.altitude < 1m{}:\n        d Land\n", " + 1m".repeat(10_000));
    let found = messages(&sum);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, Code::NestingTooDeep);
    assert!(found[0].1.starts_with("a sum of more than"), "{found:?}");
}

#[test]
fn five_thousand_nested_blocks() {
    let mut text = String::from("MISSION M:\n");
    for depth in 1..=5_000 {
        text.push_str(&" ".repeat(depth));
        text.push_str("SEQUENTIAL:\n");
    }
    text.push_str(&" ".repeat(5_001));
    text.push_str("d Land\n");
    assert!(codes(&text).contains(&Code::NestingTooDeep));
}

#[test]
fn long_flat_conditions_do_not_overflow() {
    // A chain of AND/OR builds a tree as deep as it is long: bounded like nesting.
    let text = format!("MISSION M:\n    WAITFOR x{}\n", " AND x OR x".repeat(50_000));
    let parse = parse(FileId(0), &text);
    assert!(parse.diagnostics.iter().any(|d| d.code == Code::NestingTooDeep));
    drop(parse);
    // A chain of realistic length is fine, and formats.
    let text = format!("MISSION M:\n    WAITFOR x{}\n", " AND x".repeat(40));
    check_format(&text);
}

#[test]
fn empty_file_is_e003() {
    assert_eq!(codes(""), vec![Code::EmptyFile]);
    assert_eq!(codes("\n\n   \n// only a comment\n"), vec![Code::EmptyFile]);
}

#[test]
fn nul_byte_is_e002() {
    let parse = parse(FileId(0), "MISSION M:\n    d\0 Land\n");
    assert_eq!(parse.diagnostics.len(), 1);
    assert_eq!(parse.diagnostics[0].code, Code::BinaryFile);
    assert_eq!(parse.diagnostics[0].primary.span.start, 16);
}

#[test]
fn invalid_utf8_is_e001_at_the_first_bad_byte() {
    let bytes = b"MISSION M:\n    d \xff\xfe Land\n";
    let (_, parse) = parse_bytes(FileId(0), bytes);
    assert_eq!(parse.diagnostics.len(), 1);
    let d = &parse.diagnostics[0];
    assert_eq!(d.code, Code::InvalidUtf8);
    assert_eq!(d.primary.span.start, 17);
    assert_eq!(d.primary.span.end, 18);
    // A truncated multi-byte character at the very end.
    let (_, parse) = parse_bytes(FileId(0), b"MISSION M:\n    d Land \xc3");
    assert_eq!(parse.diagnostics[0].code, Code::InvalidUtf8);
    assert_eq!(parse.diagnostics[0].primary.span.start, 22);
}

#[test]
fn tab_is_e004() {
    let parse = parse(FileId(0), "MISSION M:\n\td Land\n");
    let tab = parse.diagnostics.iter().find(|d| d.code == Code::TabIndent).expect("E004");
    assert_eq!(tab.primary.span.start, 11);
}

#[test]
fn inconsistent_dedent_is_e005() {
    let text = "MISSION M:\n    SEQUENTIAL:\n        a Land\n      b Land\n";
    let parse = parse(FileId(0), text);
    let dedent =
        parse.diagnostics.iter().find(|d| d.code == Code::InconsistentDedent).expect("E005");
    assert_eq!(&text[dedent.primary.span.range()], "b");
}

#[test]
fn generator_makes_every_construct() {
    // The generator is worth only what it covers: over some seeds, every kind of item.
    let mut all = String::new();
    for seed in 0..200 {
        all.push_str(&Gen::new(seed).file());
    }
    for needle in [
        "SEQUENTIAL",
        "PARALLEL FOR",
        "ON EVERY",
        "ON EXCEPTION",
        "ELSE IF",
        "ELSE",
        "STARTIF",
        "WAITFOR",
        "DOWHILE",
        "SIGNAL",
        "THROW EXCEPTION",
        "PAUSE",
        "GEO(",
        "distance(",
        "RECEIVED(",
        "REQUIREMENTS:",
        "DEFAULTS:",
        "EXCEPTIONS:",
        "PERFORM ABORT:",
        "USE",
        "//",
        "/*",
        "\r\n",
        "-T",
    ] {
        assert!(all.contains(needle), "the generator never writes {needle}");
    }
}
