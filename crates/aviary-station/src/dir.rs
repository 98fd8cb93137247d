//! The station's folder: the missions and worlds it lists, opens and saves. A page may
//! name only a file in that folder or below it, by a relative path without `..`, with
//! the extension of a mission (`.mission`) or a world (`.toml`); a symlink that leads out
//! of the folder is refused as it would be by `USE` (docs/SECURITY.md). Saving replaces
//! the file whole (written beside it, then renamed), so a failed save loses nothing.

use std::path::{Component, Path, PathBuf};

use serde::Serialize;

/// The largest file the station opens or saves: the limit of a `USE`d mission.
pub const MAX_FILE_BYTES: u64 = aviary_check::uses::MAX_USE_BYTES;

/// How deep below the folder the listing looks.
const MAX_DEPTH: usize = 4;

/// What the folder holds, by relative path, sorted.
#[derive(Debug, Default, Serialize)]
pub struct Listing {
    pub missions: Vec<String>,
    pub worlds: Vec<String>,
    /// The recorded traces (`.jsonl`), such as the station's own flights in `traces/`.
    pub traces: Vec<String>,
}

pub struct Folder {
    /// Canonical.
    root: PathBuf,
}

impl Folder {
    pub fn new(dir: &Path) -> Result<Folder, String> {
        let root = std::fs::canonicalize(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        if !root.is_dir() {
            return Err(format!("{} is not a folder", dir.display()));
        }
        Ok(Folder { root })
    }

    pub fn root(&self) -> &Path {
        &self.root
    }

    pub fn list(&self) -> Listing {
        let mut listing = Listing::default();
        self.walk(&self.root, 0, &mut listing);
        listing.missions.sort();
        listing.worlds.sort();
        listing.traces.sort();
        listing
    }

    fn walk(&self, dir: &Path, depth: usize, listing: &mut Listing) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for entry in entries.flatten() {
            let path = entry.path();
            let Ok(kind) = entry.file_type() else { continue };
            let Ok(relative) = path.strip_prefix(&self.root) else { continue };
            let shown = relative.to_string_lossy().replace('\\', "/");
            if kind.is_dir() && depth + 1 < MAX_DEPTH && !shown.starts_with('.') {
                self.walk(&path, depth + 1, listing);
            } else if kind.is_file() {
                match FileKind::of(&shown) {
                    Some(FileKind::Mission) => listing.missions.push(shown),
                    Some(FileKind::World) => listing.worlds.push(shown),
                    Some(FileKind::Trace) => listing.traces.push(shown),
                    None => {}
                }
            }
        }
    }

    /// The file at `relative`, checked to be one the station may touch; it need not exist.
    pub fn resolve(&self, relative: &str) -> Result<PathBuf, String> {
        if FileKind::of(relative).is_none() {
            return Err(format!(
                "`{}` is not a mission (.mission), a world (.toml) or a trace (.jsonl): the station opens only those",
                shown(relative)
            ));
        }
        let path = Path::new(relative);
        let plain = path.components().all(|c| matches!(c, Component::Normal(_)));
        if relative.is_empty() || !plain {
            return Err(format!(
                "`{}` is not a path inside the station's folder: name a file as the list shows it, without `..` or a leading `/`",
                shown(relative)
            ));
        }
        let full = self.root.join(path);
        // A symlink or a folder on the way may lead elsewhere: judge where it leads.
        let parent = full.parent().unwrap_or(&self.root);
        let parent = std::fs::canonicalize(parent).map_err(|_| {
            format!("there is no folder for `{}` in the station's folder", shown(relative))
        })?;
        let target = match std::fs::canonicalize(&full) {
            Ok(p) => p,
            Err(_) => parent.join(full.file_name().unwrap_or_default()),
        };
        if !aviary_check::uses::within_roots(&target, std::slice::from_ref(&self.root)) {
            return Err(format!(
                "`{}` leads outside the station's folder {}",
                shown(relative),
                self.root.display()
            ));
        }
        Ok(target)
    }

