//! A fast path from TOML text to the spanned tree, for the files worlds are made of.
//!
//! `toml` (through `toml_edit`) builds a whole editable document, with its decor and
//! formatting, and then serde walks it: about 50,000 instructions and 2.5 KiB of peak
//! memory per `[drones.NAME]` table, so a world of 100,000 drones took a second and
//! 250 MiB to read. Here `toml_parser` (the lexer and parser `toml` itself is built on)
//! hands over its events with their spans, and the tree is built directly, with every
//! span where the serde path puts it (tests compare the two trees).
//!
//! It covers tables, arrays of tables, bare keys, key/value pairs, strings, numbers,
//! booleans, arrays and inline tables. Anything else (a syntax error, a duplicate key,
//! a dotted or quoted key, a date, a key/value pair outside any table, a table defined
//! twice or implicitly first) returns `None`, and the caller takes the serde path,
//! which reports the problem with the same words as before.
//!
//! Each `[drones.NAME]` table is handed to the caller as soon as it is complete (when
//! the next header starts), and leaves the tree: a world of many drones never has all
//! their tables in memory. So that this stays exact, every entry of `[drones]` must come
//! from such a header, once: anything else there takes the serde path.

use std::collections::HashMap;
use std::hash::{BuildHasher, BuildHasherDefault};

use aviary_diagnostics::Span;
use toml_parser::decoder::{Encoding, IntegerRadix, ScalarKind};
use toml_parser::lexer::TokenKind;
use toml_parser::parser::EventReceiver;
use toml_parser::{ErrorSink, ParseError, Source};

use crate::hash::{Quick, QuickSet};
use crate::node::{Entry, Node, Value};

/// The tree of `text`, or `None` when the serde path should read it.
pub(crate) fn parse(text: &str) -> Option<Node> {
    let mut drones = Vec::new();
    let mut root = parse_with(text, 0, &mut |e| drones.push(e))?;
    if let Value::Table(top) = &mut root.value {
        if let Some(Entry { node: Node { value: Value::Table(entries), .. }, .. }) =
            top.iter_mut().find(|e| e.key == "drones")
        {
            *entries = drones;
        }
    }
    Some(root)
}

/// As [`parse`], but each `[drones.NAME]` table goes to `on_drone` (in file order) as
/// soon as it has been read, and the tree's `drones` table is left empty. When this
/// returns `None`, some tables may have gone to `on_drone` already. `drones`: about how
/// many there are.
pub(crate) fn parse_with(
    text: &str,
    drones: usize,
    on_drone: &mut dyn FnMut(Entry),
) -> Option<Node> {
    let part = parse_part(text, 0..text.len(), Part::Whole, drones, on_drone)?;
    Some(part.root.into_node())
}

/// Which part of a file [`parse_part`] reads.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Part {
    /// All of it.
    Whole,
    /// From the start to a line that starts a `[drones.NAME]` table: it must end on a
    /// line break, outside any bracket or string, with no key waiting for its value.
    Head,
    /// From such a line to the end: nothing but `[drones.NAME]` tables.
    Tail,
}

/// What [`parse_part`] read, before the parts are put together ([`join`]).
pub(crate) struct Read {
    root: Table,
    /// The hashes of the drones' names.
    names: QuickSet<u64>,
}

