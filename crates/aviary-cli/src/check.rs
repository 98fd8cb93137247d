use std::path::Path;

use aviary_diagnostics::{render_json, render_text, summary_line, Diagnostic, SourceMap};

use crate::files::{color_wanted, world_beside, DiskProvider};
use crate::Format;

pub fn run(files: &[std::path::PathBuf], world: Option<&Path>, format: Format) -> u8 {
    let mut worst = 0;
    for file in files {
        worst = worst.max(check_one(file, world, format));
    }
    worst
}

fn check_one(path: &Path, world_path: Option<&Path>, format: Format) -> u8 {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("aviary: cannot read {}: {e}", path.display());
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
    let checked = aviary_check::check_sources(&mut sources, (&name, &bytes), world, &DiskProvider, &aviary_sim::descriptor());
    let diagnostics = checked.diagnostics;
    print(&sources, &diagnostics, format, path);
    u8::from(diagnostics.iter().any(Diagnostic::is_error))
}

fn print(sources: &SourceMap, diagnostics: &[Diagnostic], format: Format, path: &Path) {
    match format {
        Format::Json => {
            for d in diagnostics {
                println!("{}", render_json(sources, d));
            }
        }
        Format::Text => {
            let color = color_wanted();
            for d in diagnostics {
                print!("{}", render_text(sources, d, color));
            }
            let summary = summary_line(diagnostics);
            if diagnostics.iter().any(Diagnostic::is_error) {
                println!("{}: {summary}", path.display());
            } else if summary.is_empty() {
                println!("{}: ok", path.display());
            } else {
                println!("{}: ok ({summary})", path.display());
            }
        }
    }
}
