use std::path::{Path, PathBuf};

use aviary_diagnostics::{render_json, render_text, summary_line, Diagnostic, SourceMap};

use crate::files::{color_wanted, use_roots as use_roots_of, world_beside, DiskProvider};
use crate::Format;

/// What `--plan` asks for: the plan, and whether to ask MAVLink vehicles for their
/// figures first (not with `--offline`; never without `--plan`, which must stay fast and
/// offline for editors).
#[derive(Clone, Copy)]
pub struct Plan {
    pub plan: bool,
    pub ask: bool,
}

pub fn run(
    files: &[PathBuf],
    world: Option<&Path>,
    format: Format,
    plan: Plan,
    use_roots: &[PathBuf],
) -> u8 {
    let roots = match use_roots_of(use_roots) {
        Ok(r) => r,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let mut worst = 0;
    for file in files {
        worst = worst.max(check_one(file, world, format, plan, &roots));
    }
    worst
}

fn check_one(
    path: &Path,
    world_path: Option<&Path>,
    format: Format,
    want: Plan,
    use_roots: &[PathBuf],
) -> u8 {
    let want_plan = want.plan;
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("aviary: cannot read {}: {e}", path.display());
            return 2;
        }
    };
    let provider = match DiskProvider::new(path, use_roots) {
        Ok(p) => p,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let world_path = world_path.map(Path::to_path_buf).or_else(|| world_beside(path));
    let world_bytes = match &world_path {
        Some(wp) => match std::fs::read(wp) {
            Ok(b) => Some(b),
            Err(e) => {
                eprintln!("aviary: cannot read the world file {}: {e}", wp.display());
                return 2;
            }
        },
        None => None,
    };
    let world_name = world_path.as_ref().map(|p| p.display().to_string());
    let mut sources = SourceMap::new();
    let world = world_name.as_deref().zip(world_bytes.as_deref());
    let name = path.display().to_string();
    let mut checked = aviary_check::check_sources(&mut sources, (&name, &bytes), world, &provider);
    // MAVLink drones fly with their vehicles' figures: the plan is made with them.
    let mut figures = None;
    if want.ask && !checked.has_errors() {
        if let Some(world) = checked.world.as_mut() {
            figures = Some(crate::vehicle_figures::ask(world));
        }
    }
    let verdict = aviary_verify::verdict(&mut checked);
    let diagnostics = verdict.diagnostics;
    let plan = verdict.flight.map(|(_, plan)| plan);
    let failed = u8::from(diagnostics.iter().any(Diagnostic::is_error));
    if !want_plan {
        print(&sources, &diagnostics, format, path);
        return failed;
    }
    let Some(mut plan) = plan else {
        print(&sources, &diagnostics, format, path);
        eprintln!(
            "aviary: no plan for {}: {}",
            path.display(),
            why_no_plan(failed == 1, world_name.is_some())
        );
        return failed.max(1);
    };
    plan.locate_in(&sources);
    match format {
        Format::Text => {
            print(&sources, &diagnostics, format, path);
            match &figures {
                Some(Ok(f)) if !f.is_empty() => out!("\nfigures of the MAVLink drones:\n{}", crate::vehicle_figures::render(f)),
                Some(Err(why)) => out!("\nfigures of the MAVLink drones: not asked ({why}); planned with the world's figures\n"),
                _ => {}
            }
            out!("\n{}", plan.render_text());
        }
        Format::Json => {
            let (vehicles, vehicles_not_asked) = match figures {
                Some(Ok(f)) if !f.is_empty() => (Some(f), None),
                Some(Err(why)) => (None, Some(why)),
                _ => (None, None),
            };
            let doc = PlanReport {
                file: path.display().to_string(),
                plan: &plan,
                diagnostics: diagnostics.iter().map(|d| render_json(&sources, d)).collect(),
                vehicles,
                vehicles_not_asked,
            };
            outln!("{}", serde_json::to_string(&doc).unwrap_or_default());
        }
    }
    failed
}

/// `aviary check --plan --format json`: the file, its plan and diagnostics, and the
/// MAVLink drones' own figures when they were asked.
#[derive(serde::Serialize)]
struct PlanReport<'a> {
    file: String,
    plan: &'a aviary_verify::plan::Plan,
    diagnostics: Vec<aviary_diagnostics::JsonDiagnostic>,
    #[serde(skip_serializing_if = "Option::is_none")]
    vehicles: Option<Vec<crate::vehicle_figures::Source>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    vehicles_not_asked: Option<String>,
}

fn why_no_plan(errors: bool, world: bool) -> &'static str {
    if errors {
        "fix its errors first"
    } else if !world {
        "a plan needs the world file (put NAME.world.toml beside it, or pass --world)"
    } else {
        "it holds no MISSION"
    }
}

fn print(sources: &SourceMap, diagnostics: &[Diagnostic], format: Format, path: &Path) {
    match format {
        Format::Json => {
            for d in diagnostics {
                outln!("{}", render_json(sources, d));
            }
        }
        Format::Text => {
            let color = color_wanted();
            for d in diagnostics {
                out!("{}", render_text(sources, d, color));
            }
            let summary = summary_line(diagnostics);
            if diagnostics.iter().any(Diagnostic::is_error) {
                outln!("{}: {summary}", path.display());
            } else if summary.is_empty() {
                outln!("{}: ok", path.display());
            } else {
                outln!("{}: ok ({summary})", path.display());
            }
        }
    }
}
