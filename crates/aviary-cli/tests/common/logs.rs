//! The autopilots' own flight logs, read by `tests/logs/positions.py` (pyulog for PX4's
//! ULog, pymavlink's reader for ArduPilot's DataFlash), to hold Aviary's trace to where
//! the vehicle itself logged it was.

use std::path::{Path, PathBuf};
use std::process::Command;

use aviary_mavlink::Origin;

/// The Python with pyulog and pymavlink: `AVIARY_PYTHON`, else the virtual environment
/// `.ci/run` makes, `target/pyenv`.
pub fn python() -> PathBuf {
    let python = std::env::var_os("AVIARY_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| super::repo().join("target/pyenv/bin/python"));
    assert!(
        python.is_file(),
        "no Python for the flight logs at {}: run `python3 -m venv target/pyenv && target/pyenv/bin/pip install pymavlink==2.4.50 pyulog==1.3.0`, or set AVIARY_PYTHON",
        python.display()
    );
    python
}

/// The positions a flight log holds, as local metres about `origin` and the height above
/// home.
pub fn logged_positions(log: &Path, origin: Origin) -> Vec<[f64; 3]> {
    let out = Command::new(python())
        .arg(super::repo().join("tests/logs/positions.py"))
        .arg(log)
        .output()
        .expect("tests/logs/positions.py");
    assert!(
        out.status.success(),
        "reading {}: {}",
        log.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|line| {
            let [lat, lon, z]: [f64; 3] = serde_json::from_str(line).expect("[lat, lon, height]");
            let xy = origin.to_local(lat, lon);
            [xy[0], xy[1], z]
        })
        .collect()
}

/// Every position of `flown` lies within `within` metres of some position the vehicle
/// logged: the farthest, and where.
pub fn farthest_from_log(flown: &[[f64; 3]], logged: &[[f64; 3]]) -> (f64, [f64; 3]) {
    flown
        .iter()
        .map(|p| {
            let near = logged
                .iter()
                .map(|q| (p[0] - q[0]).hypot(p[1] - q[1]).hypot(p[2] - q[2]))
                .fold(f64::INFINITY, f64::min);
            (near, *p)
        })
        .fold((0.0, [0.0; 3]), |a, b| if b.0 > a.0 { b } else { a })
}

/// The files under `dir` whose name ends in `ending`, sorted.
pub fn files_ending(dir: &Path, ending: &str) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut dirs = vec![dir.to_path_buf()];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.to_string_lossy().ends_with(ending) {
                found.push(p);
            }
        }
    }
    found.sort();
    found
}
