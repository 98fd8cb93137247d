// Shared by several test binaries; each uses part of it.
#![allow(dead_code)]

//! Running the built `aviary` as a user does, in scratch directories.

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs `aviary ARGS` in `dir`: exit code, stdout, stderr.
pub fn aviary(args: &[&str], dir: &Path) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_aviary")).args(args).current_dir(dir).env("NO_COLOR", "1").output().expect("run aviary");
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh directory under the target dir, so tests never touch the source tree.
pub fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}
pub mod sitl;
