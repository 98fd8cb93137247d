//! The run's lines on their way to the event streams (`GET /api/events`): broadcast to the
//! streams open, and kept, telemetry aside, for a stream that asks `?from=start`. A run's
//! [`crate::Feed`] pushes its events here; a station watching a run on another machine
//! pushes the lines it receives ([`Line::parse`]), and its pages stream them the same way.

use parking_lot::{Mutex, MutexGuard};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use aviary_api::trace::{Event, Record};
use tokio::sync::broadcast;

/// How many events a slow WebSocket client may fall behind before it misses some.
const BACKLOG: usize = 4096;

/// How many events (telemetry aside) a stream `?from=start` can replay: a page that opens
/// mid-mission sees the blocks, activities and signals so far. Beyond, the oldest go.
const HISTORY: usize = 100_000;

/// An event as streams send it: its trace line, and what a stream needs to know of it
/// without reading the line again.
pub struct Line {
    /// The trace file's line, without its newline.
    pub text: Box<str>,
    /// The drone, for a telemetry sample.
    pub telemetry_of: Option<Box<str>>,
    /// `mission_end`: the last.
    pub end: bool,
    /// How many events (telemetry aside) came before this one: an event's place in the
    /// run, by which a station on another machine joins the history it asked for to the
    /// lines it hears. Set by [`Relay::push`].
    pub seq: u64,
}

impl Line {
    /// The line of `record`, as the trace file has it.
    pub fn of(record: &Record) -> Option<Line> {
        let text = serde_json::to_string(record).ok()?;
        Some(Line::known(text, record))
    }

    /// A line received from elsewhere (a run on another machine): kept as it came, if it
    /// is a trace event; anything else is refused with the reason.
    pub fn parse(text: &str) -> Result<Line, String> {
        let record: Record = serde_json::from_str(text)
            .map_err(|e| format!("not an event of a trace (docs/TRACE.md): {e}"))?;
        Ok(Line::known(text.trim_end().to_string(), &record))
    }

    fn known(text: String, record: &Record) -> Line {
        let telemetry_of = match &record.event {
            Event::Telemetry { actor, .. } => Some(Box::from(&**actor)),
            _ => None,
        };
        let end = matches!(record.event, Event::MissionEnd { .. });
        Line { text: text.into_boxed_str(), telemetry_of, end, seq: 0 }
    }
}

/// The events so far, telemetry aside, as their lines.
#[derive(Default)]
pub(crate) struct History {
    pub lines: VecDeque<Arc<Line>>,
    /// How many of the oldest were let go.
    pub dropped: u64,
}

/// Where lines go to the event streams.
pub struct Relay {
    /// Event streams still open.
    pub(crate) streams: AtomicUsize,
    events: broadcast::Sender<Arc<Line>>,
    /// Appended and broadcast under one lock, so a new stream takes both at one instant.
    history: Mutex<History>,
}

impl Relay {
    pub fn new() -> Arc<Relay> {
        Relay::after(0)
    }

    /// A relay whose first event is the run's `dropped`th: the history a station of a
    /// run on another machine joins lacks the `dropped` oldest, as the run's did.
    pub fn after(dropped: u64) -> Arc<Relay> {
        let (events, _) = broadcast::channel(BACKLOG);
        let history = Mutex::new(History { lines: VecDeque::new(), dropped });
        Arc::new(Relay { streams: AtomicUsize::new(0), events, history })
    }

    /// Sends `line` to every stream, and keeps it for the later ones (not telemetry).
    pub fn push(&self, mut line: Line) {
        let mut history = self.history();
        line.seq = history.dropped + history.lines.len() as u64;
        let line = Arc::new(line);
        if line.telemetry_of.is_none() {
            history.lines.push_back(line.clone());
            if history.lines.len() > HISTORY {
                history.lines.pop_front();
                history.dropped += 1;
            }
        }
        let _ = self.events.send(line);
    }

    /// Every line from now on. A receiver that falls [`BACKLOG`] lines behind misses the
    /// oldest and is told so (`RecvError::Lagged`).
    pub fn subscribe(&self) -> broadcast::Receiver<Arc<Line>> {
        self.events.subscribe()
    }

    /// The lines so far (with `from_start`) and every one after, taken at one instant, so
    /// that no line is missed or sent twice between them.
    pub(crate) fn open(
        &self,
        from_start: bool,
    ) -> (crate::stream::Past, broadcast::Receiver<Arc<Line>>) {
        let history = self.history();
        let past = from_start.then(|| (history.lines.iter().cloned().collect(), history.dropped));
        // Taken while the lock is held: no line is pushed between the two.
        (past, self.events.subscribe())
    }

    /// The events so far (telemetry aside), and how many older ones were let go.
    pub fn past(&self) -> (Vec<Arc<Line>>, u64) {
        let history = self.history();
        (history.lines.iter().cloned().collect(), history.dropped)
    }

    /// After `mission_end`: waits (at most `limit`) until every open stream has delivered
    /// it, so that no client misses how the mission ended.
    pub fn finish(&self, limit: std::time::Duration) {
        let start = std::time::Instant::now();
        while self.streams.load(Ordering::SeqCst) > 0 && start.elapsed() < limit {
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
    }

    fn history(&self) -> MutexGuard<'_, History> {
        self.history.lock()
    }
}
