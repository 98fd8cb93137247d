//! The `aviary` binary as a user runs it: exit codes, output forms, world discovery,
//! USE, and fmt's promise never to lose data.

mod common;

use common::{aviary, repo, scratch};

const WORLD: &str = "[places]\nHome = [0, 0]\n[drones.d1]\nhome = [0, 0]\ngroup = \"g\"\n";

#[test]
fn the_paper_mission_checks_clean_with_its_world_found_beside_it() {
    let (code, out, _) = aviary(&["check", "examples/search_and_rescue.mission"], &repo());
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("examples/search_and_rescue.mission: ok"), "{out}");
    assert!(!out.contains("N302"), "the world beside the mission must be found: {out}");
}

#[test]
fn errors_give_exit_1_and_the_runtime_md_first_line() {
    let dir = scratch("errors");
    std::fs::write(dir.join("m.mission"), "MISSION M:\n    d1 TakeOff WITH 20s\n").unwrap();
    std::fs::write(dir.join("m.world.toml"), WORLD).unwrap();
    let (code, out, _) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 1, "{out}");
    let first = out.lines().next().unwrap_or_default();
    assert_eq!(first, "m.mission:2:21: error[E107]: `TakeOff`'s `alt` is a length (m, km), but this is a duration (s, min, h)");
    assert!(out.contains("2 |     d1 TakeOff WITH 20s"), "the source line is shown: {out}");
    assert!(out.contains("^^^"), "a caret marks the place: {out}");
    assert!(out.contains("help: write a length"), "{out}");
}

#[test]
fn json_gives_one_object_per_diagnostic() {
    let dir = scratch("json");
    std::fs::write(dir.join("m.mission"), "MISSION M:\n    d1 TakeOff WITH 20s\n    d2 Land\n")
        .unwrap();
    std::fs::write(dir.join("m.world.toml"), WORLD).unwrap();
    let (code, out, _) = aviary(&["check", "m.mission", "--format", "json"], &dir);
    assert_eq!(code, 1);
    let objects: Vec<serde_json::Value> =
        out.lines().map(|l| serde_json::from_str(l).expect("each line is JSON")).collect();
    assert_eq!(objects.len(), 2, "{out}");
    assert_eq!(objects[0]["code"], "E107");
    assert_eq!(objects[0]["line"], 2);
    assert_eq!(objects[0]["column"], 21);
    assert_eq!(objects[0]["severity"], "error");
    assert_eq!(objects[1]["code"], "E102");
    assert_eq!(objects[1]["help"], "did you mean `d1`?");
}

#[test]
fn an_explicit_world_is_used_and_a_missing_file_is_exit_2() {
    let dir = scratch("world_flag");
    std::fs::write(dir.join("m.mission"), "MISSION M:\n    d1 FlyTo WITH Home\n").unwrap();
    std::fs::write(dir.join("other.toml"), WORLD).unwrap();
    let (code, out, _) = aviary(&["check", "m.mission", "--world", "other.toml"], &dir);
    assert_eq!(code, 0, "{out}");
    let (code, _, err) = aviary(&["check", "nope.mission"], &dir);
    assert_eq!(code, 2);
    assert!(err.contains("cannot read nope.mission"), "{err}");
    let (code, _, err) = aviary(&["check", "m.mission", "--world", "nope.toml"], &dir);
    assert_eq!(code, 2, "{err}");
    let (code, _, _) = aviary(&["check"], &dir);
    assert_eq!(code, 2, "usage errors are exit 2");
}

#[test]
fn without_a_world_names_are_not_checked_and_a_note_says_so() {
    let dir = scratch("no_world");
    std::fs::write(dir.join("m.mission"), "MISSION M:\n    anyone FlyTo WITH Anywhere\n").unwrap();
    let (code, out, _) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("note[N302]"), "{out}");
}

#[test]
fn a_broken_world_file_is_reported_in_the_world_file() {
    let dir = scratch("bad_world");
    std::fs::write(dir.join("m.mission"), "MISSION M:\n    d1 Land\n").unwrap();
    std::fs::write(dir.join("m.world.toml"), "[drones.d1]\nhome = \"here\"\n").unwrap();
    let (code, out, _) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 1, "{out}");
    assert!(out.starts_with("m.world.toml:2:8: error[E119]"), "{out}");
}

