//! The station's folder: the missions and worlds it lists, opens and saves, and the
//! traces of its flights. Every path the station reads or writes, whatever the call, is
//! checked by one function, [`Folder::place`] (docs/SECURITY.md): a plain relative name
//! of a mission (`.mission`), a world (`.toml`) or a trace (`.jsonl`), never hidden, with
//! no `..`, `.`, empty part, backslash, control character or percent-escape; every
//! folder on the way and the file itself, links followed, inside the folder; for a save
//! or a new trace, a regular file or none. What is opened is what was checked: a file is
//! read without following a link, saved by writing a new file that cannot be a link
//! (`tempfile`, `O_EXCL`) beside it and renaming it over, and a trace made only where no
//! file or link is (`O_EXCL`). `tests/paths.rs` is the suite of `place`.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use serde::Serialize;

/// The largest file the station opens or saves: the limit of a `USE`d mission.
pub const MAX_FILE_BYTES: u64 = aviary_check::uses::MAX_USE_BYTES;

/// How deep below the folder the listing looks.
const MAX_DEPTH: usize = 4;

/// The longest name the station takes (bytes): far more than any list shows.
const MAX_NAME_BYTES: usize = 1024;

/// What the folder holds, by relative path, sorted.
#[derive(Debug, Default, Serialize)]
pub struct Listing {
    pub missions: Vec<String>,
    pub worlds: Vec<String>,
    /// The recorded traces (`.jsonl`), such as the station's own flights in `traces/`.
    pub traces: Vec<String>,
}

