//! The VS Code extension's TextMate grammar (`editors/vscode/syntaxes/aviary.tmLanguage.json`)
//! held to the lexer, so that the two cannot drift: its `keywords-*` rules name every
//! keyword of `Keyword::ALL` and nothing else, and every other word its patterns name is a
//! keyword, a unit, or a word the parser reads in its place (`LET`, `ANY`, `GEO`...),
//! spelled as a string in the parser's source. The extension's own fixture of every
//! construct parses without an error.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use aviary_diagnostics::FileId;
use aviary_syntax::ast::Unit;
use aviary_syntax::token::Keyword;
use serde_json::Value;

fn repository_file(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(path)
}

fn grammar() -> Value {
    let path = repository_file("editors/vscode/syntaxes/aviary.tmLanguage.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// Every regular expression of the grammar, wherever it is nested.
fn regexes<'a>(value: &'a Value, out: &mut Vec<&'a str>) {
    match value {
        Value::Object(map) => {
            for (key, v) in map {
                match (key.as_str(), v) {
                    ("match" | "begin" | "end" | "while", Value::String(s)) => out.push(s),
                    _ => regexes(v, out),
                }
            }
        }
        Value::Array(items) => items.iter().for_each(|v| regexes(v, out)),
        _ => {}
    }
}

/// The words a regular expression spells: runs of ASCII letters outside escapes (`\b`,
/// `\s`) and character classes (`[A-Za-z_]`).
fn words(regex: &str) -> Vec<String> {
    let (mut out, mut word) = (Vec::new(), String::new());
    let mut chars = regex.chars();
    while let Some(c) = chars.next() {
        if c.is_ascii_alphabetic() {
            word.push(c);
            continue;
        }
        if !word.is_empty() {
            out.push(std::mem::take(&mut word));
        }
        match c {
            '\\' => {
                chars.next();
            }
            '[' => {
                while let Some(c) = chars.next() {
                    match c {
                        '\\' => {
                            chars.next();
                        }
                        ']' => break,
                        _ => {}
                    }
                }
            }
            _ => {}
        }
    }
    out.extend((!word.is_empty()).then_some(word));
    out
}

#[test]
fn the_grammars_keyword_rules_are_the_lexers_keywords() {
    let grammar = grammar();
    let repository = grammar["repository"].as_object().unwrap();
    let mut named = Vec::new();
    for (rule, body) in repository.iter().filter(|(k, _)| k.starts_with("keywords-")) {
        let regex = body["match"].as_str().unwrap_or_else(|| panic!("{rule} has no match"));
        let list = regex
            .strip_prefix(r"\b(?:")
            .and_then(|r| r.strip_suffix(r")\b"))
            .unwrap_or_else(|| panic!("{rule} is not written \\b(?:A|B|...)\\b: {regex}"));
        named.extend(list.split('|').map(str::to_string));
    }
    let unique: BTreeSet<&str> = named.iter().map(String::as_str).collect();
    assert_eq!(unique.len(), named.len(), "a keyword is in two keywords-* rules: {named:?}");
    let lexer: BTreeSet<&str> = Keyword::ALL.iter().map(|k| k.as_str()).collect();
    let missing: Vec<_> = lexer.difference(&unique).collect();
    let extra: Vec<_> = unique.difference(&lexer).collect();
    assert!(
        missing.is_empty(),
        "lexer keywords missing from the grammar's keywords-* rules: {missing:?}"
    );
    assert!(
        extra.is_empty(),
        "words in the grammar's keywords-* rules that the lexer does not have: {extra:?}"
    );
}

#[test]
fn every_word_of_the_grammar_is_a_word_of_the_language() {
    let parser: String =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/parser"))
            .unwrap()
            .map(|entry| std::fs::read_to_string(entry.unwrap().path()).unwrap())
            .collect();
    let grammar = grammar();
    let mut all = Vec::new();
    regexes(&grammar, &mut all);
    assert!(all.len() > 30, "only {} regular expressions found", all.len());
    let mut unknown = BTreeSet::new();
    for regex in all {
        for word in words(regex) {
            let known = Keyword::from_exact(&word).is_some()
                || Unit::ALL.iter().any(|u| u.as_str().split('/').any(|part| part == word))
                || parser.contains(&format!("\"{word}\""));
            if !known {
                unknown.insert(format!("{word} (in {regex})"));
            }
        }
    }
    assert!(unknown.is_empty(), "the grammar names words the language does not have: {unknown:#?}");
}

#[test]
fn the_extensions_fixture_of_every_construct_parses() {
    let path = repository_file("editors/vscode/test/fixtures/constructs.mission");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let parse = aviary_syntax::parse(FileId(0), &text);
    let errors: Vec<_> = parse
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .map(|d| format!("{}: {} at {:?}", d.code.as_str(), d.message, d.primary.span))
        .collect();
    assert!(errors.is_empty(), "{}: {errors:#?}", path.display());
}

#[test]
fn words_skips_escapes_and_classes() {
    assert_eq!(words(r"\b(?:IF|ELSE)\b"), ["IF", "ELSE"]);
    assert_eq!(words(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s+(m/s|deg)\S"), ["m", "s", "deg"]);
}
