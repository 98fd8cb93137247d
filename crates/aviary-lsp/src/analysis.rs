//! One open mission checked as `aviary check` checks it: its world file beside it and
//! the files it `USE`s, read from the open documents first, then, when it checks, the
//! pre-flight analyses (W2xx). A world file open with no open mission is read alone.

use std::path::{Path, PathBuf};

use aviary_check::{Program, SourceProvider};
use aviary_diagnostics::{Diagnostic, FileId, SourceMap};
use aviary_world::World;

use crate::index::{self, Occurrence};
use crate::overlay::{roots_of, Docs, Overlay};
use crate::Config;

pub struct Analysis {
    pub sources: SourceMap,
    pub world_file: Option<FileId>,
    /// The analysed document's file (a mission, or the world file read alone).
    pub root: FileId,
    pub program: Option<Program>,
    pub world: Option<World>,
    pub diagnostics: Vec<Diagnostic>,
    pub occurrences: Vec<Occurrence>,
}

impl Analysis {
    /// Every file the analysis read.
    pub fn files(&self) -> Vec<FileId> {
        let mut ids: Vec<FileId> = self.world_file.into_iter().chain([self.root]).collect();
        if let Some(p) = &self.program {
            ids.extend(p.files.iter().map(|(f, _)| *f));
        }
        ids.sort_unstable();
        ids.dedup();
        ids
    }

    /// The file named `key`, if the analysis read it.
    pub fn file(&self, key: &str) -> Option<FileId> {
        self.files().into_iter().find(|&f| self.sources.name(f) == key)
    }

    pub fn tree(&self, file: FileId) -> Option<&aviary_syntax::ast::SourceFile> {
        self.program.as_ref()?.files.iter().find(|(f, _)| *f == file).map(|(_, t)| t)
    }
}

/// `NAME.world.toml` beside the mission `NAME.mission`: open, or on disk when the disk
/// may be read for the mission (`on_disk`).
pub fn world_key(mission: &str, docs: &Docs, on_disk: bool) -> Option<String> {
    let path = Path::new(mission);
    if !path.is_absolute() {
        return None;
    }
    let stem = path.file_stem()?.to_string_lossy().into_owned();
    let candidate = path.with_file_name(format!("{stem}.world.toml"));
    let key = candidate.to_string_lossy().into_owned();
    (docs.contains_key(&key) || (on_disk && candidate.is_file())).then_some(key)
}

pub fn is_world(key: &str) -> bool {
    key.ends_with(".world.toml")
}

/// Checks the open document `key` as the root of a mission.
pub fn mission(key: &str, docs: &Docs, config: &Config) -> Analysis {
    let text = docs.get(key).map(|d| d.text.as_str()).unwrap_or("");
    let path = Path::new(key);
    // The disk is read for a mission only where the caller's provider allows it (the
    // station's: its folder); elsewhere only open documents are read, the world beside
    // the mission included.
    let disk: Option<Box<dyn SourceProvider>> = if path.is_absolute() {
        (config.disk)(path).map_err(|why| eprintln!("aviary lsp: {why}")).ok()
    } else {
        None
    };
    let world = world_key(key, docs, disk.is_some()).and_then(|w| {
        let bytes = match docs.get(&w) {
            Some(doc) => Some(doc.text.as_bytes().to_vec()),
            None => std::fs::read(&w).ok(),
        };
        bytes.map(|b| (w, b))
    });
    let disk: Box<dyn SourceProvider> = disk.unwrap_or_else(|| Box::new(aviary_check::NoFiles));
    let roots: Vec<PathBuf> =
        if path.is_absolute() { roots_of(path, &config.use_roots) } else { Vec::new() };
    let overlay = Overlay { open: docs, roots, disk: &*disk };
    let mut sources = SourceMap::new();
    let world_in = world.as_ref().map(|(n, b)| (n.as_str(), b.as_slice()));
    let mut checked =
        aviary_check::check_sources(&mut sources, (key, text.as_bytes()), world_in, &overlay);
    let world_file = world.is_some().then_some(FileId(0));
    let root = FileId(u32::from(world.is_some()));
    // As `aviary check` and the station say it, the tree kept for hover and completion.
    let diagnostics = aviary_verify::verdict_keeping_tree(&mut checked).diagnostics;
    let program = checked.program;
    let world = checked.world;
    let occurrences = match &program {
        Some(p) => {
            let files: Vec<_> = p.files.iter().map(|(f, t)| (*f, t)).collect();
            index::index(&files, world_file.zip(world.as_ref()))
        }
        None => Vec::new(),
    };
    Analysis { sources, world_file, root, program, world, diagnostics, occurrences }
}

/// The world file `key` read alone.
pub fn world_alone(key: &str, docs: &Docs, config: &Config) -> Analysis {
    let text = docs.get(key).map(|d| d.text.clone()).unwrap_or_default();
    let mut sources = SourceMap::new();
    // The files its `[imports]` names, from the disk beside it.
    let path = Path::new(key);
    let disk: Box<dyn SourceProvider> = match path.is_absolute().then(|| (config.disk)(path)) {
        Some(Ok(disk)) => disk,
        _ => Box::new(aviary_check::NoFiles),
    };
    let read = aviary_check::read_world(
        &mut sources,
        key,
        std::borrow::Cow::Owned(text.into_bytes()),
        &*disk,
    );
    let occurrences = index::index(&[], read.world.as_ref().map(|w| (FileId(0), w)));
    Analysis {
        sources,
        world_file: Some(FileId(0)),
        root: FileId(0),
        program: None,
        world: read.world,
        diagnostics: read.diagnostics,
        occurrences,
    }
}