/// What the station does with a path: what [`Folder::place`] allows for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// Read a mission, a world or a trace that is there.
    Open,
    /// Write a mission or a world (a trace, never): replace the file, or make it.
    Save,
    /// Make a new trace, the record of a flight: never where a file or a link is.
    Record,
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

    /// The missions, worlds and traces of the folder that the station would open: those
    /// whose names [`Folder::place`] takes (no hidden file or folder, no link).
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
            if refused_name(&shown).is_some() && !kind.is_dir() {
                continue;
            }
            if kind.is_dir()
                && depth + 1 < MAX_DEPTH
                && !entry.file_name().to_string_lossy().starts_with('.')
            {
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

    /// The one check of every path the station reads or writes: where `relative` really
    /// is, if the station may do `access` there, else why not (a message for the page).
    ///
    /// The name must be a plain relative path ([`refused_name`]) of the kind `access`
    /// takes: a mission, world or trace to open; a mission or world to save; a trace to
    /// record. Every folder on the way, links followed, must be inside the folder (a
    /// `traces` folder to record in is made if missing). The file, if it is there, is
    /// judged where it really is: a link is followed, and must lead inside the folder to
    /// a file of the same kind; it must be a regular file (no folder, FIFO or device);
    /// and a trace is only ever recorded where nothing is. The answer is that real
    /// place: the caller opens it without following links, or, to save, writes a new file
    /// beside it and renames it over.
    pub fn place(&self, relative: &str, access: Access) -> Result<PathBuf, String> {
        if let Some(why) = refused_name(relative) {
            return Err(match relative {
                "" => format!("the path {why}"),
                _ => format!("`{}` {why}", shown(relative)),
            });
        }
        let kind = FileKind::of(relative);
        match (access, kind) {
            (_, None) => {
                return Err(format!(
                    "`{}` is not a mission (.mission), a world (.toml) or a trace (.jsonl): the station opens only those",
                    shown(relative)
                ))
            }
            (Access::Save, Some(FileKind::Trace)) => {
                return Err(format!(
                    "`{}` is a trace, the record of a flight: the station never rewrites one",
                    shown(relative)
                ))
            }
            (Access::Record, Some(k)) if k != FileKind::Trace => {
                return Err(format!("`{}` is not a trace (.jsonl)", shown(relative)))
            }
            _ => {}
        }
        let full = self.root.join(relative);
        let name = full.file_name().unwrap_or_default().to_owned();
        let parent = full.parent().unwrap_or(&self.root);
        if access == Access::Record {
            self.make_folders(parent, relative)?;
        }
        // The folders on the way, links followed.
        let parent = std::fs::canonicalize(parent).map_err(|_| {
            format!("there is no folder for `{}` in the station's folder", shown(relative))
        })?;
        let outside = || {
            format!(
                "`{}` leads outside the station's folder {}",
                shown(relative),
                self.root.display()
            )
        };
        if !parent.starts_with(&self.root) {
            return Err(outside());
        }
        let here = parent.join(&name);
        let file = match std::fs::symlink_metadata(&here) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return match access {
                    Access::Open => Err(format!("`{}`: there is no such file", shown(relative))),
                    Access::Save | Access::Record => Ok(here),
                };
            }
            Err(e) => return Err(format!("`{}`: {e}", shown(relative))),
            Ok(meta) => meta,
        };
        if access == Access::Record {
            return Err(format!(
                "`{}` is there already: a trace is never written over",
                shown(relative)
            ));
        }
        let real = if file.file_type().is_symlink() {
            // Where the link leads; a link that leads nowhere leads outside as far as
            // the station knows (it would make a file wherever that is).
            let real = std::fs::canonicalize(&here).map_err(|_| outside())?;
            if !real.starts_with(&self.root) {
                return Err(outside());
            }
            let real_name = real.to_string_lossy().into_owned();
            if FileKind::of(&real_name) != kind {
                return Err(format!(
                    "`{}` is a link to a file that is no {}",
                    shown(relative),
                    kind.map_or("file", FileKind::noun)
                ));
            }
            real
        } else {
            here
        };
        let meta = std::fs::metadata(&real).map_err(|e| format!("`{}`: {e}", shown(relative)))?;
        if meta.is_dir() {
            return Err(format!("`{}` is a folder", shown(relative)));
        }
        if !meta.is_file() {
            return Err(format!("`{}` is not a regular file", shown(relative)));
        }
        Ok(real)
    }

    /// Makes the folders of `parent` under the folder that are missing, one at a time,
    /// each where nothing is (a link in their place is not followed: it is refused
    /// later, by where it leads).
    fn make_folders(&self, parent: &Path, relative: &str) -> Result<(), String> {
        let Ok(below) = parent.strip_prefix(&self.root) else { return Ok(()) };
        let mut at = self.root.clone();
        for part in below.components() {
            at.push(part);
            match std::fs::create_dir(&at) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
                Err(e) => {
                    return Err(format!("cannot make the folder for `{}`: {e}", shown(relative)))
                }
            }
        }
        Ok(())
    }

    /// The text of a mission, world or trace of the folder.
    pub fn read(&self, relative: &str) -> Result<String, String> {
        let path = self.place(relative, Access::Open)?;
        let why = |e: std::io::Error| format!("{}: {e}", shown(relative));
        let file = open_options().read(true).open(&path).map_err(why)?;
        let meta = file.metadata().map_err(why)?;
        if !meta.is_file() {
            return Err(format!("`{}` is not a regular file", shown(relative)));
        }
        if meta.len() > MAX_FILE_BYTES {
            return Err(format!("`{}` is larger than the station opens (16 MiB)", shown(relative)));
        }
        let mut bytes = Vec::new();
        file.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes).map_err(why)?;
        if bytes.len() as u64 > MAX_FILE_BYTES {
            return Err(format!("`{}` is larger than the station opens (16 MiB)", shown(relative)));
        }
        String::from_utf8(bytes)
            .map_err(|_| format!("`{}` is not UTF-8 text: save it as UTF-8", shown(relative)))
    }

    /// Replaces the mission or world with `text`: written to a new file beside it, made
    /// where nothing is (never through a link), then renamed over it. The file keeps its
    /// permissions; nothing is left beside it, whatever fails.
    pub fn save(&self, relative: &str, text: &str) -> Result<(), String> {
        if text.len() as u64 > MAX_FILE_BYTES {
            return Err("the text is larger than the station saves (16 MiB)".into());
        }
        let path = self.place(relative, Access::Save)?;
        let cannot = |e: &dyn std::fmt::Display| format!("cannot save `{}`: {e}", shown(relative));
        let beside = path.parent().unwrap_or(&self.root);
        let mut new = tempfile::Builder::new()
            .prefix(".aviary-saving-")
            .tempfile_in(beside)
            .map_err(|e| cannot(&e))?;
        new.as_file_mut().write_all(text.as_bytes()).map_err(|e| cannot(&e))?;
        // The file's own permissions; a new one is readable by all, as a plain write
        // would make it (the temporary file is made readable by its owner only).
        match std::fs::metadata(&path) {
            Ok(meta) => new.as_file().set_permissions(meta.permissions()),
            Err(_) => new_file_permissions(new.as_file()),
        }
        .map_err(|e| cannot(&e))?;
        new.as_file().sync_all().map_err(|e| cannot(&e))?;
        // A rename replaces what is at `path`, a link included, and follows none.
        new.persist(&path).map_err(|e| cannot(&e.error))?;
        Ok(())
    }

    /// A new trace of the folder, made for writing where nothing is.
    pub fn record(&self, relative: &str) -> Result<std::fs::File, String> {
        let path = self.place(relative, Access::Record)?;
        open_options()
            .write(true)
            .create_new(true)
            .open(&path)
            .map_err(|e| format!("cannot write the trace {}: {e}", shown(relative)))
    }
}

