//! The trace file: one JSON object per line, each written whole and flushed at once, so a
//! run cut short (a kill, a crash, a second Ctrl-C) keeps every event before the cut.

use std::io::Write;
use std::sync::{Arc, Mutex, MutexGuard};

pub struct TraceFile {
    out: Box<dyn Write + Send>,
    last_t: f64,
    closed: bool,
}

pub type SharedTrace = Arc<Mutex<TraceFile>>;

pub fn lock(trace: &SharedTrace) -> MutexGuard<'_, TraceFile> {
    trace.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

impl TraceFile {
    pub fn new(out: Box<dyn Write + Send>) -> SharedTrace {
        Arc::new(Mutex::new(TraceFile { out, last_t: 0.0, closed: false }))
    }

    pub fn write(&mut self, event: &serde_json::Value) {
        if self.closed {
            return;
        }
        // One write of the whole line: a cut never leaves half an event behind.
        let line = format!("{event}\n");
        let _ = self.out.write_all(line.as_bytes());
        let _ = self.out.flush();
        if let Some(t) = event["t"].as_f64() {
            self.last_t = t;
        }
        if event["event"] == "mission_end" {
            self.closed = true;
        }
    }

    /// Ends the trace now, from outside the engine (a second Ctrl-C).
    pub fn close_now(&mut self, reason: &str) {
        let end = serde_json::json!({ "t": self.last_t, "event": "mission_end", "status": "aborted", "reason": reason });
        self.write(&end);
    }
}