    pub fn read(&self, relative: &str) -> Result<String, String> {
        let path = self.resolve(relative)?;
        let meta = std::fs::metadata(&path).map_err(|e| format!("{}: {e}", shown(relative)))?;
        if !meta.is_file() {
            return Err(format!("`{}` is not a regular file", shown(relative)));
        }
        if meta.len() > MAX_FILE_BYTES {
            return Err(format!("`{}` is larger than the station opens (16 MiB)", shown(relative)));
        }
        let bytes = std::fs::read(&path).map_err(|e| format!("{}: {e}", shown(relative)))?;
        String::from_utf8(bytes)
            .map_err(|_| format!("`{}` is not UTF-8 text: save it as UTF-8", shown(relative)))
    }

    /// Replaces the file with `text`: written to a new file beside it, then renamed over it.
    pub fn save(&self, relative: &str, text: &str) -> Result<(), String> {
        if text.len() as u64 > MAX_FILE_BYTES {
            return Err("the text is larger than the station saves (16 MiB)".into());
        }
        if FileKind::of(relative) == Some(FileKind::Trace) {
            return Err(format!(
                "`{}` is a trace, the record of a flight: the station never rewrites one",
                shown(relative)
            ));
        }
        let path = self.resolve(relative)?;
        if path.is_dir() {
            return Err(format!("`{}` is a folder", shown(relative)));
        }
        let name = path.file_name().unwrap_or_default().to_string_lossy().into_owned();
        let temporary = path.with_file_name(format!(".{name}.saving"));
        std::fs::write(&temporary, text).and_then(|()| std::fs::rename(&temporary, &path)).map_err(
            |e| {
                let _ = std::fs::remove_file(&temporary);
                format!("cannot save `{}`: {e}", shown(relative))
            },
        )
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Mission,
    World,
    /// A recorded trace: read (replayed, reported), never saved.
    Trace,
}

impl FileKind {
    pub fn of(path: &str) -> Option<FileKind> {
        if path.ends_with(".mission") {
            Some(FileKind::Mission)
        } else if path.ends_with(".toml") {
            Some(FileKind::World)
        } else if path.ends_with(".jsonl") {
            Some(FileKind::Trace)
        } else {
            None
        }
    }
}

/// A path as a message shows it: short, printable.
fn shown(text: &str) -> String {
    text.chars().filter(|c| !c.is_control()).take(120).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn folder() -> (PathBuf, Folder) {
        let dir = std::env::temp_dir().join(format!("aviary-station-dir-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("drills")).unwrap();
        std::fs::write(dir.join("a.mission"), "MISSION A:\n").unwrap();
        std::fs::write(dir.join("a.world.toml"), "").unwrap();
        std::fs::write(dir.join("drills/b.mission"), "").unwrap();
        std::fs::write(dir.join("notes.txt"), "").unwrap();
        std::fs::create_dir_all(dir.join("traces")).unwrap();
        std::fs::write(dir.join("traces/a-1.jsonl"), "{}\n").unwrap();
        let folder = Folder::new(&dir).unwrap();
        (dir, folder)
    }

    #[test]
    fn lists_opens_and_saves_only_what_is_inside() {
        let (dir, folder) = folder();
        let listing = folder.list();
        assert_eq!(listing.missions, ["a.mission", "drills/b.mission"]);
        assert_eq!(listing.worlds, ["a.world.toml"]);
        assert_eq!(listing.traces, ["traces/a-1.jsonl"]);
        assert_eq!(folder.read("traces/a-1.jsonl").unwrap(), "{}\n");
        let why = folder.save("traces/a-1.jsonl", "").unwrap_err();
        assert!(why.contains("never rewrites"), "{why}");
        assert_eq!(folder.read("traces/a-1.jsonl").unwrap(), "{}\n", "a trace is kept as it was");
        assert_eq!(folder.read("a.mission").unwrap(), "MISSION A:\n");
        folder.save("drills/b.mission", "MISSION B:\n").unwrap();
        assert_eq!(folder.read("drills/b.mission").unwrap(), "MISSION B:\n");
        for bad in ["../a.mission", "/etc/passwd.toml", "notes.txt", "", "drills/../a.mission"] {
            let why = folder.read(bad).unwrap_err();
            assert!(!why.is_empty(), "{bad}");
        }
        assert!(folder.save("nowhere/c.mission", "").is_err(), "no folder is made");
        #[cfg(unix)]
        {
            std::os::unix::fs::symlink("/etc", dir.join("out")).unwrap();
            let why = folder.read("out/x.toml").unwrap_err();
            assert!(why.contains("outside"), "{why}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
