//! `aviary run` in the background, for the real-autopilot suites: the test acts on the
//! vehicles while the mission flies, then waits for its end.

use std::path::Path;
use std::process::{Child, Command};
use std::time::Duration;

use aviary_api::trace::{Event, EventKind, Record};
use aviary_api::Function;
use aviary_test_support::trace::Trace;

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

/// The events of a trace, as far as it is written: every line a whole record.
pub fn events(path: &Path) -> Trace {
    Trace::parse(&std::fs::read_to_string(path).unwrap_or_default())
}

/// The events of one kind.
pub fn named<'a>(
    events: &'a [Record<'static>],
    kind: EventKind,
) -> impl Iterator<Item = &'a Record<'static>> {
    events.iter().filter(move |e| e.event.kind() == kind)
}

/// The first exception of that name.
pub fn exception<'a>(events: &'a [Record<'static>], name: &str) -> Option<&'a Record<'static>> {
    events.iter().find(|e| is_exception(e, name))
}

/// Whether `e` is an exception of that name.
pub fn is_exception(e: &Record, name: &str) -> bool {
    matches!(&e.event, Event::Exception { name: n, .. } if n == name)
}

/// Whether `e` is a call of `function` starting.
pub fn is_call(e: &Record, function: Function) -> bool {
    matches!(&e.event, Event::ApiCall { function: f, .. } if *f == function)
}

/// Waits (at most `limit`, from now) for the first event of the trace at `path` that
/// `wanted` picks, as the run writes it; fails the test with `what` and the trace's last
/// event otherwise.
pub fn first_event(
    path: &Path,
    limit: Duration,
    what: &str,
    wanted: impl Fn(&Record) -> bool,
) -> Record<'static> {
    let start = std::time::Instant::now();
    loop {
        if let Some(e) = events(path).0.into_iter().find(|e| wanted(e)) {
            return e;
        }
        assert!(start.elapsed() < limit, "no {what} within {limit:?}: {:?}", events(path).last());
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The names of the signals raised, in order.
pub fn signal_names<'a>(events: &'a [Record<'static>]) -> Vec<&'a str> {
    events
        .iter()
        .filter_map(|e| match &e.event {
            Event::Signal { name, .. } => Some(&**name),
            _ => None,
        })
        .collect()
}

/// Whether a signal of that name was raised.
pub fn signalled(events: &[Record<'static>], name: &str) -> bool {
    events.iter().any(|e| matches!(&e.event, Event::Signal { name: n, .. } if n == name))
}

/// What an exception's values (`args`) say, as the trace writes them: its reason, in words.
pub fn said(e: &Record) -> String {
    match &e.event {
        Event::Exception { args, .. } => serde_json::to_string(args).expect("values are JSON"),
        other => panic!("not an exception: {other:?}"),
    }
}

/// A position of the trace, `[x, y, z]`, a coordinate it does not know (written null) 0.
pub fn pos(p: [f64; 3]) -> [f64; 3] {
    p.map(|c| if c.is_finite() { c } else { 0.0 })
}

/// Waits until the trace in `dir` shows the take-off done.
pub fn airborne(dir: &Path, limit: Duration) {
    super::sitl::wait_until(limit, "the take-off", || {
        events(&dir.join("t.jsonl"))
            .iter()
            .any(|e| matches!(e.event, Event::ApiDone { function: Function::TakeOff, .. }))
    });
}
