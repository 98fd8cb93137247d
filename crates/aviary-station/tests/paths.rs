//! Every path the ground station reads or writes is checked by one function
//! (`Folder::place`, docs/SECURITY.md): this is its suite. The cases are data,
//! `tests/paths/cases.txt`, asked of a folder laid out below with links in and out of
//! it; the answers are a snapshot, and after each case nothing outside the folder may
//! have changed. The tests after it are the reproductions, one each.

#![cfg(unix)]

use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};

use aviary_station::Folder;

/// A folder of its own for each test: `ROOT` (the station's) and `OUTSIDE` beside it.
fn lay_out(name: &str) -> (PathBuf, PathBuf) {
    let base = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("station_paths_{name}"));
    let _ = std::fs::remove_dir_all(&base);
    let (root, outside) = (base.join("root"), base.join("outside"));
    for dir in [&root, &outside, &root.join("drills"), &root.join("traces")] {
        std::fs::create_dir_all(dir).unwrap();
    }
    std::fs::create_dir_all(root.join("folder.mission")).unwrap();
    let files = [
        ("a.mission", "MISSION A:\n"),
        ("a.world.toml", "[site]\n"),
        ("notes.txt", "notes\n"),
        ("drills/b.mission", "MISSION B:\n"),
        ("traces/t.jsonl", "{}\n"),
        (".hidden.mission", "MISSION Hidden:\n"),
        ("100%25.mission", "MISSION Percent:\n"),
        ("victim.mission", "MISSION Victim:\n"),
    ];
    for (file, text) in files {
        std::fs::write(root.join(file), text).unwrap();
    }
    std::fs::write(outside.join("secret.mission"), "MISSION Secret:\n").unwrap();
    let links = [
        ("in.mission", PathBuf::from("a.mission")),
        ("in_dir", PathBuf::from("drills")),
        ("txt.mission", PathBuf::from("notes.txt")),
        ("out.mission", outside.join("secret.mission")),
        ("out_dir", outside.clone()),
        ("dangling_out.mission", outside.join("none.mission")),
        // The issue's: where a save once wrote its new text first, leading outside.
        (".victim.mission.saving", outside.join("planted.mission")),
    ];
    for (link, to) in links {
        symlink(to, root.join(link)).unwrap();
    }
    let fifo = std::process::Command::new("mkfifo").arg(root.join("fifo.mission")).status();
    assert!(fifo.is_ok_and(|s| s.success()), "mkfifo");
    (root, outside)
}

/// Every file outside the folder, with its text: what no case may change.
fn outside_as_it_is(outside: &Path) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = std::fs::read_dir(outside)
        .unwrap()
        .map(|e| {
            let path = e.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap_or_default();
            (path.file_name().unwrap().to_string_lossy().into_owned(), text)
        })
        .collect();
    out.sort();
    out
}

#[test]
fn answers() {
    let (root, outside) = lay_out("answers");
    let before = outside_as_it_is(&outside);
    let folder = Folder::new(&root).unwrap();
    let cases = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/paths/cases.txt"),
    )
    .unwrap();
    let mut answers = String::new();
    for line in cases.lines().filter(|l| !l.trim().is_empty() && !l.starts_with('#')) {
        let (op, path) = line.split_once(' ').unwrap_or((line, ""));
        let path = if path == "<empty>" { "" } else { path };
        let answer = match op {
            "open" => folder.read(path).map(|text| text.lines().next().unwrap_or("").to_string()),
            "save" => folder.save(path, "MISSION Saved:\n").map(|()| "saved".to_string()),
            _ => panic!("no such operation: {line}"),
        };
        let shown = match answer {
            Ok(what) => format!("{line} → ok: {what}"),
            Err(why) => format!("{line} → refused: {why}"),
        };
        answers.push_str(&shown.replace(&*root.to_string_lossy(), "ROOT"));
        answers.push('\n');
        assert_eq!(outside_as_it_is(&outside), before, "{line}: a file outside changed");
        assert!(!outside.join("planted.mission").exists(), "{line}: written through a link");
    }
    insta::assert_snapshot!(answers);
}

/// The issue's: the folder (a cloned repository, say) holds `victim.mission` and a link
/// `.victim.mission.saving` to a file outside. Saving `victim.mission` once wrote the new
/// text through the link, into the file outside.
#[test]
fn a_save_never_writes_through_a_link_planted_where_it_writes_first() {
    let (root, outside) = lay_out("planted");
    std::fs::write(outside.join("planted.mission"), "outside, untouched\n").unwrap();
    let folder = Folder::new(&root).unwrap();
    folder.save("victim.mission", "MISSION Victim:\n    SIGNAL Saved\n").unwrap();
    assert_eq!(
        std::fs::read_to_string(outside.join("planted.mission")).unwrap(),
        "outside, untouched\n"
    );
    assert_eq!(
        std::fs::read_to_string(root.join("victim.mission")).unwrap(),
        "MISSION Victim:\n    SIGNAL Saved\n"
    );
    // And the link, which is not the station's, is left where it was.
    assert!(root.join(".victim.mission.saving").symlink_metadata().unwrap().is_symlink());
}

#[test]
fn a_save_to_a_link_that_leads_out_of_the_folder_is_refused() {
    let (root, outside) = lay_out("link_out");
    let folder = Folder::new(&root).unwrap();
    for path in ["out.mission", "dangling_out.mission", "out_dir/secret.mission"] {
        let why = folder.save(path, "MISSION Overwritten:\n").unwrap_err();
        assert!(why.contains("leads outside the station's folder"), "{path}: {why}");
    }
    assert_eq!(
        std::fs::read_to_string(outside.join("secret.mission")).unwrap(),
        "MISSION Secret:\n"
    );
    assert!(!outside.join("none.mission").exists());
}

/// A save keeps the file's permissions, and leaves no temporary file behind.
#[test]
fn a_save_replaces_the_file_whole_and_leaves_nothing_beside_it() {
    use std::os::unix::fs::PermissionsExt;
    let (root, _) = lay_out("whole");
    std::fs::set_permissions(root.join("a.mission"), std::fs::Permissions::from_mode(0o640))
        .unwrap();
    let folder = Folder::new(&root).unwrap();
    let before: Vec<_> =
        std::fs::read_dir(&root).unwrap().map(|e| e.unwrap().file_name()).collect();
    folder.save("a.mission", "MISSION A2:\n").unwrap();
    let after: Vec<_> = std::fs::read_dir(&root).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(before.len(), after.len(), "nothing left beside it: {after:?}");
    let meta = std::fs::metadata(root.join("a.mission")).unwrap();
    assert_eq!(meta.permissions().mode() & 0o777, 0o640);
    assert_eq!(std::fs::read_to_string(root.join("a.mission")).unwrap(), "MISSION A2:\n");
}
