//! Reading a mission's files: the root, what it `USE`s (transitively, each once), and
//! the standard library, then the table of capabilities by name.

use std::collections::BTreeMap;

use aviary_diagnostics::{Code, Diagnostic, FileId, SourceMap};
use aviary_syntax::ast::Item;

use crate::uses::{self, LoadError};
use crate::{DefRef, Program};

/// The standard capability library, compiled into the binary.
pub const STD_SOURCE: &str = include_str!("../../../std/standard.mission");
pub const STD_NAME: &str = "<std>/standard.mission";

/// Supplies the files a mission `USE`s.
pub trait SourceProvider {
    /// The file that `path`, written in a USE inside the file named `from`, refers to:
    /// its name (used to read it only once) and its bytes, or why it cannot be read or
    /// may not be (`crate::uses`). Only paths that pass [`uses::check_written`] are asked
    /// for.
    fn load(&self, from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError>;

    /// The file `path` that the world file named `world` imports (`[imports]` in
    /// docs/WORLD.md: GeoJSON beside it): its bytes, or why not. By default none is
    /// served, as by [`NoFiles`].
    fn world_file(&self, world: &str, path: &str) -> Result<Vec<u8>, LoadError> {
        let _ = (world, path);
        Err(LoadError::Unreadable("the world file is read here without the files beside it".into()))
    }
}

/// The provider of a mission that stands alone, held in memory (tests, the benchmarks,
/// fuzzing): it serves no file, so every `USE` is unreadable (E113). The one such
/// provider; the CLI's `DiskProvider` is the one that reads the disk.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoFiles;

impl SourceProvider for NoFiles {
    fn load(&self, _from: &str, _path: &str) -> Result<(String, Vec<u8>), LoadError> {
        Err(LoadError::Unreadable("no files are read here".into()))
    }
}

pub(crate) fn load(
    sources: &mut SourceMap,
    root: FileId,
    provider: &dyn SourceProvider,
    diagnostics: &mut Vec<Diagnostic>,
) -> Program {
    let std_id = sources.add(STD_NAME, STD_SOURCE);
    let std_parse = aviary_syntax::parse(std_id, STD_SOURCE);
    diagnostics.extend(std_parse.diagnostics);
    let mut files = vec![(std_id, std_parse.tree)];

    let root_parse = aviary_syntax::parse(root, sources.text(root));
    diagnostics.extend(root_parse.diagnostics);
    let mut queue = vec![(root, root_parse.tree)];
    let mut seen = vec![sources.name(root).to_string()];
    let mut unreadable = Vec::new();
    while let Some((id, tree)) = queue.pop() {
        for item in &tree.items {
            let Item::Use(u) = item else { continue };
            let from = sources.name(id).to_string();
            match uses::check_written(&u.path).and_then(|()| provider.load(&from, &u.path)) {
                Ok((name, _)) if seen.contains(&name) => {}
                Ok((name, bytes)) => {
                    seen.push(name.clone());
                    let (text, invalid_at) = aviary_syntax::decode(&bytes);
                    let file = sources.add(name, text);
                    let tree = match invalid_at {
                        Some(at) => {
                            diagnostics.push(aviary_syntax::invalid_utf8(file, at));
                            aviary_syntax::ast::SourceFile::default()
                        }
                        None => {
                            let parse = aviary_syntax::parse(file, sources.text(file));
                            diagnostics.extend(parse.diagnostics);
                            parse.tree
                        }
                    };
                    queue.push((file, tree));
                }
                Err(LoadError::Unreadable(why)) => {
                    unreadable.push(u.path.clone());
                    diagnostics.push(
                        Diagnostic::new(
                            Code::UseNotFound,
                            id,
                            u.path_span,
                            format!("cannot read `{}`: {why}", u.path),
                        )
                        .with_help("the path is relative to the file that holds the USE"),
                    );
                }
                // Said without a word of what the file holds.
                Err(LoadError::Refused { why, help }) => {
                    unreadable.push(u.path.clone());
                    let message = if u.path.trim().is_empty() {
                        why
                    } else {
                        format!("this USE of `{}` is refused: {why}", u.path)
                    };
                    diagnostics.push(
                        Diagnostic::new(Code::UseRefused, id, u.path_span, message)
                            .label("not read")
                            .with_help(help),
                    );
                }
            }
        }
        files.push((id, tree));
    }
    let api_functions = crate::resolve::ApiFunctions::of(&files);
    let mut program = Program {
        files,
        mission: None,
        param_kinds: Default::default(),
        param_origins: Default::default(),
        signal_values: BTreeMap::new(),
        unreadable,
        allows: Vec::new(),
        index: Default::default(),
        api_functions,
    };
    index_definitions(&mut program, std_id, diagnostics);
    program
}

fn index_definitions(program: &mut Program, std_id: FileId, diagnostics: &mut Vec<Diagnostic>) {
    // By hash and borrowed: a mission may define tens of thousands of capabilities.
    let mut user: foldhash::HashMap<&str, (DefRef, aviary_diagnostics::Span)> =
        foldhash::HashMap::default();
    let mut mission: Option<(DefRef, aviary_diagnostics::Span)> = None;
    for (file, tree) in &program.files {
        for (index, item) in tree.items.iter().enumerate() {
            let r = DefRef { file: *file, index };
            match item {
                Item::Capability(c) if *file == std_id => {
                    program.index.insert(c.name.name.as_str().into(), r);
                }
                Item::Capability(c) => {
                    if let Some((first, span)) = user.get(c.name.name.as_str()) {
                        diagnostics.push(
                            Diagnostic::new(
                                Code::DuplicateCapability,
                                *file,
                                c.name.span,
                                format!("capability `{}` is defined twice", c.name.name),
                            )
                            .also(first.file, *span, "first defined here")
                            .with_help("rename one of them, or remove one"),
                        );
                        continue;
                    }
                    user.insert(&c.name.name, (r, c.name.span));
                    program.index.insert(c.name.name.as_str().into(), r);
                }
                Item::Mission(m) => {
                    if let Some((first, span)) = mission {
                        diagnostics.push(
                            Diagnostic::new(Code::DuplicateMission, *file, m.name.span, format!("a second MISSION, `{}`", m.name.name))
                                .also(first.file, span, "the first MISSION")
                                .with_help("a mission and the files it USEs hold one MISSION in all; turn the other into a capability"),
                        );
                        continue;
                    }
                    mission = Some((r, m.name.span));
                }
                Item::Use(_) => {}
            }
        }
    }
    program.mission = mission.map(|(r, _)| r);
}

#[cfg(test)]
mod tests {

    use aviary_diagnostics::{Code, SourceMap};

    use super::NoFiles;

    #[test]
    fn no_files_makes_every_use_unreadable() {
        let mut sources = SourceMap::new();
        let checked = crate::check_sources(
            &mut sources,
            ("m.mission", b"USE \"lib/beacons.mission\"\nMISSION M:\n    SIGNAL Go\n".as_slice()),
            None,
            &NoFiles,
        );
        let unreadable: Vec<(Code, &str)> = checked
            .diagnostics
            .iter()
            .filter(|d| d.code == Code::UseNotFound)
            .map(|d| (d.code, d.message.as_str()))
            .collect();
        assert_eq!(
            unreadable,
            [(Code::UseNotFound, "cannot read `lib/beacons.mission`: no files are read here")]
        );
        assert_eq!(checked.program.expect("a program").unreadable, ["lib/beacons.mission"]);
    }
}
