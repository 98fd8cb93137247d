//! Checks a mission before any drone leaves the ground: loads `USE`d files and the
//! standard library, resolves names against the world, and checks arguments, kinds,
//! tags, API calls and signals. Every problem becomes a diagnostic with a stable code.
//!
//! Invariant: no IO. Files come through a [`SourceProvider`] that the caller supplies
//! (the CLI reads the disk; a mission that stands alone is checked with [`NoFiles`]), as
//! in typst's `World`.

// A pure stage: no unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]
// A pass says what it does with every kind of node: a new statement, expression or IR
// node is then a compile error in each pass (with clippy), not one it silently skips. An
// enum that is no language construct may be matched with `_`, allowed where it is.
#![deny(clippy::wildcard_enum_match_arm)]

mod actors;
mod allow;
mod chains;
mod endurance;
mod env;
mod geofence;
mod infer;
mod inputs;
mod load;
mod no_fly;
mod recursion;
mod resolve;
mod signal_cycles;
mod signal_values;
mod signals;
mod unheard;
pub mod uses;
mod walk;

use std::collections::BTreeMap;

use aviary_api::{Kind, Signature};
use aviary_diagnostics::{Diagnostic, FileId, SourceMap};
use aviary_syntax::ast::{ApiCall, Capability, Item, Mission, SourceFile};
use aviary_world::World;

pub use allow::{acknowledge, Allow};
pub use env::{bind_args, ArgBinding, BindProblem};
pub use infer::KindOrigin;
pub use inputs::{check_against, check_sources, normalize_path, read_world, Checked, WorldRead};
pub use load::{NoFiles, SourceProvider, STD_NAME, STD_SOURCE};
pub use uses::LoadError;

/// Where a definition lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DefRef {
    pub file: FileId,
    pub index: usize,
}

/// Facts per capability, by name. By hash: every pass asks at every call, and a mission may
/// have tens of thousands of capabilities.
pub type ByName<T> = foldhash::HashMap<String, T>;

/// A mission with everything it refers to, parsed and resolved.
pub struct Program {
    /// Every file read, the standard library first, in load order.
    pub files: Vec<(FileId, SourceFile)>,
    pub mission: Option<DefRef>,
    /// The kind of each `WITH` parameter of each capability, where it could be inferred.
    pub param_kinds: ByName<Vec<Option<Kind>>>,
    /// Where each of those kinds was fixed: the chain an E107 report shows.
    pub param_origins: ByName<Vec<Option<KindOrigin>>>,
    /// The values each signal carries, by name, with each one's kind where it is known
    /// (see `signal_values.rs`): what an operator's signal is checked against.
    pub signal_values: BTreeMap<String, Vec<Option<Kind>>>,
    /// The ALLOW lines that can apply, for [`acknowledge`] (empty when a file has a
    /// syntax error).
    pub allows: Vec<Allow>,
    /// The paths of `USE`s that could not be read (reported as E113).
    pub unreadable: Vec<String>,
    /// The capability each name means, after user definitions override the library. By
    /// hash: every pass looks names up, and a mission may have tens of thousands of
    /// capabilities, where a tree would compare strings all the way down;
    /// [`Program::capability_names`] gives them in order.
    index: foldhash::HashMap<Box<str>, DefRef>,
    /// The function each API call names, resolved once as the files are loaded
    /// (`resolve.rs`); read through [`Program::api_function`].
    api_functions: resolve::ApiFunctions,
}

