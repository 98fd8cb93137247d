use std::path::Path;

use aviary_api::Descriptor;
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
    let mut sources = SourceMap::new();
    let mut diagnostics: Vec<Diagnostic> = Vec::new();
    let world_path = world_path.map(Path::to_path_buf).or_else(|| world_beside(path));
    let mut world = None;
    if let Some(wp) = &world_path {
        match std::fs::read(wp) {
            Ok(wbytes) => {
                let (text, invalid) = aviary_syntax::decode(&wbytes);
                let id = sources.add(wp.display().to_string(), text);
                match invalid {
                    Some(at) => diagnostics.push(aviary_syntax::invalid_utf8(id, at)),
                    None => {
                        let (w, d) = aviary_world::parse_world(id, sources.text(id));
                        world = w;
                        diagnostics.extend(d);
                    }
                }
            }
            Err(e) => {
                eprintln!("aviary: cannot read the world file {}: {e}", wp.display());
                return 2;
            }
        }
    }
    let world_failed = world_path.is_some() && world.is_none();
    let (text, invalid) = aviary_syntax::decode(&bytes);
    let root = sources.add(path.display().to_string(), text);
    if let Some(at) = invalid {
        diagnostics.push(aviary_syntax::invalid_utf8(root, at));
    } else {
        let checked = aviary_check::check(&mut sources, root, world.as_ref(), &DiskProvider, &Descriptor::standard());
        // Without a usable world the checks would complain of every name; the world's own errors say why.
        diagnostics.extend(checked.diagnostics.into_iter().filter(|d| !(world_failed && d.code == aviary_diagnostics::Code::NoWorld)));
    }
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
