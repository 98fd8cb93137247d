//! Snapshot tests of the parser: every `tests/parse/*.mission` input is parsed, and its
//! diagnostics and its whole tree, spans included (as `start..end`), are snapshotted. The
//! parser never fails, so a broken input gives a tree too: the snapshot shows what the
//! parser recovered.

mod common;

use aviary_diagnostics::FileId;

#[test]
fn fixtures() {
    insta::glob!("parse/*.mission", |path| {
        let bytes = std::fs::read(path).expect("read the fixture");
        let text = String::from_utf8(bytes).expect("fixtures are UTF-8");
        let parsed = aviary_syntax::parse(FileId(0), &text);
        let diagnostics = common::describe_errors(&parsed);
        let tree = compact_spans(&format!("{:#?}", parsed.tree.items));
        insta::assert_snapshot!(format!("diagnostics:\n{diagnostics}\n\ntree:\n{tree}"));
    });
}

/// A tree names the line of any offset once the text is gone: what a run-time report
/// uses to point at a handler.
#[test]
fn a_tree_tells_the_line_of_an_offset() {
    let text = "MISSION M:\r\n    a Hover\n\n    b Hover\n";
    let tree = aviary_syntax::parse(FileId(0), text).tree;
    let line = |s: &str| tree.line_of(text.find(s).unwrap() as u32);
    assert_eq!((line("MISSION"), line("M:"), line("a Hover"), line("b Hover")), (1, 1, 2, 4));
    assert_eq!(tree.line_of(text.len() as u32), 5, "past the last line break");
    assert_eq!(aviary_syntax::ast::SourceFile::default().line_of(7), 0, "made without text");
}

/// The pretty `Debug` text with each `Span {\n start: A,\n end: B,\n }` as `A..B`.
fn compact_spans(debug: &str) -> String {
    let mut out = String::with_capacity(debug.len());
    let mut lines = debug.lines().peekable();
    while let Some(line) = lines.next() {
        if let Some(head) = line.strip_suffix("Span {") {
            let mut number = |key: &str| {
                let l = lines.next().unwrap_or_default().trim();
                l.strip_prefix(key).and_then(|n| n.strip_suffix(',')).unwrap_or("?").to_string()
            };
            let (start, end) = (number("start: "), number("end: "));
            let close = lines.next().unwrap_or_default().trim();
            out.push_str(&format!(
                "{head}{start}..{end}{}\n",
                close.strip_prefix('}').unwrap_or("")
            ));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}
