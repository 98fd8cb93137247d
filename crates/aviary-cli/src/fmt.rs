//! `aviary fmt`: files with syntax errors are never rewritten, and a rewrite goes
//! through a temporary file and a rename, so no data is lost on any failure.

use std::path::{Path, PathBuf};

use aviary_diagnostics::{render_text, FileId, SourceMap};

use crate::files::color_wanted;

pub fn run(files: &[PathBuf], check: bool) -> u8 {
    let mut worst = 0;
    for file in files {
        worst = worst.max(format_one(file, check));
    }
    worst
}

fn format_one(path: &Path, check: bool) -> u8 {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("aviary: cannot read {}: {e}", path.display());
            return 2;
        }
    };
    let (text, parse) = aviary_syntax::parse_bytes(FileId(0), &bytes);
    if parse.has_errors() {
        let mut sources = SourceMap::new();
        sources.add(path.display().to_string(), text);
        for d in parse.diagnostics.iter().filter(|d| d.is_error()) {
            out!("{}", render_text(&sources, d, color_wanted()));
        }
        outln!("{}: not formatted, because it has syntax errors", path.display());
        return 1;
    }
    let formatted = aviary_syntax::format(&parse.tree, &text, &parse.line_starts);
    if formatted == text {
        return 0;
    }
    if check {
        outln!("{}: would be reformatted", path.display());
        return 1;
    }
    match write_atomically(path, &formatted) {
        Ok(()) => {
            outln!("{}: formatted", path.display());
            0
        }
        Err(e) => {
            eprintln!("aviary: cannot write {}: {e}", path.display());
            2
        }
    }
}

fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let temp = path.with_file_name(format!(".{name}.aviary-fmt.tmp"));
    std::fs::write(&temp, text)?;
    if let Ok(meta) = std::fs::metadata(path) {
        let _ = std::fs::set_permissions(&temp, meta.permissions());
    }
    std::fs::rename(&temp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&temp);
    })
}
