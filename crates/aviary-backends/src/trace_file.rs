//! The trace file: one JSON object per line, each written whole and flushed at once, so a
//! run cut short (a kill, a crash, a second Ctrl-C) keeps every event before the cut.
//!
//! A write that fails (a full disk, `/dev/full`, a closed pipe) is answered with the
//! reason once, for the caller to say at once, and nothing more is written: a line written
//! after a failed one could follow half an event. The mission flies on (stopping a fleet
//! in the air because a disk filled up would be the worse failure); `aviary run` exits 3
//! at its end, and the ground station says so on the page. Used by `aviary run --trace`
//! and by the station's flights.

use std::io::Write;
use std::sync::{Arc, Mutex, MutexGuard};

use aviary_api::trace::{Event, Record, Status};

pub struct TraceFile {
    out: Box<dyn Write + Send>,
    /// Where it goes, for messages.
    name: String,
    /// The mission's name, for a `mission_start` the trace must begin with.
    mission: String,
    started: bool,
    last_t: f64,
    closed: bool,
    /// The first write error, once one happened.
    failed: Option<String>,
    /// The line being written, kept between events so that writing one allocates nothing.
    line: Vec<u8>,
}

pub type SharedTrace = Arc<Mutex<TraceFile>>;

pub fn lock(trace: &SharedTrace) -> MutexGuard<'_, TraceFile> {
    trace.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

impl TraceFile {
    pub fn new(out: Box<dyn Write + Send>, name: String, mission: String) -> SharedTrace {
        Arc::new(Mutex::new(TraceFile {
            out,
            name,
            mission,
            started: false,
            last_t: 0.0,
            closed: false,
            failed: None,
            line: Vec::new(),
        }))
    }

    /// Why the trace is not whole, if it is not.
    pub fn failed(&self) -> Option<&str> {
        self.failed.as_deref()
    }

    /// Writes the event; `Some(why)` when this write failed (once: nothing is written
    /// after).
    pub fn write(&mut self, record: &Record) -> Option<String> {
        if self.closed || self.failed.is_some() {
            return None;
        }
        // One write of the whole line: a cut never leaves half an event behind.
        self.line.clear();
        let written = serde_json::to_writer(&mut self.line, record).map_err(std::io::Error::from);
        self.line.push(b'\n');
        let written =
            written.and_then(|()| self.out.write_all(&self.line)).and_then(|()| self.out.flush());
        if let Err(e) = written {
            self.failed = Some(e.to_string());
            return Some(format!("cannot write the trace {}: {e}", self.name));
        }
        // A time that is not finite is written `null`: the last one stands.
        if record.t.is_finite() {
            self.last_t = record.t;
        }
        match record.event {
            Event::MissionStart { .. } => self.started = true,
            Event::MissionEnd { .. } => self.closed = true,
            _ => {}
        }
        None
    }

    /// Ends the trace now, from outside the engine (a second Ctrl-C, or a stop before
    /// the mission started): a trace is whole, from `mission_start` to `mission_end`,
    /// whenever it is cut.
    pub fn close_now(&mut self, reason: &str) -> Option<String> {
        if !self.started {
            let mission = self.mission.clone();
            let start = Event::MissionStart { mission: mission.into() };
            if let Some(why) = self.write(&Record { t: 0.0, event: start }) {
                return Some(why);
            }
        }
        let end = Event::MissionEnd { status: Status::Aborted, reason: Some(reason.into()) };
        self.write(&Record { t: self.last_t, event: end })
    }
}
