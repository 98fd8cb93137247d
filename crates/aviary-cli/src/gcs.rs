//! `aviary gcs [DIR]`: the ground station for the missions and worlds of a folder, served
//! until Ctrl-C. The files a mission `USE`s are read as `aviary run` reads them.

use std::io::Write;
use std::path::{Path, PathBuf};

use aviary_station::{FilesFor, Folder, Lsp, Mode};

use crate::files::{use_roots, DiskProvider};
use crate::serve::Serve;

pub fn run(dir: &Path, serve: &Serve, use_root: &[PathBuf]) -> u8 {
    let roots = match use_roots(use_root) {
        Ok(r) => r,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let folder = match Folder::new(dir) {
        Ok(f) => f,
        Err(why) => {
            eprintln!("aviary: cannot serve {}: {why}", dir.display());
            return 2;
        }
    };
    // The page's editor speaks to the language server of `aviary lsp`, reading as it does.
    // The standard library's file is written once, not for every page's socket.
    let lsp_roots = roots.clone();
    let std = crate::lsp::std_file();
    let lsp = Lsp::new(move || crate::lsp::config(&lsp_roots, std.clone()));
    let files: FilesFor = Box::new(move |mission: &Path| {
        DiskProvider::new(mission, &roots)
            .map(|p| Box::new(p) as Box<dyn aviary_check::SourceProvider + Send>)
    });
    let shown = folder.root().display().to_string();
    match crate::serve::station(
        serve,
        Mode::Folder { folder, files },
        serde_json::Value::Null,
        Some(lsp),
    ) {
        Ok(_serving) => {
            // Not `eprintln!`: a script that closed standard error must not stop the station.
            let _ = writeln!(
                std::io::stderr(),
                "aviary: serving the missions of {shown}; Ctrl-C stops"
            );
            // The station serves on its own thread until the process ends.
            loop {
                std::thread::park();
            }
        }
        Err(why) => {
            eprintln!("aviary: {why}");
            2
        }
    }
}
