//! A trace names the world it was flown in (its file and SHA-256, in `mission_start`):
//! `aviary report` and `aviary replay` draw that world, find it without `--world`, and
//! refuse another with the reason, instead of drawing the flight over a world it never saw.

mod common;

use aviary_api::trace::WorldStamp;
use common::{aviary, repo, scratch};

const MISSION: &str = "examples/faults/motor_failure.mission";
const WORLD: &str = "examples/faults/motor_failure.world.toml";

/// Flies the drill with its trace in a scratch folder; the trace's path.
fn flown(name: &str) -> std::path::PathBuf {
    let trace = scratch(name).join("drill.jsonl");
    let (code, out, err) =
        aviary(&["run", MISSION, "--quiet", "--trace", &trace.to_string_lossy()], &repo());
    assert_eq!(code, 0, "{out}{err}");
    trace
}

#[test]
fn a_trace_names_its_world_and_a_report_refuses_another() {
    let trace = flown("records_refuse");
    let first: serde_json::Value = serde_json::from_str(
        std::fs::read_to_string(&trace).unwrap().lines().next().expect("a first line"),
    )
    .unwrap();
    let bytes = std::fs::read(repo().join(WORLD)).unwrap();
    let stamp = WorldStamp::of(WORLD, &bytes);
    assert_eq!(first["event"], "mission_start");
    assert_eq!(first["world"]["file"], WORLD);
    assert_eq!(first["world"]["sha256"], stamp.sha256.as_ref());
    assert_eq!(stamp.sha256.len(), 64, "SHA-256, in hex");

    // Another world is refused, with the one the trace names.
    let html = trace.with_file_name("wrong.html");
    let (code, _, err) = aviary(
        &[
            "report",
            &trace.to_string_lossy(),
            "--world",
            "examples/crop_spraying.world.toml",
            "-o",
            &html.to_string_lossy(),
        ],
        &repo(),
    );
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("examples/crop_spraying.world.toml is not the world this trace was flown in")
            && err.contains(WORLD),
        "{err}"
    );
    assert!(!html.exists(), "nothing written");
    // The same world under another name is the same world.
    let copy = trace.with_file_name("same.world.toml");
    std::fs::write(&copy, &bytes).unwrap();
    let (code, _, err) = aviary(
        &[
            "report",
            &trace.to_string_lossy(),
            "--world",
            &copy.to_string_lossy(),
            "-o",
            &html.to_string_lossy(),
        ],
        &repo(),
    );
    assert_eq!(code, 0, "{err}");
}

#[test]
fn without_world_a_report_draws_the_world_the_trace_names_if_it_is_unchanged() {
    let trace = flown("records_find");
    let html = trace.with_file_name("found.html");
    let (code, _, err) =
        aviary(&["report", &trace.to_string_lossy(), "-o", &html.to_string_lossy()], &repo());
    assert_eq!(code, 0, "{err}");
    assert!(err.contains(&format!("the trace was flown in {WORLD}: drawn on it")), "{err}");
    let drawn = std::fs::read_to_string(&html).unwrap();
    assert!(drawn.contains("Tower") && drawn.contains("Bridge"), "the world's places are drawn");

    // Elsewhere, beside a changed copy of the world: drawn without one, and said so.
    let dir = trace.parent().unwrap();
    let changed = std::fs::read_to_string(repo().join(WORLD)).unwrap().replace("Tower", "Mast");
    std::fs::write(dir.join("motor_failure.world.toml"), changed).unwrap();
    let alone = dir.join("alone.html");
    let (code, _, err) =
        aviary(&["report", &trace.to_string_lossy(), "-o", &alone.to_string_lossy()], dir);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("which is not here as it was: drawn without a world"), "{err}");
    let drawn = std::fs::read_to_string(&alone).unwrap();
    assert!(!drawn.contains("Mast"), "the changed world is not drawn");
}