/// Why `relative` is no name the station takes, if it is not: it must be a plain
/// relative path, `name/name/...`, each part a name as the list shows it.
pub fn refused_name(relative: &str) -> Option<&'static str> {
    if relative.is_empty() {
        return Some("is empty: name a file as the list shows it");
    }
    if relative.len() > MAX_NAME_BYTES {
        return Some("is longer than any name the station takes");
    }
    if relative.chars().any(char::is_control) {
        return Some("holds a control character: name a file as the list shows it");
    }
    if relative.contains('\\') {
        return Some("holds a backslash: parts of a path are separated by `/`");
    }
    if percent_escaped(relative) {
        return Some("is still percent-encoded (`%2e`, `%2f`, ...): send the name as the list shows it, encoded once");
    }
    for part in relative.split('/') {
        match part {
            "" | "." | ".." => {
                return Some("is not a path inside the station's folder: name a file as the list shows it, without `..` or a leading `/`")
            }
            hidden if hidden.starts_with('.') => {
                return Some("is hidden (a part of it starts with `.`): the station opens no hidden file or folder")
            }
            _ => {}
        }
    }
    None
}

/// Whether `text` holds a `%` and two hex digits: a name decoded once by the server
/// that still holds an escape was encoded twice, or is meant to be read otherwise than
/// it is written.
fn percent_escaped(text: &str) -> bool {
    text.as_bytes()
        .windows(3)
        .any(|w| w[0] == b'%' && w[1].is_ascii_hexdigit() && w[2].is_ascii_hexdigit())
}

/// How a file is opened: never through a link at its last part (`O_NOFOLLOW`), so a
/// link put there after [`Folder::place`] looked is refused, not followed.
fn open_options() -> std::fs::OpenOptions {
    let mut options = std::fs::OpenOptions::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NOFOLLOW);
    }
    options
}

#[cfg(unix)]
fn new_file_permissions(file: &std::fs::File) -> std::io::Result<()> {
    use std::os::unix::fs::PermissionsExt;
    file.set_permissions(std::fs::Permissions::from_mode(0o644))
}

/// Elsewhere a new file's permissions are only whether it is read-only, which it is not.
#[cfg(not(unix))]
fn new_file_permissions(_file: &std::fs::File) -> std::io::Result<()> {
    Ok(())
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Mission,
    World,
    /// A recorded trace: read (replayed, reported), never saved.
    Trace,
}

impl FileKind {
    /// As a message names it.
    pub fn noun(self) -> &'static str {
        match self {
            FileKind::Mission => "mission",
            FileKind::World => "world",
            FileKind::Trace => "trace",
        }
    }

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
        // Names the station refuses are not listed either.
        std::fs::write(dir.join(".hidden.mission"), "").unwrap();
        std::fs::write(dir.join("100%25.mission"), "").unwrap();
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