/// Reads `text[range]` (spans stay those of `text`) as the part `part` of the file,
/// exactly as [`parse_with`] reads those lines within the whole: a file is read in
/// tables (`parse_document` is called once per table), so a head that ends where a
/// table starts, and a tail that starts there, are handed to the parser in the same
/// pieces, and the builder is at the same point between them (no header, key, open
/// bracket or dotted key pending; checked). What differs is what the builder keeps
/// across tables: the tree and the names of the drones, which [`join`] puts together.
/// `None`: the serde path reads the file (for a head or a tail: the whole file is read
/// in one part, which decides).
pub(crate) fn parse_part(
    text: &str,
    range: std::ops::Range<usize>,
    part: Part,
    drones: usize,
    on_drone: &mut dyn FnMut(Entry),
) -> Option<Read> {
    let whole = text;
    let base = range.start;
    let text = text.get(range)?;
    if !within_toml_1_0(text.as_bytes()) {
        return None;
    }
    let source = Source::new(text);
    let mut builder = Builder {
        text: whole,
        base,
        root: Table::new(Span::new(0, 0)),
        current: None,
        header: None,
        key: None,
        dotted: false,
        stack: Vec::new(),
        bail: false,
        on_drone,
        drone_names: QuickSet::with_capacity_and_hasher(drones, Default::default()),
        drones_at: None,
        open_drone: false,
        only_drones: part == Part::Tail,
    };
    const MAX_DEPTH: i64 = 32;
    let mut errors = Errors(false);
    // Parsed a table at a time: all the tokens of a large world at once would take more
    // memory than its tree. A `[` that opens a line outside any bracket starts a table.
    let mut tokens = Vec::with_capacity(64);
    let (mut depth, mut line_start) = (0i64, true);
    let (mut inline, mut last) = (0i64, TokenKind::Newline);
    for token in source.lex() {
        // TOML 1.1 forms (`toml_parser` reads 1.1, the serde path `toml` 0.8 reads 1.0):
        // line breaks and a trailing comma in an inline table, `\e` and `\x` escapes;
        // and CRLF in multi-line strings, which the two decode differently.
        match token.kind() {
            TokenKind::Newline if inline > 0 => return None,
            TokenKind::RightCurlyBracket if last == TokenKind::Comma => return None,
            TokenKind::BasicString | TokenKind::MlBasicString => {
                let raw = text.get(token.span().start()..token.span().end())?.as_bytes();
                let escapes = raw.windows(2).any(|w| w[0] == b'\\' && matches!(w[1], b'e' | b'x'));
                if escapes || raw.contains(&b'\r') {
                    return None;
                }
            }
            // `toml` reads a CRLF inside a multi-line string as LF; `toml_parser` keeps it.
            TokenKind::MlLiteralString
                if text.get(token.span().start()..token.span().end())?.contains('\r') =>
            {
                return None
            }
            TokenKind::LeftCurlyBracket => inline += 1,
            TokenKind::RightCurlyBracket => inline -= 1,
            // A head is a piece of the file: its end is not the file's.
            TokenKind::Eof if part == Part::Head => continue,
            _ => {}
        }
        if !matches!(token.kind(), TokenKind::Whitespace | TokenKind::Comment) {
            last = token.kind();
        }
        match token.kind() {
            TokenKind::LeftSquareBracket => {
                if depth == 0 && line_start && !tokens.is_empty() {
                    toml_parser::parser::parse_document(&tokens, &mut builder, &mut errors);
                    tokens.clear();
                }
                depth += 1;
            }
            TokenKind::LeftCurlyBracket => depth += 1,
            TokenKind::RightSquareBracket | TokenKind::RightCurlyBracket => depth -= 1,
            _ => {}
        }
        // `toml_parser` recurses once per open bracket, without a limit: deep nesting
        // goes to the serde path, which stops at its recursion limit with an error
        // (a world file nests four deep at most).
        if depth > MAX_DEPTH {
            return None;
        }
        line_start = token.kind() == TokenKind::Newline;
        tokens.push(token);
    }
    if part == Part::Head {
        // The whole file's lexer, too, ends a token at the end of the head: its last
        // token is a line break (a string or comment running on would have taken it).
        let ends_line = tokens
            .last()
            .is_some_and(|t| t.kind() == TokenKind::Newline && t.span().end() == text.len());
        if !(ends_line && depth == 0 && inline == 0) {
            return None;
        }
    }
    toml_parser::parser::parse_document(&tokens, &mut builder, &mut errors);
    let pending = builder.header.is_some() || builder.key.is_some() || builder.dotted;
    if errors.0 || builder.bail || !builder.stack.is_empty() || (part == Part::Head && pending) {
        return None;
    }
    builder.hand_over_drone()?;
    Some(Read { root: builder.root, names: builder.drone_names })
}