impl Program {
    fn file(&self, id: FileId) -> Option<&SourceFile> {
        self.files.iter().find(|(f, _)| *f == id).map(|(_, t)| t)
    }
    pub fn capability(&self, name: &str) -> Option<&Capability> {
        self.capability_in(name).map(|(_, c)| c)
    }
    /// The capability a name means, with the file that holds it: one lookup for a walk
    /// that goes into its body (whose spans and calls are that file's).
    pub fn capability_in(&self, name: &str) -> Option<(FileId, &Capability)> {
        let r = self.index.get(name)?;
        match self.file(r.file)?.items.get(r.index)? {
            Item::Capability(c) => Some((r.file, c)),
            Item::Use(_) | Item::Mission(_) => None,
        }
    }
    /// The file that holds the MISSION, and its tree.
    pub fn mission_file(&self) -> Option<(FileId, &SourceFile)> {
        let r = self.mission?;
        Some((r.file, self.file(r.file)?))
    }
    pub fn mission(&self) -> Option<&Mission> {
        let r = self.mission?;
        match self.file(r.file)?.items.get(r.index)? {
            Item::Mission(m) => Some(m),
            Item::Use(_) | Item::Capability(_) => None,
        }
    }
    /// The capabilities that run: user definitions, and library ones no user one replaces.
    pub fn active_capabilities(&self) -> impl Iterator<Item = (FileId, &Capability)> {
        self.files.iter().flat_map(move |(file, tree)| {
            tree.items.iter().filter_map(move |item| match item {
                Item::Capability(c) if self.is_active(*file, c) => Some((*file, c)),
                Item::Use(_) | Item::Capability(_) | Item::Mission(_) => None,
            })
        })
    }
    /// The bodies of `item` that the checks walk: a mission's, or an active capability's
    /// PERFORM sections and exception handlers (`env::capability_bodies`); `None` for any
    /// other item, or a capability its name does not mean.
    pub fn walked_bodies<'a>(
        &self,
        file: FileId,
        item: &'a Item,
    ) -> Option<Vec<&'a aviary_syntax::ast::Body>> {
        match item {
            Item::Mission(m) => Some(vec![&m.body]),
            Item::Capability(c) if self.is_active(file, c) => Some(env::capability_bodies(c)),
            Item::Use(_) | Item::Capability(_) => None,
        }
    }
    /// Whether this definition is the one its name means (not overridden, not a duplicate).
    pub fn is_active(&self, file: FileId, c: &Capability) -> bool {
        self.index.get(c.name.name.as_str()).map(|r| r.file) == Some(file)
    }
    /// The names of the capabilities, in name order.
    pub fn capability_names(&self) -> Vec<&str> {
        let mut names: Vec<&str> = self.index.keys().map(|n| &**n).collect();
        names.sort_unstable();
        names
    }
    /// Each name that means a capability, with the file that holds it and the capability
    /// it means, in no order.
    pub fn capabilities(&self) -> impl Iterator<Item = (&str, FileId, &Capability)> {
        self.index.iter().filter_map(|(name, r)| match self.file(r.file)?.items.get(r.index)? {
            Item::Capability(c) => Some((&**name, r.file, c)),
            Item::Use(_) | Item::Mission(_) => None,
        })
    }
    /// How many names mean a capability.
    pub fn capability_count(&self) -> usize {
        self.index.len()
    }
    pub fn capability_file(&self, name: &str) -> Option<FileId> {
        self.index.get(name).map(|r| r.file)
    }
    /// The middle-layer function that `call`, in `file`, names: resolved once, when the
    /// program was loaded, for every pass and the lowering; `None` for a name the middle
    /// layer does not have (which the checker reports, E109).
    pub fn api_function(&self, file: FileId, call: &ApiCall) -> Option<&'static Signature> {
        self.api_functions.get(file, call)
    }
}

/// From this size of mission text, the checker's passes run on two threads: below it, a
/// thread costs more than it saves.
const IN_PARALLEL_FROM: usize = 64 * 1024;

