//! World files as `aviary check` shows them: every `*.world.toml` under `tests/fixtures/`
//! is read, and what a user sees is compared with a snapshot (`tests/snapshots/`): each
//! diagnostic rendered (`path:line:col`, the line, a caret, the help), or for a world
//! without problems a summary of its drones, groups, areas and no-fly zones.

use std::fmt::Write;
use std::path::Path;

use aviary_diagnostics::{render_text, SourceMap};

/// What a user sees of the world file at `path`.
fn shown(path: &Path) -> String {
    let text = std::fs::read_to_string(path).expect("a readable fixture");
    let name = format!("fixtures/{}", path.file_name().unwrap_or_default().to_string_lossy());
    let mut sources = SourceMap::new();
    let id = sources.add(&name, text);
    let (world, diagnostics) = aviary_world::parse_world(id, sources.text(id));
    let mut out = String::new();
    for d in &diagnostics {
        out.push_str(&render_text(&sources, d, false));
    }
    let Some(w) = world else { return out };
    let _ = writeln!(out, "{} drones:", w.drones.len());
    for d in w.drones.iter().take(4).chain(w.drones.iter().skip(4).last()) {
        let attributes: Vec<String> =
            d.attributes.iter().map(|(k, v)| format!("{k} = {v:?}")).collect();
        let _ = writeln!(
            out,
            "  {} at ({}, {}) group {:?} sensors {:?} max_speed {} [{}]",
            d.name,
            d.home[0],
            d.home[1],
            d.group.as_deref(),
            d.sensors,
            d.max_speed,
            attributes.join(", ")
        );
    }
    for g in &w.groups {
        let _ = writeln!(out, "group {}: {} members", g.name, g.members.len());
    }
    for a in w.areas.iter().take(3) {
        let _ = writeln!(out, "area {}: {:?}", a.name, a.polygon);
    }
    for z in &w.no_fly {
        let _ = writeln!(out, "no-fly zone {} up to {:?}: {:?}", z.name, z.up_to, z.polygon);
    }
    if !w.air.is_still() {
        let _ = writeln!(out, "air: {:#?}", w.air);
    }
    for d in w.drones.iter().filter(|d| d.air.is_some()) {
        let _ = writeln!(out, "air of {}: {:?}", d.name, d.air);
    }
    out
}

#[test]
fn fixtures() {
    insta::glob!("fixtures/*.world.toml", |path| {
        insta::assert_snapshot!(shown(path));
    });
}

/// The files a fixture's `[imports]` names, read beside it (the crate reads none itself).
struct Beside<'p>(&'p Path);

impl aviary_world::WorldFiles for Beside<'_> {
    fn read(&self, path: &str) -> Result<Vec<u8>, String> {
        let folder = self.0.parent().unwrap_or(Path::new("."));
        std::fs::read(folder.join(path)).map_err(|e| format!("there is no file {path} ({e})"))
    }
}

/// What a user sees of the world file at `path` with its imports: its diagnostics, or
/// the places, lines, areas and no-fly zones it has (the local frame's metres, to the cm).
fn shown_with_imports(path: &Path) -> String {
    let text = std::fs::read_to_string(path).expect("a readable fixture");
    let name =
        format!("fixtures/imports/{}", path.file_name().unwrap_or_default().to_string_lossy());
    let mut sources = SourceMap::new();
    let id = sources.add(&name, text);
    let (world, diagnostics) = aviary_world::parse_world_with(id, sources.text(id), &Beside(path));
    let mut out = String::new();
    for d in &diagnostics {
        out.push_str(&render_text(&sources, d, false));
    }
    let Some(w) = world else { return out };
    let cm = |v: f64| (v * 100.0).round() / 100.0;
    let xy = |p: &[f64; 2]| format!("({}, {})", cm(p[0]), cm(p[1]));
    let corners = |ps: &[[f64; 2]]| ps.iter().map(xy).collect::<Vec<_>>().join(" ");
    let z = |z: f64, has_z: bool| if has_z { format!(" z {}", cm(z)) } else { String::new() };
    for p in &w.places {
        let _ =
            writeln!(out, "place {} at {}{}", p.name, xy(&[p.at[0], p.at[1]]), z(p.at[2], p.has_z));
    }
    for l in &w.lines {
        let points: Vec<String> = l
            .points
            .iter()
            .map(|(p, has_z)| format!("{}{}", xy(&[p[0], p[1]]), z(p[2], *has_z)))
            .collect();
        let _ = writeln!(out, "line {}: {}", l.name, points.join(" "));
    }
    for a in &w.areas {
        let _ = writeln!(out, "area {}: {}", a.name, corners(&a.polygon));
    }
    for z in &w.no_fly {
        let _ =
            writeln!(out, "no-fly zone {} up to {:?}: {}", z.name, z.up_to, corners(&z.polygon));
    }
    out
}

#[test]
fn imports() {
    insta::glob!("fixtures/imports/*.world.toml", |path| {
        insta::assert_snapshot!(shown_with_imports(path));
    });
}

/// Serves one file's bytes, whatever the name asked for.
struct Bytes(Vec<u8>);

impl aviary_world::WorldFiles for Bytes {
    fn read(&self, _path: &str) -> Result<Vec<u8>, String> {
        Ok(self.0.clone())
    }
}

/// A broken GeoJSON, KML or plan file is an error, never a panic: every imported fixture cut
/// short at many places, and with bytes changed, read as each kind.
#[test]
fn broken_imports_never_panic() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/imports");
    let world = |file: &str| {
        format!("[site]\norigin = {{ lat = 46.6, lon = 14.2 }}\n[imports]\nfeatures = \"{file}\"\nno_fly = \"{file}\"\n")
    };
    for entry in std::fs::read_dir(&folder).unwrap() {
        let path = entry.unwrap().path();
        let Ok(bytes) = std::fs::read(&path) else { continue };
        if bytes.len() > 64 * 1024 {
            continue;
        }
        let step = (bytes.len() / 40).max(1);
        for cut in (0..bytes.len()).step_by(step) {
            let mut changed = bytes.clone();
            changed[cut] = changed[cut].wrapping_add(7);
            for served in [bytes[..cut].to_vec(), changed] {
                for file in ["f.geojson", "f.kml", "f.plan"] {
                    let provider = Bytes(served.clone());
                    let (_, _) = aviary_world::parse_world_with(
                        aviary_diagnostics::FileId(0),
                        &world(file),
                        &provider,
                    );
                }
            }
        }
    }
}
