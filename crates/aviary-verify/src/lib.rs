//! Pre-flight analyses of a compiled mission (docs/LANGUAGE.md, section 22): conflicting commands
//! (W203, N303) and the energy and time plan (W204, `aviary check --plan`).
//!
//! Invariant: no IO. They run on the IR, after the checker found no error, so names are
//! resolved, units are SI and every statement keeps its origin for the report.

// A pure stage: no unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]
// A pass says what it does with every kind of node: a new statement, expression or IR
// node is then a compile error in each pass (with clippy), not one it silently skips. An
// enum that is no language construct may be matched with `_`, allowed where it is.
#![deny(clippy::wildcard_enum_match_arm)]

mod conflicts;
pub mod plan;
mod sites;

use aviary_check::Checked;
use aviary_diagnostics::Diagnostic;
use aviary_ir::Mission;
use aviary_world::World;

pub use plan::Plan;

pub struct Verification {
    pub diagnostics: Vec<Diagnostic>,
    pub plan: Plan,
}

/// Every pre-flight analysis of `mission` on `world`.
pub fn verify(mission: &Mission, world: &World) -> Verification {
    let conflicts = || {
        let mut out = Vec::new();
        conflicts::check_conflicts(mission, &mut out);
        out
    };
    let plan = || {
        let mut out = Vec::new();
        let plan = plan::estimate(mission, world, &mut out);
        (plan, out)
    };
    let (mut diagnostics, (plan, more)) = aviary_check::both(large(mission), conflicts, plan);
    diagnostics.extend(more);
    // Sorted, so the order in which the analyses ran does not show.
    aviary_diagnostics::sort(&mut diagnostics);
    Verification { diagnostics, plan }
}

/// From this many statements at the mission's top level and capabilities, the two analyses
/// run on two threads: below it, a thread costs more than it saves.
fn large(mission: &Mission) -> bool {
    mission.body.items.len() + mission.capabilities.len() >= 1000
}

/// Compiles and verifies what the checker accepted: `None` when it has errors, no world
/// or no MISSION. Takes the checked tree out of `checked` and drops it once compiled: the
/// analyses read only the IR, and on a long mission the tree is a large part of the peak
/// memory, whose fresh pages are much of the time `aviary check` takes; the analyses
/// reuse what it frees (docs/BENCHMARKS.md, "Pre-flight analyses at scale").
pub fn preflight(checked: &mut Checked) -> Option<(Mission, Verification)> {
    analyse(checked, Tree::Drop)
}

/// What happens to the checked tree while the mission is compiled and verified.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Tree {
    /// Dropped once compiled, for the memory (see [`preflight`]).
    Drop,
    /// Kept, for a caller that goes on reading it (an editor).
    Keep,
}

fn analyse(checked: &mut Checked, tree: Tree) -> Option<(Mission, Verification)> {
    if checked.has_errors() {
        return None;
    }
    let world = checked.world.as_ref()?;
    let mission = match tree {
        Tree::Keep => aviary_lower::compile(checked.program.as_ref()?, world),
        Tree::Drop => {
            let program = checked.program.take()?;
            aviary_lower::compile(&program, world)
        }
    }?;
    let verification = verify(&mission, world);
    Some((mission, verification))
}

/// What `aviary check` says of a checked mission, as every front end shows it (the CLI,
/// the station): the checker's diagnostics and the pre-flight analyses' in one list, the
/// `ALLOW` lines applied to it, and the compiled mission with its plan when it has them
/// (no error, a world, a MISSION).
pub struct Verdict {
    pub diagnostics: Vec<Diagnostic>,
    pub flight: Option<(Mission, Plan)>,
}

impl Verdict {
    /// Whether the mission may fly: the checker found no error, and it has a world and a
    /// MISSION (the pre-flight analyses warn; they do not refuse).
    pub fn flyable(&self) -> bool {
        self.flight.is_some()
    }
}

/// [`preflight`], then the one rule of `ALLOW` (`aviary_check::acknowledge`) over every
/// diagnostic. The world in `checked` is the one planned with: a caller that knows
/// better figures (a MAVLink vehicle's own) puts them there first.
pub fn verdict(checked: &mut Checked) -> Verdict {
    conclude(checked, Tree::Drop)
}

/// As [`verdict`], for a caller that goes on reading the checked tree (the language
/// server: hover, completion): `checked.program` is kept; its diagnostics are taken.
pub fn verdict_keeping_tree(checked: &mut Checked) -> Verdict {
    conclude(checked, Tree::Keep)
}

fn conclude(checked: &mut Checked, tree: Tree) -> Verdict {
    let verified = analyse(checked, tree);
    let mut diagnostics = std::mem::take(&mut checked.diagnostics);
    let preflight_ran = verified.is_some();
    let flight = verified.map(|(mission, v)| {
        diagnostics.extend(v.diagnostics);
        (mission, v.plan)
    });
    aviary_check::acknowledge(&checked.allows, &mut diagnostics, preflight_ran);
    Verdict { diagnostics, flight }
}