/// The tree of a head and a tail read by [`parse_part`], as [`parse_with`] builds it
/// from the whole file; `None` when the whole file must be read in one part (a drone's
/// name in both, or a `drones` of the head that is not a table of drones).
pub(crate) fn join(head: Read, tail: Read) -> Option<Node> {
    let Read { mut root, names } = head;
    if tail.names.len() > names.len() {
        if names.iter().any(|n| tail.names.contains(n)) {
            return None;
        }
    } else if tail.names.iter().any(|n| names.contains(n)) {
        return None;
    }
    // The tail holds only `[drones.NAME]` tables, all handed over: its tree is one empty
    // table `drones`, made by its first header.
    let mut tail_entries = tail.root.entries.into_iter();
    let (Some((key, key_span, Item::Table(drones))), None) =
        (tail_entries.next(), tail_entries.next())
    else {
        return None;
    };
    if key != "drones" || !drones.entries.is_empty() {
        return None;
    }
    match root.find("drones") {
        // The whole file's reader found it there, and added nothing to it.
        Some(i) => match &root.entries[i].2 {
            Item::Table(t) if t.entries.is_empty() => {}
            _ => return None,
        },
        // ... or made it at the tail's first header, after every table of the head.
        None => {
            root.push(key, key_span, Item::Table(drones));
        }
    }
    Some(root.into_node())
}

/// No control character but tab and line breaks, and no carriage return outside a CRLF:
/// TOML forbids them, and `toml_parser`'s lexer lets some through (a lone `\r` breaks a
/// line there).
fn within_toml_1_0(bytes: &[u8]) -> bool {
    // Most files have no control character but tab and LF: counted without a branch (so
    // the loop is vectorised) before the exact walk.
    let odd = |b: u8| (b < 0x20 && b != b'\t' && b != b'\n') || b == 0x7f;
    if bytes.iter().fold(0usize, |n, &b| n + usize::from(odd(b))) == 0 {
        return true;
    }
    bytes.iter().enumerate().all(|(i, &b)| match b {
        b'\r' => bytes.get(i + 1) == Some(&b'\n'),
        b'\t' | b'\n' => true,
        0..=0x1f | 0x7f => false,
        _ => true,
    })
}

