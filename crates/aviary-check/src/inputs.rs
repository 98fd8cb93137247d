//! The whole front end over raw bytes, as every caller needs it: a world file (if any),
//! then the mission. Pure: the caller reads the bytes and supplies USEd files.

use std::path::{Component, Path, PathBuf};

use aviary_api::Descriptor;
use aviary_diagnostics::{Code, Diagnostic, SourceMap};
use aviary_world::World;

use crate::{Program, SourceProvider};

/// What the front end made of a mission and its world.
pub struct Checked {
    /// `None` when the mission file is not UTF-8.
    pub program: Option<Program>,
    /// `None` when there is no world file, or it has errors.
    pub world: Option<World>,
    pub diagnostics: Vec<Diagnostic>,
}

impl Checked {
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}

/// Checks the mission `(name, bytes)` against the world file `(name, bytes)`, if given.
pub fn check_sources(
    sources: &mut SourceMap,
    mission: (&str, &[u8]),
    world: Option<(&str, &[u8])>,
    provider: &dyn SourceProvider,
    api: &Descriptor,
) -> Checked {
    let mut diagnostics = Vec::new();
    let mut parsed_world = None;
    if let Some((name, bytes)) = world {
        let (text, invalid) = aviary_syntax::decode(bytes);
        let id = sources.add(name, text);
        match invalid {
            Some(at) => diagnostics.push(aviary_syntax::invalid_utf8(id, at)),
            None => {
                let (w, d) = aviary_world::parse_world(id, sources.text(id));
                parsed_world = w;
                diagnostics.extend(d);
            }
        }
    }
    let world_failed = world.is_some() && parsed_world.is_none();
    let (text, invalid) = aviary_syntax::decode(mission.1);
    let root = sources.add(mission.0, text);
    let mut program = None;
    if let Some(at) = invalid {
        diagnostics.push(aviary_syntax::invalid_utf8(root, at));
    } else {
        let (p, d) = crate::check(sources, root, parsed_world.as_ref(), provider, api);
        program = Some(p);
        // With a broken world, its own errors say why names went unchecked.
        diagnostics.extend(d.into_iter().filter(|d| !(world_failed && d.code == Code::NoWorld)));
    }
    Checked { program, world: parsed_world, diagnostics }
}

/// `a/./b/../c` becomes `a/c`, lexically, so that a file reached through two paths is
/// read once.
pub fn normalize_path(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir
                if matches!(out.components().next_back(), Some(Component::Normal(_))) =>
            {
                out.pop();
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}
