//! Checking a mission as the page edits it: every diagnostic with its line, code and
//! help (as `aviary check --format json` gives them), the energy and time plan (as
//! `aviary check --plan`), the mission's block tree and the world's map. The same
//! front end and pre-flight analyses as `aviary check`; the texts are the page's, which
//! may not be saved yet, and the files they `USE` come from the disk.

use std::path::{Path, PathBuf};

use aviary_check::{LoadError, SourceProvider};
use aviary_diagnostics::{render_json, Diagnostic, SourceMap};
use serde::Serialize;
use serde_json::Value;

use crate::tree;

/// A text as the page sends it: the file it is (for `USE` and for messages) and what the
/// editor holds.
#[derive(Debug, Clone, serde::Deserialize)]
pub struct Text {
    pub path: String,
    pub text: String,
}

/// The command line's provider for the page's texts, which are named relative to the
/// station's folder: a `USE` (or a world's import) is read beside the file of the folder
/// that says it, not beside a name taken from the station's working directory, and a file
/// read is named back relative to the folder, as the page names files.
pub struct InFolder {
    pub root: PathBuf,
    pub files: Box<dyn SourceProvider + Send>,
}

impl InFolder {
    fn full(&self, name: &str) -> String {
        self.root.join(name).to_string_lossy().into_owned()
    }
}

impl SourceProvider for InFolder {
    fn load(&self, from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        let (name, bytes) = self.files.load(&self.full(from), path)?;
        let shown =
            Path::new(&name).strip_prefix(&self.root).map(|p| p.to_string_lossy().into_owned());
        Ok((shown.unwrap_or(name), bytes))
    }

    fn world_file(&self, world: &str, path: &str) -> Result<Vec<u8>, LoadError> {
        self.files.world_file(&self.full(world), path)
    }
}

/// What the page shows of a check.
pub struct Report {
    /// Whether the mission may fly: no error, a world, and a MISSION.
    pub flyable: bool,
    pub json: Value,
}

/// The check's document (`POST /api/check`), as the page reads it.
#[derive(Serialize)]
pub struct CheckResult<'m> {
    /// Whether the mission may fly: no error, a world, and a MISSION.
    pub flyable: bool,
    pub errors: usize,
    /// Errors, warnings and notes counted as `aviary check` counts them.
    pub summary: String,
    pub diagnostics: Vec<Shown>,
    /// The energy and time plan, when the mission may fly (as `aviary check --plan`).
    pub plan: Option<aviary_verify::Plan>,
    /// The block tree, when the mission may fly.
    pub tree: Option<tree::TreeNode<'m>>,
    /// The world's map, when a world was given.
    pub map: Option<WorldMap<'m>>,
}

/// A diagnostic as `aviary check --format json` gives it, with the text rendering too.
#[derive(Debug, Serialize)]
pub struct Shown {
    #[serde(flatten)]
    pub diagnostic: aviary_diagnostics::JsonDiagnostic,
    pub text: String,
}

/// Checks `mission` against `world` (none: as `aviary check` with no world file, a note
/// says what was not checked), reading what it `USE`s through `files`.
pub fn check(mission: &Text, world: Option<&Text>, files: &dyn SourceProvider) -> Report {
    let mut sources = SourceMap::new();
    let mut checked = aviary_check::check_sources(
        &mut sources,
        (&mission.path, mission.text.as_bytes()),
        world.map(|w| (w.path.as_str(), w.text.as_bytes())),
        files,
    );
    // As `aviary check`: the checker's and the pre-flight analyses' diagnostics, ALLOW
    // applied, by the one function both call.
    let verdict = aviary_verify::verdict(&mut checked);
    let flyable = verdict.flyable();
    let diagnostics = verdict.diagnostics;
    let (compiled, plan) = match verdict.flight {
        Some((compiled, mut plan)) => {
            plan.locate_in(&sources);
            (Some(compiled), Some(plan))
        }
        None => (None, None),
    };
    let result = CheckResult {
        flyable,
        errors: diagnostics.iter().filter(|d| d.is_error()).count(),
        summary: aviary_diagnostics::summary_line(&diagnostics),
        diagnostics: diagnostics.iter().map(|d| rendered(&sources, d)).collect(),
        plan,
        tree: compiled.as_ref().map(|c| tree::typed(c, Some(&sources))),
        map: checked.world.as_ref().map(WorldMap::of),
    };
    Report { flyable, json: serde_json::to_value(&result).unwrap_or(Value::Null) }
}

/// A diagnostic as `aviary check --format json` gives it, with the text rendering too.
fn rendered(sources: &SourceMap, d: &Diagnostic) -> Shown {
    Shown {
        diagnostic: render_json(sources, d),
        text: aviary_diagnostics::render_text(sources, d, false),
    }
}

/// What the map shows of a world: the site, places, areas, lines (`lines`: name, points
/// `[x, y]`), no-fly zones (`no_fly`: name, polygon, `up_to`), homes and targets, in the
/// local frame (metres east and north of the origin).
#[derive(Debug, Serialize)]
pub struct WorldMap<'w> {
    pub site: &'w aviary_world::Site,
    /// The map's tiles (`tiles.rs`); null without.
    pub base: Option<crate::tiles::BaseMap>,
    pub places: &'w [aviary_world::Place],
    pub areas: &'w [aviary_world::Area],
    pub lines: Vec<MapLine<'w>>,
    pub no_fly: &'w [aviary_world::NoFly],
    pub drones: Vec<MapDrone<'w>>,
    pub targets: &'w [aviary_world::Target],
}

/// A line of the world, on the ground.
#[derive(Debug, Serialize)]
pub struct MapLine<'w> {
    pub name: &'w str,
    pub points: Vec<[f64; 2]>,
}

/// A drone of the world: its home, group and sensors.
#[derive(Debug, Serialize)]
pub struct MapDrone<'w> {
    pub name: &'w str,
    pub home: [f64; 3],
    pub group: Option<&'w str>,
    pub sensors: &'w [String],
}

impl<'w> WorldMap<'w> {
    pub fn of(world: &'w aviary_world::World) -> Self {
        WorldMap {
            site: &world.site,
            base: crate::tiles::base_map(world),
            places: &world.places,
            areas: &world.areas,
            lines: world
                .lines
                .iter()
                .map(|l| MapLine { name: &l.name, points: l.ground() })
                .collect(),
            no_fly: &world.no_fly,
            drones: world
                .drones
                .iter()
                .map(|d| MapDrone {
                    name: &d.name,
                    home: d.home,
                    group: d.group.as_deref(),
                    sensors: &d.sensors,
                })
                .collect(),
            targets: &world.targets,
        }
    }
}

/// The map of `world` as the page reads it ([`WorldMap`]).
pub fn map_of(world: &aviary_world::World) -> Value {
    serde_json::to_value(WorldMap::of(world)).unwrap_or(Value::Null)
}
