//! The pre-flight corpus: every `.mission` under `tests/fixtures/` is checked, compiled
//! and verified as `aviary check --plan` does it, and the diagnostics and the plan are
//! compared with a snapshot.
//!
//! A fixture uses `NAME.world.toml` beside it, or else `world.toml`. A name that starts
//! with a code (`w203_...`) must produce that code; an `ok_` fixture must produce no
//! W203, W204 or N303. Together the fixtures produce every pre-flight code.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use aviary_diagnostics::{render_text, Code, Diagnostic, SourceMap};
use aviary_test_support::NoFiles;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join("fixtures")
}

struct Outcome {
    text: String,
    codes: BTreeSet<Code>,
}

fn verify_fixture(name: &str) -> Outcome {
    let read =
        |f: &str| std::fs::read(dir().join(f)).unwrap_or_else(|e| panic!("cannot read {f}: {e}"));
    let world_name = match name.strip_suffix(".mission").map(|stem| format!("{stem}.world.toml")) {
        Some(beside) if dir().join(&beside).is_file() => beside,
        _ => "world.toml".to_string(),
    };
    let (mission, world) = (read(name), read(&world_name));
    let mut sources = SourceMap::new();
    let mut checked = aviary_check::check_sources(
        &mut sources,
        (name, &mission),
        Some((&world_name, &world)),
        &NoFiles,
    );
    let verified = aviary_verify::preflight(&mut checked);
    let mut diagnostics: Vec<Diagnostic> = checked.diagnostics;
    let mut text = String::new();
    let plan = verified.map(|(_, v)| {
        diagnostics.extend(v.diagnostics);
        v.plan
    });
    aviary_diagnostics::sort(&mut diagnostics);
    for d in &diagnostics {
        text.push_str(&render_text(&sources, d, false));
    }
    match plan {
        Some(mut plan) => {
            plan.locate_in(&sources);
            text.push_str(&plan.render_text());
        }
        None => text.push_str("no plan: the mission did not check\n"),
    }
    Outcome { text, codes: diagnostics.iter().map(|d| d.code).collect() }
}

fn fixtures() -> Vec<String> {
    let mut out: Vec<String> = std::fs::read_dir(dir())
        .expect("the fixtures folder")
        .map(|e| e.expect("an entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".mission"))
        .collect();
    out.sort();
    out
}

#[test]
fn snapshots() {
    insta::glob!("fixtures/*.mission", |path| {
        let name = path.file_name().expect("a file name").to_string_lossy().into_owned();
        insta::assert_snapshot!(verify_fixture(&name).text);
    });
}

#[test]
fn each_fixture_produces_what_its_name_says() {
    let mut wrong = Vec::new();
    let mut seen = BTreeSet::new();
    for name in fixtures() {
        let outcome = verify_fixture(&name);
        assert!(
            !outcome.codes.iter().any(|c| c.severity() == aviary_diagnostics::Severity::Error),
            "{name} has errors:\n{}",
            outcome.text
        );
        seen.extend(outcome.codes.iter().copied());
        let code = name.get(..4).and_then(|p| Code::from_str(&p.to_ascii_uppercase()));
        match code {
            Some(code) if !outcome.codes.contains(&code) => {
                wrong.push(format!("{name}: no {code}"))
            }
            None if name.starts_with("ok_")
                && outcome.codes.iter().any(|c| Code::PREFLIGHT.contains(c)) =>
            {
                wrong.push(format!("{name}: a pre-flight finding where none is expected"))
            }
            _ => {}
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    let missing: Vec<&str> =
        Code::PREFLIGHT.iter().filter(|c| !seen.contains(c)).map(|c| c.as_str()).collect();
    assert!(missing.is_empty(), "no fixture produces {}", missing.join(", "));
}
