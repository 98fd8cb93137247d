//! Reading from disk: missions, the files they USE, and world files.

use std::path::{Path, PathBuf};

use aviary_check::SourceProvider;

/// Reads USEd files relative to the file that holds the USE.
pub struct DiskProvider;

impl SourceProvider for DiskProvider {
    fn load(&self, from: &str, path: &str) -> Result<(String, Vec<u8>), String> {
        let base = Path::new(from).parent().unwrap_or(Path::new(""));
        let full = aviary_check::normalize_path(&base.join(path));
        let name = full.to_string_lossy().into_owned();
        match std::fs::read(&full) {
            Ok(bytes) => Ok((name, bytes)),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(format!("there is no file {name}")),
            Err(e) => Err(format!("{} ({name})", e.kind().to_string().to_lowercase())),
        }
    }
}

/// `NAME.world.toml` beside `NAME.mission`, if it exists.
pub fn world_beside(mission: &Path) -> Option<PathBuf> {
    let stem = mission.file_stem()?.to_string_lossy().into_owned();
    let candidate = mission.with_file_name(format!("{stem}.world.toml"));
    candidate.is_file().then_some(candidate)
}

pub fn color_wanted() -> bool {
    use std::io::IsTerminal;
    std::env::var_os("NO_COLOR").is_none() && std::io::stdout().is_terminal()
}
