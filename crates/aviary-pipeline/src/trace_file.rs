//! The trace file: one JSON object per line, each written whole and flushed at once, so a
//! run cut short (a kill, a crash, a second Ctrl-C) keeps every event before the cut.
//!
//! A write that fails (a full disk, `/dev/full`, a closed pipe) is answered with the
//! reason once, for the caller to say at once, and nothing more is written: a line written
//! after a failed one could follow half an event. The mission flies on (stopping a fleet
//! in the air because a disk filled up would be the worse failure); `aviary run` exits 3
//! at its end, and the ground station says so on the page. Used by `aviary run --trace`
//! and by the station's flights.
//!
//! A trace never grows without bound: past its size limit (`aviary run
//! --max-trace-size`, [`DEFAULT_MAX_BYTES`] unless told otherwise) no event is written,
//! the trace is closed with a `mission_end` that says why, within the limit (room for it
//! is kept), and the write that reached it answers [`Cut::Full`]: the caller stops the
//! run, whose fleet goes home. A mission that makes events without end (a cycle at one
//! instant the run's bounds do not see) would otherwise fill the disk.

use parking_lot::Mutex;
use std::io::Write;
use std::sync::Arc;

use aviary_api::trace::{Event, Record, Status};

/// The size limit of a trace unless told otherwise: 1 GiB, some 10 million events, far
/// more than a day's flight of a large fleet with telemetry records.
pub const DEFAULT_MAX_BYTES: u64 = 1 << 30;

/// The smallest size limit: room for the first events and the closing line.
pub const MIN_MAX_BYTES: u64 = 4 << 10;

/// Kept free below the limit for the `mission_end` that closes a trace cut there; that
/// line is far shorter (its reason is ours, its time a number).
const CLOSING_ROOM: u64 = 1 << 10;

/// Why a write ended the trace: nothing is written after.
#[derive(Clone, Debug, PartialEq)]
pub enum Cut {
    /// A write failed (a full disk, a closed pipe): `cannot write the trace NAME: why`.
    Failed(String),
    /// The trace reached its size limit, in bytes, and was closed.
    Full { name: String, limit: u64 },
}

impl std::fmt::Display for Cut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Cut::Failed(why) => f.write_str(why),
            Cut::Full { name, limit } => {
                write!(f, "the trace {name} reached its size limit of {}", show_size(*limit))
            }
        }
    }
}

/// A size in bytes as people read it: in the largest binary unit that holds it whole.
pub fn show_size(bytes: u64) -> String {
    for (shift, unit) in [(40, "TiB"), (30, "GiB"), (20, "MiB"), (10, "KiB")] {
        if bytes >= 1 << shift && bytes.is_multiple_of(1 << shift) {
            return format!("{} {unit}", bytes >> shift);
        }
    }
    format!("{bytes} bytes")
}

pub struct TraceFile {
    out: Box<dyn Write + Send>,
    /// Where it goes, for messages.
    name: String,
    /// The mission's name, for a `mission_start` the trace must begin with.
    mission: String,
    started: bool,
    last_t: f64,
    closed: bool,
    /// The first write error, once one happened, or the limit reached.
    failed: Option<String>,
    /// Bytes written so far, and the most there may be.
    written: u64,
    max_bytes: u64,
    /// The line being written, kept between events so that writing one allocates nothing.
    line: Vec<u8>,
}

pub type SharedTrace = Arc<Mutex<TraceFile>>;

impl TraceFile {
    /// A trace written to `out`, at most `max_bytes` long (at least [`MIN_MAX_BYTES`]).
    pub fn new(
        out: Box<dyn Write + Send>,
        name: String,
        mission: String,
        max_bytes: u64,
    ) -> SharedTrace {
        Arc::new(Mutex::new(TraceFile {
            out,
            name,
            mission,
            started: false,
            last_t: 0.0,
            closed: false,
            failed: None,
            written: 0,
            max_bytes: max_bytes.max(MIN_MAX_BYTES),
            line: Vec::new(),
        }))
    }

    /// Why the trace is not whole, if it is not.
    pub fn failed(&self) -> Option<&str> {
        self.failed.as_deref()
    }

