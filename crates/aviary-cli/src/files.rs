//! Reading from disk: missions, the files they USE, and world files.

use std::path::{Component, Path, PathBuf};

use aviary_check::SourceProvider;

/// Reads USEd files relative to the file that holds the USE.
pub struct DiskProvider;

impl SourceProvider for DiskProvider {
    fn load(&self, from: &str, path: &str) -> Result<(String, Vec<u8>), String> {
        let base = Path::new(from).parent().unwrap_or(Path::new(""));
        let full = normalize(&base.join(path));
        let name = full.to_string_lossy().into_owned();
        match std::fs::read(&full) {
            Ok(bytes) => Ok((name, bytes)),
            Err(e) => Err(format!("{} ({})", e.kind().to_string().to_lowercase(), name)),
        }
    }
}

/// `a/./b/../c` becomes `a/c`, so one file read through two paths is read once.
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir if matches!(out.components().next_back(), Some(Component::Normal(_))) => {
                out.pop();
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
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