/// A TOML 1.0 bare key: the decoder would return it unchanged.
fn is_bare_key(text: &str) -> bool {
    !text.is_empty() && text.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

/// The scalars most files are made of, read without the decoder: a decimal integer
/// without sign, underscores or leading zeros (that fits), a boolean, and a one-line
/// string without escapes. `None`: ask the decoder.
fn plain_scalar(text: &str, encoding: Option<Encoding>) -> Option<Value> {
    let quoted = |q: u8| {
        let inner = text.strip_prefix(q as char)?.strip_suffix(q as char)?;
        (!inner.contains([q as char, '\\'])).then(|| Value::Str(inner.to_owned()))
    };
    match encoding {
        None => match text {
            "true" => Some(Value::Bool(true)),
            "false" => Some(Value::Bool(false)),
            _ if (1..=18).contains(&text.len())
                && text.bytes().all(|b| b.is_ascii_digit())
                && (text.len() == 1 || !text.starts_with('0')) =>
            {
                text.parse().ok().map(Value::Int)
            }
            _ => None,
        },
        Some(Encoding::BasicString) => quoted(b'"'),
        Some(Encoding::LiteralString) => quoted(b'\''),
        Some(_) => None,
    }
}

struct Errors(bool);

impl ErrorSink for Errors {
    fn report_error(&mut self, _error: ParseError) {
        self.0 = true;
    }
}

/// A table being built: entries in file order, and an index once it is large.
struct Table {
    span: Span,
    entries: Vec<(String, Span, Item)>,
    index: Option<HashMap<String, usize>>,
}

enum Item {
    Value(Node),
    Table(Table),
    /// An array of tables (`[[targets]]`).
    Tables(Vec<Table>),
}

/// Tables with more entries than this are indexed by key.
const INDEX_FROM: usize = 16;

impl Table {
    fn new(span: Span) -> Table {
        Table { span, entries: Vec::new(), index: None }
    }

    fn find(&self, key: &str) -> Option<usize> {
        match &self.index {
            Some(index) => index.get(key).copied(),
            None => self.entries.iter().position(|(k, _, _)| k == key),
        }
    }

    fn push(&mut self, key: String, key_span: Span, item: Item) -> usize {
        let at = self.entries.len();
        if let Some(index) = &mut self.index {
            index.insert(key.clone(), at);
        }
        self.entries.push((key, key_span, item));
        if self.index.is_none() && self.entries.len() > INDEX_FROM {
            self.index = Some(
                self.entries.iter().enumerate().map(|(i, (k, _, _))| (k.clone(), i)).collect(),
            );
        }
        at
    }

    fn into_node(self) -> Node {
        let entries = self
            .entries
            .into_iter()
            .map(|(key, key_span, item)| {
                let node = match item {
                    Item::Value(node) => node,
                    Item::Table(t) => t.into_node(),
                    Item::Tables(ts) => {
                        let start = ts.first().map_or(key_span.start, |t| t.span.start);
                        let end = ts.last().map_or(key_span.end, |t| t.span.end);
                        let items = ts.into_iter().map(Table::into_node).collect();
                        Node {
                            span: Span::new(start as usize, end as usize),
                            value: Value::Array(items),
                        }
                    }
                };
                Entry { key, key_span, node }
            })
            .collect();
        Node { span: self.span, value: Value::Table(entries) }
    }
}

/// `[[` or `[`, where the header starts, and its keys so far.
type Header = (bool, usize, Vec<(String, Span)>);

/// An array or inline table whose closing bracket is still to come.
enum Open {
    Array { start: usize, items: Vec<Node> },
    Inline { start: usize, entries: Vec<Entry>, key: Option<(String, Span)> },
}

struct Builder<'i, 's> {
    /// The whole file: spans are offsets into it.
    text: &'i str,
    /// Where the part being read starts in `text`: the parser's spans count from there.
    base: usize,
    root: Table,
    /// Where key/value pairs go: entry indices from the root (into the last table of
    /// an array of tables). `None` before the first header.
    current: Option<Vec<usize>>,
    /// A table header being read: `[[` or `[`, where it starts, its keys.
    header: Option<Header>,
    /// The key of a key/value pair whose value is being read.
    key: Option<(String, Span)>,
    /// A key was followed by `.`: a dotted key.
    dotted: bool,
    stack: Vec<Open>,
    bail: bool,
    /// Takes each `[drones.NAME]` table once it is complete.
    on_drone: &'s mut dyn FnMut(Entry),
    /// The hashes of the names of the drones read so far (their tables are gone): a
    /// second `[drones.NAME]` of one of them (or, once in a blue moon, of a name with
    /// the same 64-bit hash) takes the serde path. Half the memory of the names.
    drone_names: QuickSet<u64>,
    /// The root's entry of `drones`.
    drones_at: Option<usize>,
    /// The current table is a `[drones.NAME]`, to be handed over at the next header.
    open_drone: bool,
    /// Every header must be a `[drones.NAME]` (the tail of a file read in two parts).
    only_drones: bool,
}

impl<'i> Builder<'i, '_> {
    /// A span of the parser's, in the whole file.
    fn span(&self, s: toml_parser::Span) -> Span {
        Span::new(self.base + s.start(), self.base + s.end())
    }

    /// The text of a span of the parser's.
    fn raw(&self, s: toml_parser::Span) -> Option<&'i str> {
        self.text.get(self.base + s.start()..self.base + s.end())
    }

    /// Hands the `[drones.NAME]` table just read to `on_drone`: it is the only entry
    /// of `drones`, since every earlier one went the same way.
    fn hand_over_drone(&mut self) -> Option<()> {
        if !std::mem::take(&mut self.open_drone) {
            return Some(());
        }
        let Item::Table(drones) = &mut self.root.entries.get_mut(self.drones_at?)?.2 else {
            return None;
        };
        let (key, key_span, Item::Table(table)) = drones.entries.pop()? else { return None };
        self.current = None;
        (self.on_drone)(Entry { key, key_span, node: table.into_node() });
        Some(())
    }

    /// Whether a header may open a table under `drones` (`[drones]` or `[drones.NAME]`,
    /// each once) and whether it is a drone's; `None` for the serde path.
    fn drone_header(&mut self, array: bool, keys: &[(String, Span)]) -> Option<bool> {
        if keys.first().is_none_or(|(k, _)| k != "drones") {
            return Some(false);
        }
        match keys {
            [_] if !array => Some(false),
            [_, (name, at)] if !array => {
                // A bare key: its text is its name.
                let text: &'i str = self.text.get(at.range())?;
                let hash = BuildHasherDefault::<Quick>::default().hash_one(text);
                (text == name && self.drone_names.insert(hash)).then_some(true)
            }
            _ => None,
        }
    }

    fn table_at<'t>(root: &'t mut Table, path: &[usize]) -> Option<&'t mut Table> {
        let mut table = root;
        for &i in path {
            table = match &mut table.entries.get_mut(i)?.2 {
                Item::Table(t) => t,
                Item::Tables(ts) => ts.last_mut()?,
                Item::Value(_) => return None,
            };
        }
        Some(table)
    }

    /// `[a.b.c]` or `[[a.b.c]]`, from `start` to `end`.
    fn header(
        &mut self,
        array: bool,
        start: usize,
        end: usize,
        keys: Vec<(String, Span)>,
    ) -> Option<()> {
        self.hand_over_drone()?;
        let drone = self.drone_header(array, &keys)?;
        if self.only_drones && !drone {
            return None;
        }
        let (last, parents) = keys.split_last()?;
        let mut path = Vec::with_capacity(keys.len());
        let mut table = &mut self.root;
        for (key, key_span) in parents {
            let i = match table.find(key) {
                Some(i) => i,
                None => table.push(key.clone(), *key_span, Item::Table(Table::new(*key_span))),
            };
            path.push(i);
            table = match &mut table.entries[i].2 {
                Item::Table(t) => t,
                Item::Tables(ts) => ts.last_mut()?,
                Item::Value(_) => return None,
            };
        }
        let whole = Span::new(start, end);
        let i = match (table.find(&last.0), array) {
            (None, false) => table.push(last.0.clone(), last.1, Item::Table(Table::new(whole))),
            (None, true) => {
                table.push(last.0.clone(), last.1, Item::Tables(vec![Table::new(whole)]))
            }
            (Some(i), true) => match &mut table.entries[i].2 {
                Item::Tables(ts) => {
                    ts.push(Table::new(whole));
                    i
                }
                _ => return None,
            },
            // Defined twice, or made explicit after an implicit use: the serde path decides.
            (Some(_), false) => return None,
        };
        path.push(i);
        if keys[0].0 == "drones" {
            self.drones_at = path.first().copied();
        }
        self.open_drone = drone;
        self.current = Some(path);
        Some(())
    }

    /// A finished value: into the open array or inline table, or the current table.
    fn value(&mut self, node: Node) -> Option<()> {
        match self.stack.last_mut() {
            Some(Open::Array { items, .. }) => items.push(node),
            Some(Open::Inline { entries, key, .. }) => {
                let (k, key_span) = key.take()?;
                if entries.iter().any(|e| e.key == k) {
                    return None;
                }
                entries.push(Entry { key: k, key_span, node });
            }
            None => {
                let (k, key_span) = self.key.take()?;
                let path = self.current.as_ref()?;
                // `[drones]` holds only `[drones.NAME]` tables here.
                if path.len() == 1 && Some(path[0]) == self.drones_at {
                    return None;
                }
                let table = Self::table_at(&mut self.root, path)?;
                if table.find(&k).is_some() {
                    return None;
                }
                table.span = Span::new(table.span.start as usize, node.span.end as usize);
                table.push(k, key_span, Item::Value(node));
            }
        }
        Some(())
    }

    fn scalar(&mut self, at: toml_parser::Span, encoding: Option<Encoding>) -> Option<()> {
        let text = self.raw(at)?;
        if let Some(value) = plain_scalar(text, encoding) {
            return self.value(Node { span: self.span(at), value });
        }
        let raw = toml_parser::Raw::new_unchecked(text, encoding, at);
        let mut out = String::new();
        let mut errors = Errors(false);
        let kind = raw.decode_scalar(&mut out, &mut errors);
        if errors.0 {
            return None;
        }
        let value = match kind {
            ScalarKind::String => Value::Str(out),
            ScalarKind::Boolean(b) => Value::Bool(b),
            ScalarKind::Integer(IntegerRadix::Dec) => Value::Int(out.parse().ok()?),
            // A literal too large for an f64 (`14E2650`) reads as infinity here and is an
            // error for the serde path: not finite, it takes that path (as do `inf`, `nan`).
            ScalarKind::Float if encoding.is_none() => {
                Value::Float(out.parse::<f64>().ok().filter(|f| f.is_finite())?)
            }
            _ => return None,
        };
        self.value(Node { span: self.span(at), value })
    }

    fn key(&mut self, at: toml_parser::Span, encoding: Option<Encoding>) -> Option<()> {
        if encoding.is_some() || self.dotted {
            return None;
        }
        // The parser leaves a bare key's characters to the decoder (`Lookout@` lexes as
        // one key), so decode it and take serde's path on any complaint.
        let text = self.raw(at)?;
        let name = if is_bare_key(text) {
            text.to_owned()
        } else {
            let mut name = String::new();
            let mut errors = Errors(false);
            toml_parser::Raw::new_unchecked(text, None, at).decode_key(&mut name, &mut errors);
            if errors.0 {
                return None;
            }
            name
        };
        let key = (name, self.span(at));
        if let Some((_, _, keys)) = &mut self.header {
            keys.push(key);
            return Some(());
        }
        match self.stack.last_mut() {
            Some(Open::Inline { key: slot, .. }) => *slot = Some(key),
            Some(Open::Array { .. }) => return None,
            None => self.key = Some(key),
        }
        Some(())
    }

    fn check(&mut self, ok: Option<()>) {
        if ok.is_none() {
            self.bail = true;
        }
    }
}

