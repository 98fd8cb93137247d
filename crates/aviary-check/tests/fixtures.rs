//! The data-driven diagnostic corpus: every `.mission` file under `tests/fixtures/invalid/`
//! and `tests/fixtures/valid/` is checked the way `aviary check` checks a file, and the
//! rendered diagnostics are compared with a snapshot (`tests/snapshots/`).
//!
//! Conventions of the corpus:
//! - Each fixture is checked against `fixtures/world.toml`, unless `NAME.world.toml`
//!   stands beside `NAME.mission` (then that one, as the CLI would find it), or the file
//!   holds the line `// fixture: no world` (then none).
//! - An invalid fixture's name starts with the code it is about (`e107_...`), and it must
//!   produce that code. Together the invalid fixtures produce every code of `Code::ALL`.
//! - A valid fixture produces no error and no warning (notes are snapshotted).
//! - Files in subfolders (`valid/lib/`, ...) are only read through `USE`.
//! - File names in the output are relative to `fixtures/`, so snapshots do not depend on
//!   the machine.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use aviary_check::SourceProvider;
use aviary_diagnostics::{render_text, summary_line, Code, Diagnostic, Severity, SourceMap};

fn fixtures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("fixtures")
}

/// The fixture files of one folder (`invalid` or `valid`), as paths relative to
/// `fixtures/` with `/` separators, sorted.
fn fixtures(folder: &str) -> Vec<String> {
    let dir = fixtures_dir().join(folder);
    let mut out: Vec<String> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|entry| entry.expect("a directory entry").path())
        .filter(|p| p.is_file() && p.extension().is_some_and(|x| x == "mission"))
        .map(|p| format!("{folder}/{}", p.file_name().expect("a file name").to_string_lossy()))
        .collect();
    out.sort();
    out
}

/// Reads `USE`d files from the fixtures folder, relative to the file that holds the USE.
/// Names stay relative to `fixtures/`.
struct FixtureProvider;

impl SourceProvider for FixtureProvider {
    fn load(&self, from: &str, path: &str) -> Result<(String, Vec<u8>), aviary_check::LoadError> {
        let base = Path::new(from).parent().unwrap_or(Path::new(""));
        let relative = aviary_check::normalize_path(&base.join(path));
        let name = relative
            .components()
            .map(|c| c.as_os_str().to_string_lossy().into_owned())
            .collect::<Vec<_>>()
            .join("/");
        match std::fs::read(fixtures_dir().join(&relative)) {
            Ok(bytes) => Ok((name, bytes)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                Err(format!("there is no file {name}").into())
            }
            Err(e) => Err(format!("{} ({name})", e.kind().to_string().to_lowercase()).into()),
        }
    }
}

struct Outcome {
    sources: SourceMap,
    diagnostics: Vec<Diagnostic>,
}

impl Outcome {
    fn codes(&self) -> BTreeSet<Code> {
        self.diagnostics.iter().map(|d| d.code).collect()
    }
}

/// The world a fixture is checked against, relative to `fixtures/`.
fn world_of(rel: &str, bytes: &[u8]) -> Option<String> {
    if bytes.windows(b"// fixture: no world".len()).any(|w| w == b"// fixture: no world") {
        return None;
    }
    let beside = format!("{}.world.toml", rel.strip_suffix(".mission").unwrap_or(rel));
    if fixtures_dir().join(&beside).is_file() {
        Some(beside)
    } else {
        Some("world.toml".to_string())
    }
}

/// Checks one fixture as `aviary check` does: world first, then the mission.
fn check_fixture(rel: &str) -> Outcome {
    let bytes = std::fs::read(fixtures_dir().join(rel))
        .unwrap_or_else(|e| panic!("cannot read {rel}: {e}"));
    let mut sources = SourceMap::new();
    let world_rel = world_of(rel, &bytes);
    let world_bytes = world_rel.as_ref().map(|w| {
        std::fs::read(fixtures_dir().join(w)).unwrap_or_else(|e| panic!("cannot read {w}: {e}"))
    });
    let world = world_rel.as_deref().zip(world_bytes.as_deref());
    let checked = aviary_check::check_sources(&mut sources, (rel, &bytes), world, &FixtureProvider);
    let mut diagnostics = checked.diagnostics;
    // The pre-flight analyses do not run here: their codes' ALLOWs are not judged.
    aviary_check::acknowledge(&checked.allows, &mut diagnostics, false);
    Outcome { sources, diagnostics }
}

