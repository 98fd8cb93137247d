//! `aviary lsp`: the language server (aviary-lsp) over stdin and stdout. The files a
//! mission `USE`s are read from disk by the same `DiskProvider` as `aviary check`, under
//! the same rules, when the editor does not have them open.

use std::path::{Path, PathBuf};

use aviary_check::SourceProvider;

use crate::files::{use_roots as use_roots_of, DiskProvider};

/// The server's configuration: the disk read by `DiskProvider` under `roots` (the
/// `--use-root`s, resolved), and the standard library's file (`std_file`, made once by
/// the caller). `aviary gcs` gives its page's editor the same.
pub fn config(roots: &[PathBuf], std: Option<PathBuf>) -> aviary_lsp::Config {
    let for_disk = roots.to_vec();
    aviary_lsp::Config {
        disk: Box::new(move |mission: &Path| {
            DiskProvider::new(mission, &for_disk).map(|p| Box::new(p) as Box<dyn SourceProvider>)
        }),
        use_roots: roots.to_vec(),
        std_file: std,
    }
}

pub fn run(use_roots: &[PathBuf]) -> u8 {
    let roots = match use_roots_of(use_roots) {
        Ok(r) => r,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    match aviary_lsp::serve_stdio(config(&roots, std_file())) {
        Ok(()) => 0,
        Err(why) => {
            eprintln!("aviary lsp: {why}");
            1
        }
    }
}

/// The standard library's text as a file an editor can open, for go to definition (it is
/// compiled into the binary): `$XDG_CACHE_HOME/aviary/VERSION/standard.mission` (else
/// `~/.cache`, else the temporary folder), written when missing or different, read-only
/// (editing it would change nothing). `None`, with a line on stderr, when it cannot be
/// written: definitions in it are then not offered.
pub fn std_file() -> Option<PathBuf> {
    let cache = std::env::var_os("XDG_CACHE_HOME")
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))
        .unwrap_or_else(std::env::temp_dir);
    let folder = cache.join("aviary").join(env!("CARGO_PKG_VERSION"));
    let file = folder.join("standard.mission");
    let text = aviary_check::STD_SOURCE;
    if std::fs::read(&file).is_ok_and(|b| b == text.as_bytes()) {
        return Some(file);
    }
    let written = (|| {
        std::fs::create_dir_all(&folder)?;
        // Written beside it and renamed over it: another server reading it never sees half.
        let part = folder.join(format!("standard.mission.{}", std::process::id()));
        std::fs::write(&part, text)?;
        let mut read_only = std::fs::metadata(&part)?.permissions();
        read_only.set_readonly(true);
        std::fs::set_permissions(&part, read_only)?;
        std::fs::rename(&part, &file)
    })();
    match written {
        Ok(()) => Some(file),
        Err(e) => {
            eprintln!(
                "aviary lsp: the standard library could not be written to {}: {e}; go to definition will not reach it",
                file.display()
            );
            None
        }
    }
}
