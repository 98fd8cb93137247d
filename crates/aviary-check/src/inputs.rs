//! The whole front end over raw bytes, as every caller needs it: a world file (if any),
//! then the mission. Pure: the caller reads the bytes and supplies USEd files.

use std::borrow::Cow;
use std::path::{Component, Path, PathBuf};

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
    /// The program's ALLOW lines, kept here since a caller may take the program away
    /// (`aviary_verify::preflight`): for [`crate::acknowledge`] once every diagnostic is in.
    pub allows: Vec<crate::Allow>,
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
) -> Checked {
    let world =
        world.map(|(name, bytes)| read_world(sources, name, Cow::Borrowed(bytes), provider));
    check_against(sources, (mission.0, Cow::Borrowed(mission.1)), world, provider)
}

/// A world file as [`read_world`] read it.
pub struct WorldRead {
    /// `None` when the file has an error.
    pub world: Option<World>,
    pub diagnostics: Vec<Diagnostic>,
}

/// The first half of [`check_sources`]: the world file `name`, into `sources`, with the
/// files its `[imports]` names from `provider` ([`SourceProvider::world_file`]). Bytes
/// handed over (`Cow::Owned`) become its text without a copy.
pub fn read_world(
    sources: &mut SourceMap,
    name: &str,
    bytes: Cow<'_, [u8]>,
    provider: &dyn SourceProvider,
) -> WorldRead {
    let (text, invalid) = decode(bytes);
    let id = sources.add(name, text);
    match invalid {
        Some(at) => {
            WorldRead { world: None, diagnostics: vec![aviary_syntax::invalid_utf8(id, at)] }
        }
        None => {
            let files = Imports { provider, world: name };
            let (world, diagnostics) = aviary_world::parse_world_with(id, sources.text(id), &files);
            WorldRead { world, diagnostics }
        }
    }
}

/// The files a world imports, from the mission's provider.
struct Imports<'a> {
    provider: &'a dyn SourceProvider,
    world: &'a str,
}

impl aviary_world::WorldFiles for Imports<'_> {
    fn read(&self, path: &str) -> Result<Vec<u8>, String> {
        self.provider.world_file(self.world, path).map_err(|e| match e {
            crate::LoadError::Unreadable(why) => why,
            crate::LoadError::Refused { why, help } => format!("{why} ({help})"),
        })
    }
}

/// The second half of [`check_sources`]: the mission `(name, bytes)` against the world
/// [`read_world`] read, if there is one. Its diagnostics come first in the result, as
/// in [`check_sources`]. (A caller that times the two halves, `aviary bench`, calls them
/// one after the other.)
pub fn check_against(
    sources: &mut SourceMap,
    mission: (&str, Cow<'_, [u8]>),
    world: Option<WorldRead>,
    provider: &dyn SourceProvider,
) -> Checked {
    let world_failed = world.as_ref().is_some_and(|w| w.world.is_none());
    let (parsed_world, mut diagnostics) = match world {
        Some(w) => (w.world, w.diagnostics),
        None => (None, Vec::new()),
    };
    let (text, invalid) = decode(mission.1);
    let root = sources.add(mission.0, text);
    let mut program = None;
    let mut allows = Vec::new();
    if let Some(at) = invalid {
        diagnostics.push(aviary_syntax::invalid_utf8(root, at));
    } else {
        let (p, d) = crate::check(sources, root, parsed_world.as_ref(), provider);
        allows = p.allows.clone();
        program = Some(p);
        // With a broken world, its own errors say why names went unchecked.
        diagnostics.extend(d.into_iter().filter(|d| !(world_failed && d.code == Code::NoWorld)));
    }
    Checked { program, world: parsed_world, diagnostics, allows }
}

fn decode(bytes: Cow<'_, [u8]>) -> (String, Option<usize>) {
    match bytes {
        Cow::Borrowed(bytes) => aviary_syntax::decode(bytes),
        Cow::Owned(bytes) => aviary_syntax::decode_owned(bytes),
    }
}

/// `a/./b/../c` becomes `a/c`, lexically, so that a file reached through two paths is
/// read once.
// A std enum, not a construct: every other component is kept.
#[allow(clippy::wildcard_enum_match_arm)]
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
