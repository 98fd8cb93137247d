//! Checking a mission as the page edits it: every diagnostic with its line, code and
//! help (as `aviary check --format json` gives them), the energy and time plan (as
//! `aviary check --plan`), the mission's block tree and the world's map. The same
//! front end and pre-flight analyses as `aviary check`; the texts are the page's, which
//! may not be saved yet, and the files they `USE` come from the disk.

use std::path::{Path, PathBuf};

use aviary_check::{LoadError, SourceProvider};
use aviary_diagnostics::{render_json, Diagnostic, SourceMap};
use serde_json::{json, Value};

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
    let map = checked.world.as_ref().map(map_of);
    let verified = aviary_verify::preflight(&mut checked);
    let mut diagnostics = checked.diagnostics;
    let mut plan = Value::Null;
    let mut tree = Value::Null;
    let flyable = verified.is_some();
    if let Some((compiled, v)) = verified {
        diagnostics.extend(v.diagnostics);
        let mut v_plan = v.plan;
        v_plan.locate_in(&sources);
        plan = serde_json::to_value(&v_plan).unwrap_or(Value::Null);
        tree = tree::of(&compiled, Some(&sources));
    }
    aviary_check::acknowledge(&checked.allows, &mut diagnostics, flyable);
    let errors = diagnostics.iter().filter(|d| d.is_error()).count();
    let shown: Vec<Value> = diagnostics.iter().map(|d| rendered(&sources, d)).collect();
    Report {
        flyable,
        json: json!({
            "flyable": flyable,
            "errors": errors,
            // Errors, warnings and notes counted as `aviary check` counts them.
            "summary": aviary_diagnostics::summary_line(&diagnostics),
            "diagnostics": shown,
            "plan": plan,
            "tree": tree,
            "map": map,
        }),
    }
}

/// A diagnostic as `aviary check --format json` gives it, with the text rendering too.
fn rendered(sources: &SourceMap, d: &Diagnostic) -> Value {
    let mut value = render_json(sources, d);
    value["text"] = aviary_diagnostics::render_text(sources, d, false).into();
    value
}

/// What the map shows of a world: the site, places, areas, lines (`lines`: name, points
/// `[x, y]`), no-fly zones (`no_fly`: name, polygon, `up_to`), homes and targets, in the
/// local frame (metres east and north of the origin).
pub fn map_of(world: &aviary_world::World) -> Value {
    let drones: Vec<Value> = world
        .drones
        .iter()
        .map(|d| {
            json!({
                "name": d.name,
                "home": d.home,
                "group": d.group.as_deref(),
                "sensors": d.sensors,
            })
        })
        .collect();
    json!({
        "site": world.site,
        "base": crate::tiles::base_map(world),
        "places": world.places,
        "areas": world.areas,
        "lines": world
            .lines
            .iter()
            .map(|l| json!({ "name": l.name, "points": l.ground() }))
            .collect::<Vec<Value>>(),
        "no_fly": world.no_fly,
        "drones": drones,
        "targets": world.targets,
    })
}
