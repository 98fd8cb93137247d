//! `aviary run` in the background, for the real-autopilot suites: the test acts on the
//! vehicles while the mission flies, then waits for its end.

use std::path::Path;
use std::process::{Child, Command};
use std::time::Duration;

use serde_json::Value;

/// `aviary run` started in a folder, killed if the test ends first.
pub struct Run(Child);

impl Drop for Run {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Runs `mission` in `dir` with the trace `t.jsonl` (telemetry at 2 Hz); its output goes
/// to `stdout.txt` and `stderr.txt` there.
pub fn start_run(dir: &Path, mission: &str) -> Run {
    let child = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", mission, "--trace", "t.jsonl", "--telemetry-hz", "2"])
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .stdout(std::fs::File::create(dir.join("stdout.txt")).expect("stdout"))
        .stderr(std::fs::File::create(dir.join("stderr.txt")).expect("stderr"))
        .spawn()
        .expect("aviary run");
    Run(child)
}

/// Waits for the run to end: its exit code and the output it printed.
pub fn finish(run: &mut Run, dir: &Path, limit: Duration) -> (i32, String) {
    let code = super::wait_at_most(&mut run.0, limit, &format!("aviary run in {}", dir.display()));
    let out = std::fs::read_to_string(dir.join("stdout.txt")).unwrap_or_default()
        + &std::fs::read_to_string(dir.join("stderr.txt")).unwrap_or_default();
    (code, out)
}

/// The events of a trace, as far as it is written.
pub fn events(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap_or_default()
        .lines()
        .map(|l| serde_json::from_str(l).expect("a whole JSON event"))
        .collect()
}

/// The events of one kind.
pub fn named<'a>(events: &'a [Value], event: &str) -> impl Iterator<Item = &'a Value> {
    let event = event.to_owned();
    events.iter().filter(move |e| e["event"] == event.as_str())
}

/// The first exception of that name.
pub fn exception<'a>(events: &'a [Value], name: &str) -> Option<&'a Value> {
    named(events, "exception").find(|e| e["name"] == name)
}

/// A position of the trace, `[x, y, z]`.
pub fn pos(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("a position");
    let n = |i: usize| a.get(i).and_then(Value::as_f64).unwrap_or(0.0);
    [n(0), n(1), n(2)]
}

/// Waits until the trace in `dir` shows the take-off done.
pub fn airborne(dir: &Path, limit: Duration) {
    super::sitl::wait_until(limit, "the take-off", || {
        events(&dir.join("t.jsonl"))
            .iter()
            .any(|e| e["event"] == "api_done" && e["function"] == "TakeOff")
    });
}
