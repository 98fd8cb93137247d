//! What the fuzz targets run on each input. The `fuzz_*` binaries feed AFL's inputs to
//! these functions; a test runs the seed corpus through them without AFL. Every
//! function panics when a property does not hold, which AFL records as a crash.

mod call;
mod lsp;
mod mavlink;
mod operator;
mod station;

pub use lsp::lsp;
pub use mavlink::{
    answers_of_px4_vehicles, answers_of_the_vehicles, heard_on_a_link, link, vehicles,
};
pub use operator::operator;
pub use station::station;

// Fuzzed missions `USE` nothing that can be read.
use aviary_check::NoFiles;
use aviary_diagnostics::{render_json, render_text, FileId, SourceMap};

/// The world every fuzzed mission is checked against.
pub const EXAMPLE_WORLD: &str = include_str!("../../examples/search_and_rescue.world.toml");

/// Parses the bytes as a mission. When they parse without errors: formats them, checks
/// that the result parses without errors and that formatting it again changes nothing.
/// Then checks the mission against the example world, as `aviary check` would, and
/// renders every diagnostic.
pub fn mission(data: &[u8]) {
    let (text, parse) = aviary_syntax::parse_bytes(FileId(0), data);
    if !parse.has_errors() {
        let formatted = aviary_syntax::format(&parse.tree, &text, &parse.line_starts);
        let again = aviary_syntax::parse(FileId(0), &formatted);
        if again.has_errors() {
            panic!(
                "the formatted text does not parse: {:#?}\n--- input ---\n{text}\n--- formatted ---\n{formatted}",
                again.diagnostics.iter().filter(|d| d.is_error()).collect::<Vec<_>>()
            );
        }
        let twice = aviary_syntax::format(&again.tree, &formatted, &again.line_starts);
        if twice != formatted {
            panic!("formatting is not idempotent\n--- input ---\n{text}\n--- formatted once ---\n{formatted}\n--- formatted twice ---\n{twice}");
        }
    }
    // The whole front end, as `aviary check` runs it (non-UTF-8 input included).
    let mut sources = SourceMap::new();
    let mut checked = aviary_check::check_sources(
        &mut sources,
        ("fuzz.mission", data),
        Some(("world.toml", EXAMPLE_WORLD.as_bytes())),
        &NoFiles,
    );
    assert!(checked.world.is_some(), "the example world has problems");
    for d in &checked.diagnostics {
        let _ = render_text(&sources, d, false);
        let _ = render_json(&sources, d);
    }
    // A mission without errors is compiled and goes through the pre-flight analyses.
    if let Some((_, verified)) = aviary_verify::preflight(&mut checked) {
        for d in &verified.diagnostics {
            let _ = render_text(&sources, d, false);
        }
        let _ = verified.plan.render_text();
    }
}

/// Reads the bytes (lossily decoded) as a world file and renders every diagnostic.
pub fn world(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let mut sources = SourceMap::new();
    let id = sources.add("world.toml", text.as_ref());
    let (world, diagnostics) = aviary_world::parse_world(id, sources.text(id));
    assert!(
        world.is_some() == diagnostics.is_empty(),
        "a world must come exactly when there are no diagnostics"
    );
    for d in &diagnostics {
        let _ = render_text(&sources, d, false);
        let _ = render_json(&sources, d);
    }
}

/// Without AFL: runs `target` on each file named on the command line, or on stdin.
pub fn run_files(target: fn(&[u8])) {
    let files: Vec<String> = std::env::args().skip(1).collect();
    if files.is_empty() {
        let mut data = Vec::new();
        std::io::Read::read_to_end(&mut std::io::stdin(), &mut data).expect("stdin");
        target(&data);
        return;
    }
    for file in files {
        eprintln!("{file}");
        let data = std::fs::read(&file).unwrap_or_else(|e| panic!("cannot read {file}: {e}"));
        target(&data);
    }
}