#[test]
fn used_files_are_read_relative_to_the_using_file_once_each() {
    let dir = scratch("use");
    std::fs::create_dir_all(dir.join("lib")).unwrap();
    std::fs::write(
        dir.join("m.mission"),
        "USE \"lib/a.mission\"\nUSE \"lib/b.mission\"\nMISSION M:\n    d1 Patrol\n",
    )
    .unwrap();
    std::fs::write(dir.join("m.world.toml"), WORLD).unwrap();
    std::fs::write(
        dir.join("lib/a.mission"),
        "USE \"b.mission\"\nCAPABILITY Patrol BY drone:\n    PERFORM:\n        drone Circle\n",
    )
    .unwrap();
    std::fs::write(dir.join("lib/b.mission"), "USE \"a.mission\"\nCAPABILITY Circle BY drone:\n    PERFORM:\n        drone.Orbit((0, 0), 10m)\n").unwrap();
    let (code, out, _) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 0, "a USE cycle is fine and each file is read once: {out}");
    std::fs::write(dir.join("m.mission"), "USE \"lib/missing.mission\"\nMISSION M:\n    d1 Land\n")
        .unwrap();
    let (code, out, _) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 1);
    assert!(
        out.starts_with("m.mission:1:5: error[E113]: cannot read `lib/missing.mission`"),
        "{out}"
    );
}

#[test]
fn a_use_reads_only_mission_files_under_the_missions_folder_and_never_shows_another_file() {
    let dir = scratch("use_rules");
    let (home, shared) = (dir.join("home"), dir.join("shared"));
    std::fs::create_dir_all(&home).unwrap();
    std::fs::create_dir_all(&shared).unwrap();
    std::fs::write(home.join("m.world.toml"), WORLD).unwrap();
    std::fs::write(
        shared.join("lib.mission"),
        "CAPABILITY Patrol BY drone:\n    PERFORM:\n        drone.Hover(1s)\n",
    )
    .unwrap();
    let check = |used: &str, extra: &[&str]| {
        std::fs::write(
            home.join("m.mission"),
            format!("USE \"{used}\"\nMISSION M:\n    d1 Patrol\n"),
        )
        .unwrap();
        let mut args = vec!["check", "home/m.mission"];
        args.extend(extra);
        aviary(&args, &dir)
    };
    let refused = |used: &str, why: &str| {
        let (code, out, _) = check(used, &[]);
        assert_eq!(code, 1, "{out}");
        assert!(
            out.starts_with(&format!(
                "home/m.mission:1:5: error[E127]: this USE of `{used}` is refused: "
            )),
            "{out}"
        );
        assert!(out.contains(why), "{used}: {out}");
        out
    };
    // The environment and the password file are not mission files: nothing of them shows.
    let out = refused("/proc/self/environ", "it is not a mission file");
    assert!(!out.contains("PATH="), "{out}");
    let out = refused("../../../../../../../../etc/passwd", "it is not a mission file");
    assert!(!out.contains("root:"), "{out}");
    refused("/dev/zero", "it is not a mission file");
    // Outside the mission's folder, directly or through a symlink, until named a root.
    refused("../shared/lib.mission", "is outside the mission's folder");
    std::os::unix::fs::symlink(shared.join("lib.mission"), home.join("link.mission")).unwrap();
    refused("link.mission", "leads to");
    let (code, out, _) = check("../shared/lib.mission", &["--use-root", "shared"]);
    assert_eq!(code, 0, "{out}");
    let (code, out, _) = check("link.mission", &["--use-root", "shared"]);
    assert_eq!(code, 0, "{out}");
    // Not a regular file, or too large: refused without being read (a FIFO would block).
    assert!(std::process::Command::new("mkfifo")
        .arg(home.join("pipe.mission"))
        .status()
        .unwrap()
        .success());
    refused("pipe.mission", "is a device, pipe or socket, not a regular file");
    std::fs::create_dir(home.join("folder.mission")).unwrap();
    refused("folder.mission", "is a folder, not a regular file");
    std::fs::File::create(home.join("big.mission")).unwrap().set_len(17 << 20).unwrap();
    refused("big.mission", "has 17825792 bytes, more than the 16 MiB a USEd file may have");
    let (code, out, _) = check("", &[]);
    assert_eq!(code, 1);
    assert!(
        out.starts_with(
            "home/m.mission:1:5: error[E127]: this USE names no file: its path is empty"
        ),
        "{out}"
    );
    let (code, _, err) = aviary(&["check", "home/m.mission", "--use-root", "nowhere"], &dir);
    assert_eq!(code, 2);
    assert!(err.starts_with("aviary: --use-root nowhere: "), "{err}");
}