    /// Writes the event; `Some(cut)` when this write ended the trace (once: nothing is
    /// written after).
    pub fn write(&mut self, record: &Record) -> Option<Cut> {
        if self.closed || self.failed.is_some() {
            return None;
        }
        self.line.clear();
        let made = serde_json::to_writer(&mut self.line, record).map_err(std::io::Error::from);
        self.line.push(b'\n');
        // Room is kept for a closing line; the closing line itself may take it.
        let room = match record.event {
            Event::MissionEnd { .. } => 0,
            _ => CLOSING_ROOM,
        };
        if made.is_ok() && self.written + self.line.len() as u64 + room > self.max_bytes {
            return Some(self.full());
        }
        if let Err(e) = made.and_then(|()| self.put()) {
            self.failed = Some(e.to_string());
            return Some(Cut::Failed(format!("cannot write the trace {}: {e}", self.name)));
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

    /// One write of the whole line: a cut never leaves half an event behind.
    fn put(&mut self) -> std::io::Result<()> {
        self.out.write_all(&self.line)?;
        self.out.flush()?;
        self.written += self.line.len() as u64;
        Ok(())
    }

    /// The trace has reached its limit: closed with a `mission_end` that says so, in the
    /// room kept for it.
    #[cold]
    fn full(&mut self) -> Cut {
        let limit = show_size(self.max_bytes);
        let reason = format!("the trace reached its size limit of {limit}: the run was stopped here, its fleet sent home, and nothing after is recorded");
        let end = Event::MissionEnd { status: Status::Aborted, reason: Some(reason.into()) };
        self.line.clear();
        let closed = serde_json::to_writer(&mut self.line, &Record { t: self.last_t, event: end })
            .map_err(std::io::Error::from);
        self.line.push(b'\n');
        let cut = Cut::Full { name: self.name.clone(), limit: self.max_bytes };
        match closed.and_then(|()| self.put()) {
            Ok(()) => self.failed = Some(format!("it reached its size limit of {limit}")),
            Err(e) => {
                self.failed = Some(format!("it reached its size limit of {limit}, and its closing line could not be written: {e}"))
            }
        }
        self.closed = true;
        cut
    }

    /// Ends the trace now, from outside the engine (a second Ctrl-C, or a stop before
    /// the mission started): a trace is whole, from `mission_start` to `mission_end`,
    /// whenever it is cut.
    pub fn close_now(&mut self, reason: &str) -> Option<Cut> {
        if !self.started {
            let mission = self.mission.clone();
            let start = Event::MissionStart { mission: mission.into(), world: None };
            if let Some(why) = self.write(&Record { t: 0.0, event: start }) {
                return Some(why);
            }
        }
        let end = Event::MissionEnd { status: Status::Aborted, reason: Some(reason.into()) };
        self.write(&Record { t: self.last_t, event: end })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `Write` whose bytes the test can read after the trace has them.
    #[derive(Clone, Default)]
    struct Shared(Arc<Mutex<Vec<u8>>>);

    impl Write for Shared {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.0.lock().extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    fn signal(t: f64) -> Record<'static> {
        Record {
            t,
            event: Event::Signal {
                name: "X".into(),
                actor: None,
                args: Vec::new(),
                by: None,
                line: None,
            },
        }
    }

    #[test]
    fn a_trace_at_its_limit_is_closed_within_it_and_says_why() {
        let out = Shared::default();
        let trace = TraceFile::new(Box::new(out.clone()), "t.jsonl".into(), "M".into(), 4096);
        let mut trace = trace.lock();
        let start =
            Record { t: 0.0, event: Event::MissionStart { mission: "M".into(), world: None } };
        assert_eq!(trace.write(&start), None);
        let mut cuts = Vec::new();
        for i in 0..1000 {
            cuts.extend(trace.write(&signal(i as f64)));
        }
        assert_eq!(cuts, [Cut::Full { name: "t.jsonl".into(), limit: 4096 }], "said once");
        assert_eq!(cuts[0].to_string(), "the trace t.jsonl reached its size limit of 4 KiB");
        assert_eq!(trace.failed(), Some("it reached its size limit of 4 KiB"));
        let text = String::from_utf8(out.0.lock().clone()).unwrap();
        assert!(text.len() <= 4096, "{} bytes", text.len());
        let last: Record = serde_json::from_str(text.lines().last().unwrap()).unwrap();
        let Event::MissionEnd { status, reason } = &last.event else { panic!("{last:?}") };
        assert_eq!(*status, Status::Aborted);
        assert_eq!(
            reason.as_deref(),
            Some("the trace reached its size limit of 4 KiB: the run was stopped here, its fleet sent home, and nothing after is recorded")
        );
        // The events before the cut are whole, and written up to the room kept.
        assert!(text.len() > 4096 - 2 * CLOSING_ROOM as usize, "{} bytes", text.len());
        let end = Record { t: 9.0, event: Event::MissionEnd { status: Status::Ok, reason: None } };
        assert_eq!(trace.write(&end), None, "nothing after");
        assert_eq!(out.0.lock().len(), text.len());
    }

    #[test]
    fn sizes_are_shown_in_the_largest_unit_that_holds_them_whole() {
        assert_eq!(show_size(DEFAULT_MAX_BYTES), "1 GiB");
        assert_eq!(show_size(64 << 10), "64 KiB");
        assert_eq!(show_size(1536 << 20), "1536 MiB");
        assert_eq!(show_size(5000), "5000 bytes");
    }
}