/// What `a` and `b` give; with `parallel`, `b` runs on a second thread meanwhile. For
/// passes that only read what they check, and write what they find to their own list.
pub fn both<A: Send, B: Send>(
    parallel: bool,
    a: impl FnOnce() -> A + Send,
    b: impl FnOnce() -> B + Send,
) -> (A, B) {
    if !parallel {
        return (a(), b());
    }
    // Kept here rather than moved into the thread, so that `b` can still run here if no
    // thread can be made.
    let b = std::sync::Mutex::new(Some(b));
    let take = || b.lock().ok().and_then(|mut b| b.take());
    std::thread::scope(|s| {
        let other =
            std::thread::Builder::new().stack_size(STACK).spawn_scoped(s, || take().map(|b| b()));
        let first = a();
        let second = match other.map(|o| o.join()) {
            Ok(Ok(Some(second))) => second,
            Ok(Err(panicked)) => std::panic::resume_unwind(panicked),
            // No thread could be made: `b` runs here.
            _ => match take() {
                Some(b) => b(),
                None => unreachable!("`b` ran on the thread that failed to start"),
            },
        };
        (first, second)
    })
}

/// The stack the front end and the analyses need: they follow capability calls by
/// recursion, and a mission may chain tens of thousands of capabilities. A thread that
/// runs them (the command's, or the second of [`both`]) reserves this much; it is address
/// space, used only as deep as a walk goes.
pub const STACK: usize = 1 << 30;

/// Checks the mission file `root` (already in `sources`): its program, and every problem.
pub fn check(
    sources: &mut SourceMap,
    root: FileId,
    world: Option<&World>,
    provider: &dyn SourceProvider,
) -> (Program, Vec<Diagnostic>) {
    let mut diagnostics = Vec::new();
    let mut program = load::load(sources, root, provider, &mut diagnostics);
    // Checks on a file that did not parse would only repeat its syntax errors.
    let syntax_ok =
        !diagnostics.iter().any(|d: &Diagnostic| d.is_error() && d.code.as_str().starts_with("E0"));
    (program.param_kinds, program.param_origins) = infer::parameter_kinds(&program);
    program.signal_values = signal_values::signal_values(&program);
    if syntax_ok {
        let program = &program;
        let names = || {
            let mut out = Vec::new();
            walk::check_program(program, world, root, &mut out);
            signals::check_signals(program, &mut out);
            signal_cycles::check_signal_cycles(program, &mut out);
            out
        };
        let walks = || {
            let mut out = Vec::new();
            // The drones each of the world's names stands for: one table for the walks
            // that follow drones, made when one first asks.
            let actors = world.map(actors::Actors::new);
            if let (Some(world), Some(actors)) = (world, &actors) {
                geofence::check_geofence(program, world, actors, &mut out);
                endurance::check_endurance(program, world, actors, &mut out);
            }
            chains::check_chains(program, &mut out);
            recursion::check_recursion(program, &mut out);
            unheard::check_unheard(program, world, actors.as_ref(), &mut out);
            out
        };
        let large = sources.text(root).len() >= IN_PARALLEL_FROM;
        let (found, more) = both(large, names, walks);
        diagnostics.extend(found);
        diagnostics.extend(more);
    }
    if syntax_ok {
        program.allows = allow::collect(&program, &mut diagnostics);
    }
    // Sorted, so the order in which the passes ran does not show.
    aviary_diagnostics::sort(&mut diagnostics);
    diagnostics.dedup();
    (program, diagnostics)
}

#[cfg(test)]
mod tests {
    use super::both;

    /// As deep as a walk of a long capability chain: far past a default thread's 2 MiB.
    fn depth(n: u64) -> u64 {
        if n == 0 {
            return 0;
        }
        let frame = std::hint::black_box([n; 16]);
        1 + depth(n - 1) + frame[0] - n
    }

    #[test]
    fn both_gives_what_each_gives_on_one_thread_or_two() {
        let one = both(false, || (1..=100u32).sum::<u32>(), || "b".repeat(3));
        let two = both(true, || (1..=100u32).sum::<u32>(), || "b".repeat(3));
        assert_eq!(one, (5050, "bbb".to_string()));
        assert_eq!(one, two);
    }

    #[test]
    fn the_second_thread_has_the_stack_a_deep_walk_needs() {
        let (a, b) = both(true, || depth(10), || depth(200_000));
        assert_eq!((a, b), (10, 200_000));
    }
}