#[test]
fn an_empty_file_name_says_what_was_empty() {
    let dir = scratch("empty_names");
    for (args, what) in [
        (&["check", ""][..], "invalid value '' for '<FILES>...': the name is empty: write the path of a .mission file"),
        (&["check", "m.mission", "--world", ""][..], "invalid value '' for '--world <WORLD>': the name is empty: write the path of a world file"),
        (&["run", ""][..], "invalid value '' for '<FILE>': the name is empty: write the path of a .mission file"),
        (&["check", "m.mission", "--use-root", ""][..], "invalid value '' for '--use-root <DIR>': the name is empty: write the path of a folder"),
    ] {
        let (code, _, err) = aviary(args, &dir);
        assert_eq!(code, 2, "{args:?}");
        assert!(err.contains(what), "{args:?}: {err}");
    }
}

#[test]
fn several_files_are_checked_and_the_worst_exit_wins() {
    let dir = scratch("several");
    std::fs::write(
        dir.join("good.mission"),
        "CAPABILITY Go BY drone:\n    PERFORM:\n        drone.Land()\n",
    )
    .unwrap();
    std::fs::write(dir.join("bad.mission"), "MISSION M:\n    d1 TakeOff WITH 5s\n").unwrap();
    std::fs::write(dir.join("bad.world.toml"), WORLD).unwrap();
    let (code, out, _) = aviary(&["check", "good.mission", "bad.mission"], &dir);
    assert_eq!(code, 1);
    assert!(out.contains("good.mission: ok") && out.contains("bad.mission: 1 error"), "{out}");
}

#[test]
fn binary_and_non_utf8_files_get_one_clear_diagnostic() {
    let dir = scratch("binary");
    std::fs::write(dir.join("b.mission"), b"MISSION M:\n\x00\x01\x02garbage").unwrap();
    std::fs::write(dir.join("u.mission"), b"MISSION M:\n    d1 Land \xff\xfe\n").unwrap();
    let (code, out, _) = aviary(&["check", "b.mission", "u.mission"], &dir);
    assert_eq!(code, 1);
    assert!(out.contains("b.mission:2:1: error[E002]"), "{out}");
    assert!(out.contains("u.mission:2:13: error[E001]"), "{out}");
    assert_eq!(out.matches("error[").count(), 2, "one diagnostic each: {out}");
}

#[test]
fn fmt_rewrites_checks_and_never_touches_a_file_with_errors() {
    let dir = scratch("fmt");
    let messy = "MISSION   M:\n  SEQUENTIAL   A:\n      d1 TakeOff WITH 20 m   // climb\n";
    std::fs::write(dir.join("m.mission"), messy).unwrap();
    let (code, out, _) = aviary(&["fmt", "--check", "m.mission"], &dir);
    assert_eq!(code, 1, "{out}");
    assert_eq!(
        std::fs::read_to_string(dir.join("m.mission")).unwrap(),
        messy,
        "--check changes nothing"
    );
    let (code, _, _) = aviary(&["fmt", "m.mission"], &dir);
    assert_eq!(code, 0);
    let formatted = std::fs::read_to_string(dir.join("m.mission")).unwrap();
    assert!(formatted.contains("    SEQUENTIAL A:\n        d1 TakeOff WITH 20m"), "{formatted}");
    assert!(formatted.contains("// climb"), "comments are kept: {formatted}");
    let (code, _, _) = aviary(&["fmt", "--check", "m.mission"], &dir);
    assert_eq!(code, 0, "formatted output is stable");

    let broken = "MISSION M:\n    d1 TakeOff WITH (\n";
    std::fs::write(dir.join("broken.mission"), broken).unwrap();
    let (code, out, _) = aviary(&["fmt", "broken.mission"], &dir);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("not formatted, because it has syntax errors"), "{out}");
    assert_eq!(std::fs::read_to_string(dir.join("broken.mission")).unwrap(), broken);
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("tmp"))
        .collect();
    assert!(leftovers.is_empty(), "no temporary files are left behind");
}

