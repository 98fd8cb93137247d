//! `aviary test` as a user runs it (docs/CAMPAIGNS.md): the report of a fixed range of
//! seeds of a mission whose world has chance in it (`tests/campaign/patrol.*`: a sensor
//! that finds seven times in ten, a motor failure at a drawn time, and `[expect]`), the
//! same for any number of threads and for any sharding, its worst seeds flown again by
//! `aviary run`, and bad input refused before anything flies.

mod common;

use std::path::PathBuf;

use common::{aviary, repo, scratch};
use serde_json::Value;

const RUNS: &str = "24";

fn fixtures() -> PathBuf {
    repo().join("crates/aviary-cli/tests/campaign")
}

/// `aviary test patrol.mission --runs 24 ARGS`, in the fixtures' folder.
fn campaign(args: &[&str]) -> (i32, String, String) {
    let mut all = vec!["test", "patrol.mission", "--runs", RUNS];
    all.extend_from_slice(args);
    aviary(&all, &fixtures())
}

#[test]
fn the_report_is_the_same_byte_for_byte_on_one_thread_or_two() {
    let (code, one, err) = campaign(&["--jobs", "1"]);
    assert_eq!(code, 1, "some runs fail, so exit 1: {err}");
    let (_, two, _) = campaign(&["--jobs", "2"]);
    assert_eq!(one, two);
    let (_, json_one, _) = campaign(&["--jobs", "1", "--format", "json"]);
    let (_, json_two, _) = campaign(&["--jobs", "2", "--format", "json"]);
    assert_eq!(json_one, json_two);
    insta::assert_snapshot!("patrol_text", one);
}

