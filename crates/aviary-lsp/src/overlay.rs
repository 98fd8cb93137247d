//! The files a mission reads, as the editor has them: an open document's text first (even
//! unsaved), else the disk, through the provider the caller gives (the CLI's
//! `DiskProvider`, which keeps the rules of what a `USE` may read).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use aviary_check::uses::{is_mission_name, not_a_mission, within_roots, OUTSIDE_HELP};
use aviary_check::{LoadError, SourceProvider};

/// An open document.
#[derive(Clone)]
pub struct Doc {
    pub uri: lsp_types::Uri,
    pub text: String,
    pub version: i32,
}

/// The open documents by key (`crate::uri::key`).
pub type Docs = BTreeMap<String, Doc>;

pub struct Overlay<'a> {
    pub open: &'a Docs,
    /// The folders a `USE` may read from, resolved: the mission's own and the
    /// `--use-root`s.
    pub roots: Vec<PathBuf>,
    pub disk: &'a dyn SourceProvider,
}

impl SourceProvider for Overlay<'_> {
    fn load(&self, from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        let base = Path::new(from).parent().unwrap_or(Path::new(""));
        let full = aviary_check::normalize_path(&base.join(path));
        let name = full.to_string_lossy().into_owned();
        let Some(doc) = self.open.get(&name) else {
            return self.disk.load(from, path);
        };
        let resolved = resolve(&full);
        if !within_roots(&resolved, &self.roots) {
            let shown: Vec<String> = self.roots.iter().map(|r| r.display().to_string()).collect();
            return Err(LoadError::Refused {
                why: format!("{name} is outside the folders a USE may read, {}", shown.join(", ")),
                help: OUTSIDE_HELP.into(),
            });
        }
        if !is_mission_name(&resolved) {
            return Err(not_a_mission());
        }
        Ok((name, doc.text.as_bytes().to_vec()))
    }

    /// A world's imports are read from the disk, as saved (they are not missions, which
    /// an editor has open).
    fn world_file(&self, world: &str, path: &str) -> Result<Vec<u8>, LoadError> {
        self.disk.world_file(world, path)
    }
}

/// A path without symlinks: the file's own when it exists, else its folder's (an open
/// document not saved yet) with its name.
pub fn resolve(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    match (path.parent().map(std::fs::canonicalize), path.file_name()) {
        (Some(Ok(folder)), Some(name)) => folder.join(name),
        _ => path.to_path_buf(),
    }
}

/// The folders a mission at `mission` may `USE` from: its own and `use_roots`.
pub fn roots_of(mission: &Path, use_roots: &[PathBuf]) -> Vec<PathBuf> {
    let own = mission.parent().map(resolve);
    own.into_iter().chain(use_roots.iter().cloned()).collect()
}