impl EventReceiver for Builder<'_, '_> {
    fn std_table_open(&mut self, at: toml_parser::Span, _: &mut dyn ErrorSink) {
        self.header = Some((false, self.base + at.start(), Vec::new()));
    }
    fn array_table_open(&mut self, at: toml_parser::Span, _: &mut dyn ErrorSink) {
        self.header = Some((true, self.base + at.start(), Vec::new()));
    }
    fn std_table_close(&mut self, at: toml_parser::Span, _: &mut dyn ErrorSink) {
        self.close_header(at);
    }
    fn array_table_close(&mut self, at: toml_parser::Span, _: &mut dyn ErrorSink) {
        self.close_header(at);
    }
    fn inline_table_open(&mut self, at: toml_parser::Span, _: &mut dyn ErrorSink) -> bool {
        self.stack.push(Open::Inline {
            start: self.base + at.start(),
            entries: Vec::new(),
            key: None,
        });
        true
    }
    fn inline_table_close(&mut self, at: toml_parser::Span, _: &mut dyn ErrorSink) {
        let ok = match self.stack.pop() {
            Some(Open::Inline { start, entries, key: None }) => self.value(Node {
                span: Span::new(start, self.base + at.end()),
                value: Value::Table(entries),
            }),
            _ => None,
        };
        self.check(ok);
    }
    fn array_open(&mut self, at: toml_parser::Span, _: &mut dyn ErrorSink) -> bool {
        self.stack.push(Open::Array { start: self.base + at.start(), items: Vec::new() });
        true
    }
    fn array_close(&mut self, at: toml_parser::Span, _: &mut dyn ErrorSink) {
        let ok = match self.stack.pop() {
            Some(Open::Array { start, items }) => self.value(Node {
                span: Span::new(start, self.base + at.end()),
                value: Value::Array(items),
            }),
            _ => None,
        };
        self.check(ok);
    }
    fn simple_key(
        &mut self,
        at: toml_parser::Span,
        encoding: Option<Encoding>,
        _: &mut dyn ErrorSink,
    ) {
        let ok = self.key(at, encoding);
        self.check(ok);
    }
    fn key_sep(&mut self, _: toml_parser::Span, _: &mut dyn ErrorSink) {
        // In a header the keys are a path; elsewhere a dotted key is left to serde.
        if self.header.is_none() {
            self.dotted = true;
        }
    }
    fn key_val_sep(&mut self, _: toml_parser::Span, _: &mut dyn ErrorSink) {}
    fn scalar(&mut self, at: toml_parser::Span, encoding: Option<Encoding>, _: &mut dyn ErrorSink) {
        let ok = self.scalar(at, encoding);
        self.check(ok);
    }
    fn error(&mut self, _: toml_parser::Span, _: &mut dyn ErrorSink) {
        self.bail = true;
    }
}

impl Builder<'_, '_> {
    fn close_header(&mut self, at: toml_parser::Span) {
        let ok = match self.header.take() {
            Some((array, start, keys)) => self.header(array, start, self.base + at.end(), keys),
            None => None,
        };
        self.check(ok);
    }
}