#[test]
fn explain_prints_what_a_code_means() {
    let (code, out, _) = aviary(&["explain", "e107"], &repo());
    assert_eq!(code, 0);
    assert!(out.starts_with("E107 (error): a value of the wrong kind"), "{out}");
    let (code, _, _) = aviary(&["explain", "X999"], &repo());
    assert_eq!(code, 2);
}

#[test]
fn a_reader_that_stops_reading_ends_the_output_not_in_a_panic() {
    use std::process::{Command, Stdio};
    // Hundreds of kilobytes to a pipe whose reader is gone before the first write ends.
    let mut child = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["bench", "w", "--n", "20000", "--k", "1", "--emit-world"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.is_empty(), "a closed pipe is not an error to report: {stderr}");
}

/// `ALLOW W203 "reason"` before one of the two statements: `aviary check` shows the
/// warning as an acknowledged note with its reason, and exits 0 with no warning; the same
/// ALLOW where no W203 is warns that it matches nothing.
#[test]
fn an_allow_acknowledges_a_preflight_warning_and_an_unused_one_warns() {
    let dir = scratch("allow");
    let world = "[places]\nNorth = [0, 100]\nEast = [100, 0]\n[drones.d1]\nhome = [0, 0]\n";
    std::fs::write(dir.join("m.world.toml"), world).unwrap();
    let both = |allow_at: usize| {
        let mut lines = vec![
            "MISSION M:",
            "    d1 TakeOff WITH 20m",
            "    PARALLEL Both:",
            "        d1 FlyTo WITH North",
            "        d1 FlyTo WITH East",
            "    d1 ReturnHome",
        ];
        lines.insert(allow_at, "        ALLOW W203 \"the second flight is meant to wait\"");
        lines.join("\n") + "\n"
    };
    std::fs::write(dir.join("m.mission"), both(3)).unwrap();
    let (code, out, _) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("note[W203]"), "{out}");
    assert!(out.contains("acknowledged: the second flight is meant to wait"), "{out}");
    assert!(!out.contains("warning["), "{out}");
    assert!(out.contains("m.mission: ok (1 note)"), "{out}");
    // The other statement of the pair acknowledges it too: the warning shows both.
    std::fs::write(dir.join("m.mission"), both(4)).unwrap();
    let (code, out, _) = aviary(&["check", "m.mission"], &dir);
    assert_eq!((code, out.contains("note[W203]")), (0, true), "{out}");
    // Before the block's return, where nothing conflicts, it matches nothing.
    let unused = both(3).replace("        ALLOW", "    ALLOW").replace(
        "    PARALLEL Both:\n    ALLOW W203 \"the second flight is meant to wait\"\n        d1 FlyTo WITH North\n",
        "    PARALLEL Both:\n        d1 FlyTo WITH North\n",
    );
    let unused = unused.replace(
        "    d1 ReturnHome\n",
        "    ALLOW W203 \"the second flight is meant to wait\"\n    d1 ReturnHome\n",
    );
    std::fs::write(dir.join("m.mission"), &unused).unwrap();
    let (code, out, _) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("warning[W211]: ALLOW W203 matches no warning here; remove it"), "{out}");
    assert!(out.contains("warning[W203]"), "the W203 it did not reach stays: {out}");
}
