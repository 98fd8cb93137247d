//! Snapshot tests of the canonical formatter: every `tests/fmt/*.mission` input is
//! formatted, snapshotted, and checked to be idempotent and meaning-preserving.

mod common;

use common::check_format;

#[test]
fn fixtures() {
    insta::glob!("fmt/*.mission", |path| {
        let bytes = std::fs::read(path).expect("read the fixture");
        let text = String::from_utf8(bytes).expect("fixtures are UTF-8");
        let formatted = check_format(&text);
        insta::assert_snapshot!(formatted);
    });
}

/// The paper's mission is already canonical: formatting returns it unchanged.
#[test]
fn paper_example_is_canonical() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/search_and_rescue.mission");
    let text = std::fs::read_to_string(path).expect("read the example");
    let formatted = check_format(&text);
    assert_eq!(formatted, text);
}

/// Small cases whose exact output matters, beyond the snapshots.
#[test]
fn exact_outputs() {
    let cases: &[(&str, &str)] = &[
        // One-instance FOR on one line; `20 m` glued.
        (
            "MISSION M:\n  PARALLEL FOR a WITH 20 m AS d:\n    d Land\n",
            "MISSION M:\n    PARALLEL FOR a WITH 20m AS d:\n        d Land\n",
        ),
        // Two instances written on one line become the paper's multi-line form.
        (
            "MISSION M:\n    PARALLEL FOR a WITH X AND b WITH Y AS d WITH p:\n        d Land\n",
            "MISSION M:\n    PARALLEL FOR\n        a WITH X AND\n        b WITH Y\n        AS d WITH p:\n        d Land\n",
        ),
        // No blank line right after a header; at most one elsewhere; none at the end.
        (
            "MISSION M:\n\n\n    a Land\n\n\n\n    b Land\n\n\n",
            "MISSION M:\n    a Land\n\n    b Land\n",
        ),
        // Exactly one blank line between top-level items.
        (
            "USE \"a.mission\"\nUSE \"b.mission\"\nMISSION M:\n    a Land\n\n\n\nCAPABILITY C BY d:\n    PERFORM:\n        d.Land()",
            "USE \"a.mission\"\nUSE \"b.mission\"\n\nMISSION M:\n    a Land\n\nCAPABILITY C BY d:\n    PERFORM:\n        d.Land()\n",
        ),
        // Trailing comments stay on their line; a comment at the end of a body stays there.
        (
            "MISSION M:\n    SEQUENTIAL:\n        a Land   // why\n        // end of the block\n    b Land\n",
            "MISSION M:\n    SEQUENTIAL:\n        a Land // why\n        // end of the block\n    b Land\n",
        ),
        // A dedented comment after a body moves out to the level it is written at.
        (
            "MISSION M:\n    SEQUENTIAL:\n        a Land\n    // next: b\n    b Land\n",
            "MISSION M:\n    SEQUENTIAL:\n        a Land\n    // next: b\n    b Land\n",
        ),
        // ELSE at the IF's indentation; operators spaced; parentheses kept.
        (
            "MISSION M:\n    IF (a>1 AND NOT b=c):\n        x Land\n    ELSE   IF d<=2:\n        x Land\n    ELSE:\n        x Hover\n",
            "MISSION M:\n    IF (a > 1 AND NOT b = c):\n        x Land\n    ELSE IF d <= 2:\n        x Land\n    ELSE:\n        x Hover\n",
        ),
        // A comment inside a one-line header moves just after the header line.
        (
            "MISSION M:\n    ON EVERY S\n        // inside the header\n        BY d:\n        d Land\n",
            "MISSION M:\n    ON EVERY S BY d:\n        // inside the header\n        d Land\n",
        ),
        // Two trailing line comments cannot share a line: the second goes below.
        (
            "MISSION M:\n    ON S // one\n       BY d: // two\n        d Land\n",
            "MISSION M:\n    ON S BY d: // one\n        // two\n        d Land\n",
        ),
    ];
    for (input, expected) in cases {
        let formatted = check_format(input);
        assert_eq!(&formatted, expected, "input:\n{input}");
    }
}

#[test]
fn strip_spans_removes_only_positions() {
    let debug = "Ident { name: \"a\", span: Span { start: 1, end: 22 } }, Body { items: [], header_end: 7 }, body_header_end: 99";
    assert_eq!(
        common::strip_spans(debug),
        "Ident { name: \"a\", span: Span }, Body { items: [], header_end }, body_header_end"
    );
}

/// Comments in awkward places: wherever they go, none is lost, the tree is kept, and a
/// second formatting changes nothing.
#[test]
fn awkward_comments_are_kept() {
    let cases = [
        // A block comment over two lines that code continues after.
        "MISSION M:\n    a Land /* x\n    */ b Land\n",
        // A block comment inside the indentation.
        "MISSION M:\n  /* c */  a Land\n  b Land\n",
        "MISSION M:\n    a Land // c1\n/* top */ // c2\n    b Land\n",
        "MISSION M:\n    IF x:\n        a Land\n    // before else\n        // deeper, after it\n    ELSE:\n        b Land\n",
        "MISSION M:\n    IF x:\n        a Land\n        // end of IF body\n    ELSE /* odd */ IF y: // t\n        b Land\n",
        "MISSION M:\n    PARALLEL FOR // c0\n        a WITH 1 AND // c1\n        /* own */ b WITH 2 // c2\n        // c3\n        AS d: // c4\n        // c5\n        d Land\n",
        "MISSION M:\n    PARALLEL /* k */ FOR a AND b AS d:\n        d Land\n",
        "MISSION M:\n    PARALLEL FOR a\n        /* x\n        y */ AND b AS d:\n        d Land\n",
        // Comments inside parentheses that span lines.
        "MISSION M:\n    d FlyTo WITH (1, // one\n        2) // two\n    e Land\n",
        "MISSION M:\n    d FlyTo WITH (1,\n    // inside, dedented\n        2)\n",
        "MISSION M:\n    SEQUENTIAL:\n        d FlyTo WITH (1,\n// inside, col 0\n            2)\n    e Land\n",
        "MISSION M:\n    WAITFOR (a\n        // mid\n        AND b) // end\n    d Land\n",
        // Several comments on one line; no newline at the end.
        "/* a */ /* b */\nMISSION M: /* x\n y */ /* z */\n    d Land",
        "MISSION M:\n    d Land\n    /* a\n  b */ // c\n",
        "MISSION M:\n    d Land\n\n\n    // end\n\n\n",
        "// only a comment then\n\n\n\nMISSION M:\n    d Land\n// at the end, without a newline",
        "CAPABILITY C BY d:\n    REQUIREMENTS:\n        d.battery > 1% // t\n      // between\n    PERFORM:\n        d.Land()\n    EXCEPTIONS: // e\n        ON EXCEPTION X:\n            d.Land()\n        // end exc\n    // end cap\n",
        "USE \"a\" // one\nUSE \"b\"\n// between uses\nUSE \"c\"\nMISSION M:\n    d Land\n",
        "MISSION M:\n    ON S:\n        a Land\n        // in handler\n// col0\n    // col4\n        // col8 after col0\n    b Land\n",
    ];
    for case in cases {
        check_format(case);
    }
}
