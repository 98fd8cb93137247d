//! Reading from disk: missions, the files they USE, and world files.

use std::io::Read;
use std::path::{Path, PathBuf};

use aviary_check::uses::{
    is_mission_name, not_a_mission, within_roots, MAX_USE_BYTES, OUTSIDE_HELP,
};
use aviary_check::{LoadError, SourceProvider};

/// Reads USEd files relative to the file that holds the USE, and only those the rules
/// of `aviary_check::uses` allow: `.mission` files under `roots` (resolved, so a symlink
/// that leads out counts as outside), regular files of at most 16 MiB.
pub struct DiskProvider {
    roots: Vec<PathBuf>,
}

impl DiskProvider {
    /// For the mission `mission` (read already, so its folder exists): its own folder,
    /// and the folders of [`use_roots`].
    pub fn new(mission: &Path, use_roots: &[PathBuf]) -> Result<DiskProvider, String> {
        let folder = match mission.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let own = std::fs::canonicalize(folder)
            .map_err(|e| format!("cannot find the folder of {}: {e}", mission.display()))?;
        Ok(DiskProvider { roots: std::iter::once(own).chain(use_roots.iter().cloned()).collect() })
    }
}

/// The `--use-root DIR`s, resolved; each must be a folder.
pub fn use_roots(dirs: &[PathBuf]) -> Result<Vec<PathBuf>, String> {
    dirs.iter()
        .map(|dir| match std::fs::canonicalize(dir) {
            Ok(p) if p.is_dir() => Ok(p),
            Ok(_) => Err(format!("--use-root {}: not a folder", dir.display())),
            Err(e) => Err(format!("--use-root {}: {e}", dir.display())),
        })
        .collect()
}

/// Where `full` (shown as `name`) leads, links followed; or why it cannot be read.
fn canonical(full: &Path, name: &str) -> Result<std::path::PathBuf, LoadError> {
    std::fs::canonicalize(full).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => format!("there is no file {name}").into(),
        kind => format!("{} ({name})", kind.to_string().to_lowercase()).into(),
    })
}

impl SourceProvider for DiskProvider {
    fn load(&self, from: &str, path: &str) -> Result<(String, Vec<u8>), LoadError> {
        let base = Path::new(from).parent().unwrap_or(Path::new(""));
        let full = aviary_check::normalize_path(&base.join(path));
        let name = full.to_string_lossy().into_owned();
        let resolved = canonical(&full, &name)?;
        if !within_roots(&resolved, &self.roots) {
            let shown: Vec<String> = self.roots.iter().map(|r| r.display().to_string()).collect();
            let leads = if resolved != std::path::absolute(&full).unwrap_or_default() {
                format!(" (it leads to {})", resolved.display())
            } else {
                String::new()
            };
            let why = format!(
                "{name}{leads} is outside the mission's folder{} {}",
                if shown.len() > 1 { " and the --use-root folders" } else { "" },
                shown.join(", ")
            );
            return Err(LoadError::Refused { why, help: OUTSIDE_HELP.into() });
        }
        // A symlink `a.mission` to `notes.txt` is no mission file either.
        if !is_mission_name(&resolved) {
            return Err(not_a_mission());
        }
        read_bounded(&resolved, &name, &USED)
    }

    /// A file a world's `[imports]` names: relative to the world file, inside its folder
    /// (resolved, as for a USE), a regular file of at most 16 MiB. The folder is the world
    /// file's, not the mission's: a world is read with its own files wherever it lies.
    fn world_file(&self, world: &str, path: &str) -> Result<Vec<u8>, LoadError> {
        let base = match Path::new(world).parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let full = aviary_check::normalize_path(&base.join(path));
        let name = full.to_string_lossy().into_owned();
        let folder = std::fs::canonicalize(base)
            .map_err(|e| format!("cannot find the world file's folder {}: {e}", base.display()))?;
        let resolved = canonical(&full, &name)?;
        if !within_roots(&resolved, std::slice::from_ref(&folder)) {
            return Err(LoadError::Refused {
                why: format!("{name} is outside the world file's folder {}", folder.display()),
                help: "keep the imported files in the world file's folder, or below it".into(),
            });
        }
        read_bounded(&resolved, &name, &IMPORTED).map(|(_, bytes)| bytes)
    }
}

/// What a file read by [`read_bounded`] is, for its refusals.
struct Bounded {
    what: &'static str,
    regular: &'static str,
    split: &'static str,
}

const USED: Bounded = Bounded {
    what: "a USEd file",
    regular: "USE a .mission file",
    split: "split the library into several files, each USEd",
};

const IMPORTED: Bounded = Bounded {
    what: "a world's imported file",
    regular: "name a GeoJSON, KML or QGroundControl plan file",
    split: "split it into several files, each named in [imports]",
};

