//! What a `USE` may read (docs/SECURITY.md, "Mission files (USE)"). A mission file is
//! text that `aviary check` shows back, line by line, in its diagnostics; a `USE` of
//! `/proc/self/environ` would print the environment. So a `USE` reads only `.mission`
//! files, under the mission's own folder or a folder the user names (`--use-root`), and
//! only regular files of at most [`MAX_USE_BYTES`]. A refusal (E127) says why and what to
//! do, never what the file holds.
//!
//! The rules are pure: [`check_written`] judges the path as written (here, before any
//! provider is asked), [`within_roots`] a path the provider has resolved. The provider
//! (the CLI's `DiskProvider`) does the IO: it resolves symlinks, so a link that leads
//! out of the roots counts as outside.

use std::path::{Path, PathBuf};

/// The largest file a `USE` reads: 16 MiB. A hand-written library is kilobytes; the
/// limit only keeps a `USE` of a huge or endless file (`/dev/zero`) from taking the
/// machine's memory. A mission given on the command line has no such limit.
pub const MAX_USE_BYTES: u64 = 16 << 20;

/// The extension of a mission file, the only kind a `USE` reads.
pub const MISSION_EXTENSION: &str = "mission";

/// Why a provider gives no file for a `USE`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LoadError {
    /// There is no such file, or it cannot be read (E113): why, in a few words.
    Unreadable(String),
    /// The file is not one a `USE` may read (E127): why, and what to do instead.
    Refused { why: String, help: String },
}

/// Most providers only fail to find a file.
impl From<String> for LoadError {
    fn from(why: String) -> LoadError {
        LoadError::Unreadable(why)
    }
}

/// The help of a refusal for a path outside the roots.
pub const OUTSIDE_HELP: &str =
    "a USE reads .mission files under the folder of the mission being checked; move the file there, or name its folder with `--use-root DIR`";

/// The path as written in the `USE`: not empty, and naming a `.mission` file.
pub fn check_written(path: &str) -> Result<(), LoadError> {
    if path.trim().is_empty() {
        return Err(LoadError::Refused {
            why: "this USE names no file: its path is empty".into(),
            help: "write the path of a .mission file, relative to this file: `USE \"lib/beacons.mission\"`".into(),
        });
    }
    if !is_mission_name(Path::new(path)) {
        return Err(not_a_mission());
    }
    Ok(())
}

/// Whether a file's name ends in `.mission` (and is more than that).
pub fn is_mission_name(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == MISSION_EXTENSION)
        && path.file_stem().is_some_and(|s| !s.is_empty())
}

/// The refusal of a file that is not a mission file.
pub fn not_a_mission() -> LoadError {
    LoadError::Refused {
        why: "it is not a mission file: a USE reads only files whose names end in `.mission`".into(),
        help: "USE names a file of capabilities written in the language, such as `USE \"lib/beacons.mission\"`; a world file is given with `--world`".into(),
    }
}

/// Whether `file` (resolved: absolute, no `..`, no symlinks) lies under one of `roots`
/// (resolved likewise). Compared by whole components: `/a/bc` is not under `/a/b`.
pub fn within_roots(file: &Path, roots: &[PathBuf]) -> bool {
    roots.iter().any(|root| file.starts_with(root))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_mission_files_may_be_written() {
        assert_eq!(check_written("lib/beacons.mission"), Ok(()));
        assert_eq!(check_written("../common/a.mission"), Ok(()));
        for refused in [
            "",
            "  ",
            "/proc/self/environ",
            "../../../../etc/passwd",
            "world.toml",
            "fifo",
            "/dev/zero",
            ".mission",
            "lib/",
            "a.mission.txt",
        ] {
            assert!(
                matches!(check_written(refused), Err(LoadError::Refused { .. })),
                "{refused:?}"
            );
        }
    }

    #[test]
    fn roots_compare_whole_components() {
        let roots = [PathBuf::from("/work/m")];
        assert!(within_roots(Path::new("/work/m/lib/a.mission"), &roots));
        assert!(within_roots(Path::new("/work/m/a.mission"), &roots));
        assert!(!within_roots(Path::new("/work/mission/a.mission"), &roots));
        assert!(!within_roots(Path::new("/etc/a.mission"), &roots));
        assert!(!within_roots(Path::new("/work/a.mission"), &[]));
    }
}
