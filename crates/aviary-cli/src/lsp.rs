//! `aviary lsp`: the language server (aviary-lsp) over stdin and stdout. The files a
//! mission `USE`s are read from disk by the same `DiskProvider` as `aviary check`, under
//! the same rules, when the editor does not have them open.

use std::path::{Path, PathBuf};

use aviary_check::SourceProvider;

use crate::files::{use_roots as use_roots_of, DiskProvider};

/// The server's configuration: the disk read by `DiskProvider` under `roots` (the
/// `--use-root`s, resolved). `aviary gcs` gives its page's editor the same.
pub fn config(roots: &[PathBuf]) -> aviary_lsp::Config {
    let for_disk = roots.to_vec();
    aviary_lsp::Config {
        disk: Box::new(move |mission: &Path| {
            DiskProvider::new(mission, &for_disk).map(|p| Box::new(p) as Box<dyn SourceProvider>)
        }),
        use_roots: roots.to_vec(),
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
    match aviary_lsp::serve_stdio(config(&roots)) {
        Ok(()) => 0,
        Err(why) => {
            eprintln!("aviary lsp: {why}");
            1
        }
    }
}