#[test]
fn the_json_report_holds_every_figure_and_every_run() {
    let (code, out, err) = campaign(&["--format", "json"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.is_empty(), "no progress bar or note with JSON: {err}");
    let report: Value = serde_json::from_str(&out).expect("one JSON object");
    assert_eq!(report["format"], "aviary-campaign/1");
    assert_eq!(report["runs"], 24);
    let records = report["records"].as_array().expect("records");
    let seeds: Vec<u64> = records.iter().map(|r| r["seed"].as_u64().unwrap()).collect();
    assert_eq!(seeds, (0..24).collect::<Vec<u64>>());
    let succeeded = records.iter().filter(|r| r["success"] == true).count() as u64;
    assert_eq!(report["succeeded"].as_u64(), Some(succeeded));
    assert!(succeeded > 0 && succeeded < 24, "the fixture has both: {succeeded}");
    let [low, high] =
        [&report["interval95"][0], &report["interval95"][1]].map(|v| v.as_f64().unwrap());
    let rate = report["success_rate"].as_f64().unwrap();
    assert!(0.0 <= low && low <= rate && rate <= high && high <= 1.0);
    // Each expectation counted apart, and an unhandled exception located at a statement.
    let met: Vec<&str> = report["expectations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["expectation"].as_str().unwrap())
        .collect();
    assert_eq!(met, ["all targets found", "time <= 400 s", "battery >= 78.5%"]);
    let failure = records.iter().find_map(|r| r["failure"].as_object()).expect("a failed run");
    assert_eq!(failure["exception"], "MotorFailure");
    assert_eq!(failure["drone"], "carrier");
    assert!(failure["statement"]["line"].as_u64().is_some(), "{failure:?}");
    assert!(failure["position"].as_array().is_some_and(|p| p.len() == 3), "{failure:?}");
}

#[test]
fn merged_shards_are_exactly_the_unsharded_report() {
    let dir = scratch("campaign_shards");
    let (_, whole, _) = campaign(&["--format", "json", "--jobs", "2"]);
    let (_, whole_text, _) = campaign(&["--jobs", "1"]);
    let mut names = Vec::new();
    for i in 1..=3 {
        let shard = format!("{i}/3");
        let (code, out, err) = campaign(&["--format", "json", "--shard", &shard, "--jobs", "1"]);
        assert!(code == 0 || code == 1, "{err}");
        let name = dir.join(format!("shard_{i}.json"));
        std::fs::write(&name, out).unwrap();
        names.push(name.display().to_string());
    }
    // In any order.
    names.reverse();
    let mut merge = vec!["test", "merge"];
    merge.extend(names.iter().map(String::as_str));
    let (code, merged, err) =
        aviary(&[merge.clone(), vec!["--format", "json"]].concat(), &fixtures());
    assert_eq!(code, 1, "{err}");
    assert_eq!(merged, whole, "the merged report is the unsharded one, byte for byte");
    let (_, merged_text, _) = aviary(&merge, &fixtures());
    assert_eq!(merged_text, whole_text);

    // A shard missing, or given twice: refused.
    let (code, _, err) = aviary(&["test", "merge", &names[0], &names[1]], &fixtures());
    assert_eq!(code, 2);
    assert!(err.contains("is missing"), "{err}");
    let (code, _, err) =
        aviary(&["test", "merge", &names[0], &names[0], &names[1], &names[2]], &fixtures());
    assert_eq!(code, 2);
    assert!(err.contains("in two of the reports"), "{err}");
}

/// The outcome `aviary run` prints: the `mission ...` line and whether an expectation
/// was not met.
fn run_outcome(seed: u64) -> (i32, String, bool) {
    let seed = seed.to_string();
    let (code, out, err) = aviary(
        &["run", "patrol.mission", "--world", "patrol.world.toml", "--seed", &seed],
        &fixtures(),
    );
    let line =
        out.lines().find(|l| l.starts_with("mission ")).unwrap_or_else(|| panic!("{out}{err}"));
    (code, line.to_owned(), out.contains("expectation not met"))
}

#[test]
fn the_worst_seeds_fly_again_exactly_with_aviary_run() {
    let (_, out, _) = campaign(&["--format", "json"]);
    let report: Value = serde_json::from_str(&out).unwrap();
    let worst = report["worst"].as_array().expect("worst runs");
    assert_eq!(worst.len(), 5);
    for w in worst {
        let seed = w["seed"].as_u64().unwrap();
        let command = w["command"].as_str().unwrap();
        assert_eq!(
            command,
            format!("aviary run patrol.mission --world patrol.world.toml --seed {seed}")
        );
        let record = &report["records"].as_array().unwrap()[seed as usize];
        let (code, line, unmet) = run_outcome(seed);
        let expected = match record["reason"].as_str() {
            Some(reason) => format!("mission {}: {reason}", record["status"].as_str().unwrap()),
            None => format!("mission {}", record["status"].as_str().unwrap()),
        };
        assert_eq!(line, expected, "seed {seed}");
        assert_eq!(code == 0, record["success"] == true, "seed {seed}");
        assert_eq!(unmet, record["expectations"].as_array().unwrap().iter().any(|m| m == false));
    }
}

#[test]
fn bad_input_gets_a_clear_error_and_runs_nothing() {
    let dir = fixtures();
    for (args, said) in [
        (vec!["--runs", "0"], "--runs"),
        (vec!["--runs", "ten"], "--runs"),
        (vec!["--runs", "3", "--shard", "0/3"], "from 1 to 3"),
        (vec!["--runs", "3", "--shard", "4/3"], "from 1 to 3"),
        (vec!["--runs", "3", "--shard", "garbage"], "not a shard"),
        (vec!["--runs", "3", "--shard", "1/0"], "at least one share"),
        (vec!["--runs", "3", "--jobs", "0"], "--jobs"),
        (vec!["--runs", "3", "--seed", "18446744073709551615"], "past the last seed"),
    ] {
        let all = [vec!["test", "patrol.mission"], args.clone()].concat();
        let (code, out, err) = aviary(&all, &dir);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?}: nothing flies: {out}");
        assert!(err.contains(said), "{args:?}: {err}");
    }

    let scratch = scratch("campaign_bad_expect");
    std::fs::copy(dir.join("patrol.mission"), scratch.join("patrol.mission")).unwrap();
    let world = std::fs::read_to_string(dir.join("patrol.world.toml")).unwrap();
    for (bad, line, said) in [
        ("min_battery = 1.5", "min_battery", "between 0 and 1"),
        ("max_time = -3", "max_time", "greater than zero"),
        ("min_found = 3", "min_found", "the world has 2 targets"),
        ("within = 20", "within", "unknown key `within` in [expect]"),
    ] {
        let text = world.replace("max_time = 400", bad).replace("min_battery = 0.785\n", "");
        std::fs::write(scratch.join("patrol.world.toml"), &text).unwrap();
        let (code, out, err) = aviary(&["test", "patrol.mission", "--runs", "3"], &scratch);
        assert_eq!(code, 2, "{bad}: {err}");
        assert!(out.is_empty(), "{bad}: {out}");
        let row = text.lines().position(|l| l.starts_with(line)).unwrap() + 1;
        assert!(err.contains(&format!("patrol.world.toml:{row}:")), "{bad}: located: {err}");
        assert!(err.contains(said), "{bad}: {err}");
        // `aviary run` and `aviary check` read the same table.
        let (code, _, err) = aviary(&["check", "patrol.mission"], &scratch);
        assert_eq!(code, 1, "{bad}: {err}");
    }
}

#[test]
fn the_html_report_is_one_file_with_its_plots() {
    let dir = scratch("campaign_html");
    let out = dir.join("report.html");
    let (code, text, err) = campaign(&["--html", out.to_str().unwrap()]);
    assert_eq!(code, 1, "{err}");
    assert!(text.contains("wrote "), "{text}");
    let html = std::fs::read_to_string(&out).unwrap();
    assert!(html.starts_with("<!doctype html>"));
    assert_eq!(html.matches("<svg").count(), 4, "time, finds, batteries, the map of failures");
    assert!(html.contains("Where runs failed") && html.contains("MotorFailure"));
    for outside in ["<script", "src=\"http", "href=\"http"] {
        assert!(!html.contains(outside), "self-contained: {outside}");
    }
}

#[test]
fn aviary_run_says_which_expectation_a_run_did_not_meet() {
    // Seed by seed, as the campaign counted them.
    let (_, out, _) = campaign(&["--format", "json"]);
    let report: Value = serde_json::from_str(&out).unwrap();
    let record = report["records"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["status"] == "ok" && r["success"] == false)
        .expect("a run that ended ok without meeting every expectation");
    let (code, _, unmet) = run_outcome(record["seed"].as_u64().unwrap());
    assert_eq!(code, 1);
    assert!(unmet);
    // A world without [expect] runs as before.
    let (code, out, _) = aviary(&["run", "examples/search_and_rescue.mission"], &repo());
    assert_eq!(code, 0);
    assert!(!out.contains("expectation"), "{out}");
}