/// The bytes of a regular file of at most `MAX_USE_BYTES`. Opened without blocking, so a
/// FIFO does not wait for a writer, and judged by what was opened, so nothing can be
/// swapped in between.
/// `rules` says what the file is for: a USEd file or a world's import.
fn read_bounded(path: &Path, name: &str, rules: &Bounded) -> Result<(String, Vec<u8>), LoadError> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(|e| {
        LoadError::Unreadable(format!("{} ({name})", e.kind().to_string().to_lowercase()))
    })?;
    let meta = file.metadata().map_err(|e| {
        LoadError::Unreadable(format!("{} ({name})", e.kind().to_string().to_lowercase()))
    })?;
    if !meta.is_file() {
        let what = if meta.is_dir() { "a folder" } else { "a device, pipe or socket" };
        return Err(LoadError::Refused {
            why: format!("{name} is {what}, not a regular file"),
            help: rules.regular.into(),
        });
    }
    let too_large = |size: u64| LoadError::Refused {
        why: format!(
            "{name} has {size} bytes, more than the {} MiB {} may have",
            MAX_USE_BYTES >> 20,
            rules.what
        ),
        help: rules.split.into(),
    };
    if meta.len() > MAX_USE_BYTES {
        return Err(too_large(meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // One byte past the limit tells a file that grew since.
    file.take(MAX_USE_BYTES + 1).read_to_end(&mut bytes).map_err(|e| {
        LoadError::Unreadable(format!("{} ({name})", e.kind().to_string().to_lowercase()))
    })?;
    if bytes.len() as u64 > MAX_USE_BYTES {
        return Err(too_large(bytes.len() as u64));
    }
    Ok((name.to_string(), bytes))
}

/// The provider of a world read without a mission (`aviary vehicles`, `replay`,
/// `report`): its `[imports]` beside it, and no USE (the provider's roots play no part in
/// a world's files).
pub fn world_files() -> DiskProvider {
    DiskProvider { roots: Vec::new() }
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

/// A world file read and checked on its own (`aviary replay`, `aviary report`): the world,
/// or what to print of why not (its errors rendered, each at its place).
pub fn world_alone(path: &Path) -> Result<aviary_world::World, String> {
    let bytes = std::fs::read(path)
        .map_err(|e| format!("aviary: cannot read the world file {}: {e}\n", path.display()))?;
    world_of_bytes(path, bytes)
}

/// The world to draw a recorded trace on (`aviary replay`, `aviary report`): the one given,
/// unless the trace names another (then why not); with none given, the one the trace
/// names, found as it was named, or beside the trace or in the folder above it, with the
/// same bytes. `None` (and a line on standard error that says why) when there is none.
pub fn world_of_trace(
    trace: &Path,
    bytes: &[u8],
    given: Option<&Path>,
) -> Result<Option<aviary_world::World>, String> {
    let stamp = aviary_station::replay::world_stamp(bytes);
    if let Some(path) = given {
        let world = std::fs::read(path)
            .map_err(|e| format!("aviary: cannot read the world file {}: {e}\n", path.display()))?;
        if let Some(why) =
            stamp.as_ref().and_then(|s| s.refuses(&path.display().to_string(), &world))
        {
            return Err(format!("aviary: {why}\n"));
        }
        return world_of_bytes(path, world).map(Some);
    }
    let Some(stamp) = stamp else { return Ok(None) };
    let named = Path::new(stamp.file.as_ref());
    let beside = trace.parent().unwrap_or(Path::new(""));
    let mut candidates = vec![named.to_path_buf(), beside.join(named)];
    if let Some(file) = named.file_name() {
        candidates.push(beside.join(file));
        candidates.extend(beside.parent().map(|above| above.join(file)));
    }
    for path in candidates {
        let Ok(world) = std::fs::read(&path) else { continue };
        if stamp.refuses(&path.display().to_string(), &world).is_none() {
            eprintln!("aviary: the trace was flown in {}: drawn on it", path.display());
            return world_of_bytes(&path, world).map(Some);
        }
    }
    eprintln!(
        "aviary: the trace was flown in {}, which is not here as it was: drawn without a world (give it with --world)",
        stamp.file
    );
    Ok(None)
}

fn world_of_bytes(path: &Path, bytes: Vec<u8>) -> Result<aviary_world::World, String> {
    let mut sources = aviary_diagnostics::SourceMap::new();
    let read = aviary_check::read_world(
        &mut sources,
        &path.display().to_string(),
        std::borrow::Cow::Owned(bytes),
        &world_files(),
    );
    read.world.ok_or_else(|| {
        let mut shown = String::new();
        for d in read.diagnostics.iter().filter(|d| d.is_error()) {
            shown.push_str(&aviary_diagnostics::render_text(&sources, d, color_wanted()));
        }
        shown.push_str(&format!("aviary: the world file {} has errors\n", path.display()));
        shown
    })
}

/// A recorded trace and the world it flew in (`aviary replay`, `aviary report`, `aviary
/// export`): its name as messages show it, its bytes, and the world as
/// [`world_of_trace`] finds it; or what to print of why not.
pub fn recorded_trace_and_world(
    trace: &Path,
    given: Option<&Path>,
) -> Result<(String, Vec<u8>, Option<aviary_world::World>), String> {
    let (name, bytes) = recorded_trace(trace)?;
    let world = world_of_trace(trace, &bytes, given)?;
    Ok((name, bytes, world))
}

/// A recorded trace's bytes: its name as messages show it and the bytes, or what to print
/// of why not.
pub fn recorded_trace(path: &Path) -> Result<(String, Vec<u8>), String> {
    let name = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| format!("aviary: cannot read {name}: {e}\n"))?;
    Ok((name, bytes))
}