/// The text `aviary check` prints (without color), summary line included.
fn render(rel: &str, outcome: &Outcome) -> String {
    let mut out = String::new();
    for d in &outcome.diagnostics {
        out.push_str(&render_text(&outcome.sources, d, false));
    }
    let summary = summary_line(&outcome.diagnostics);
    if outcome.diagnostics.iter().any(Diagnostic::is_error) {
        out.push_str(&format!("{rel}: {summary}\n"));
    } else if summary.is_empty() {
        out.push_str(&format!("{rel}: ok\n"));
    } else {
        out.push_str(&format!("{rel}: ok ({summary})\n"));
    }
    out
}

fn relative(path: &Path) -> String {
    let rel = path.strip_prefix(fixtures_dir()).expect("a fixture under tests/fixtures");
    rel.components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

/// The code an invalid fixture's name starts with: `e107_takeoff...` is E107.
fn code_of_name(rel: &str) -> Option<Code> {
    let file = rel.rsplit('/').next()?;
    let prefix = file.get(..4)?;
    if file.as_bytes().get(4) != Some(&b'_') {
        return None;
    }
    Code::from_str(&prefix.to_ascii_uppercase())
}

#[test]
fn invalid() {
    insta::glob!("fixtures/invalid/*.mission", |path| {
        let rel = relative(path);
        insta::assert_snapshot!(render(&rel, &check_fixture(&rel)));
    });
}

#[test]
fn valid() {
    insta::glob!("fixtures/valid/*.mission", |path| {
        let rel = relative(path);
        insta::assert_snapshot!(render(&rel, &check_fixture(&rel)));
    });
}

#[test]
fn every_code_is_produced_by_some_invalid_fixture() {
    let mut seen = BTreeSet::new();
    for rel in fixtures("invalid") {
        seen.extend(check_fixture(&rel).codes());
    }
    // The pre-flight codes come after compilation; aviary-verify's fixtures cover them.
    let missing: Vec<&str> = Code::ALL
        .iter()
        .filter(|c| !seen.contains(c) && !Code::PREFLIGHT.contains(c))
        .map(|c| c.as_str())
        .collect();
    assert!(missing.is_empty(), "no invalid fixture produces {}", missing.join(", "));
}

#[test]
fn every_invalid_fixture_produces_the_code_it_is_named_after() {
    let mut wrong = Vec::new();
    for rel in fixtures("invalid") {
        let Some(code) = code_of_name(&rel) else {
            wrong.push(format!("{rel}: the name does not start with a code such as `e107_`"));
            continue;
        };
        let outcome = check_fixture(&rel);
        // The code's own severity: an error or warning for E and W codes, a note for N codes.
        let found =
            outcome.diagnostics.iter().any(|d| d.code == code && d.severity == code.severity());
        let counts = outcome.diagnostics.iter().any(|d| d.severity != Severity::Note)
            || code.severity() == Severity::Note;
        if !found || !counts {
            let got: Vec<&str> = outcome.codes().iter().map(|c| c.as_str()).collect();
            wrong.push(format!("{rel}: expected {code}, got [{}]", got.join(", ")));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn there_are_enough_invalid_fixtures() {
    let n = fixtures("invalid").len();
    assert!(n >= 45, "only {n} invalid fixtures");
}

#[test]
fn valid_fixtures_have_no_errors_and_no_warnings() {
    let mut bad = Vec::new();
    for rel in fixtures("valid") {
        let outcome = check_fixture(&rel);
        if outcome.diagnostics.iter().any(|d| d.severity != Severity::Note) {
            bad.push(render(&rel, &outcome));
        }
    }
    assert!(bad.is_empty(), "valid fixtures with errors or warnings:\n{}", bad.join("\n"));
}

#[test]
fn the_standard_library_parses_clean_and_is_canonically_formatted() {
    let text = aviary_check::STD_SOURCE;
    let parse = aviary_syntax::parse(aviary_diagnostics::FileId(0), text);
    let mut sources = SourceMap::new();
    sources.add(aviary_check::STD_NAME, text);
    let rendered: Vec<String> =
        parse.diagnostics.iter().map(|d| render_text(&sources, d, false)).collect();
    assert!(rendered.is_empty(), "std/standard.mission has diagnostics:\n{}", rendered.join(""));
    let formatted = aviary_syntax::format(&parse.tree, text, &parse.line_starts);
    assert!(formatted == text, "std/standard.mission is not in the canonical layout; `aviary fmt` would write:\n{formatted}");
}

#[test]
fn every_code_has_a_section_in_diagnostics_md() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/DIAGNOSTICS.md");
    let doc = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let headings: Vec<&str> = doc.lines().filter_map(|l| l.strip_prefix("## ")).collect();
    let missing: Vec<&str> = Code::ALL
        .iter()
        .map(|c| c.as_str())
        .filter(|c| !headings.iter().any(|h| h.split_whitespace().next() == Some(*c)))
        .collect();
    assert!(
        missing.is_empty(),
        "docs/DIAGNOSTICS.md has no `## CODE` heading for {}",
        missing.join(", ")
    );
}
