//! A trace as typed records ([`aviary_api::trace::Record`]), for tests to read: a run of
//! the harness's, or a trace file the `aviary` binary wrote. A test picks events by
//! matching on [`Event`] (`matches!(e, Event::HandlerStart { signal, .. } if signal ==
//! "Ping")`), or with one of the few predicates of [`is`] for the lookups most tests make,
//! and reads their fields where the match binds them.

use std::path::Path;

use aviary_api::trace::{Event, EventKind, Params, Record, Status};
use aviary_api::Function;

/// The events of a trace in order, each read back as the trace file has it (so each one
/// is a valid line of the file).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace(pub Vec<Record<'static>>);

impl std::ops::Deref for Trace {
    type Target = [Record<'static>];
    fn deref(&self) -> &Self::Target {
        &self.0
    }
}

impl Trace {
    /// The records of a trace file's text, one a line: every line must be a whole record.
    #[track_caller]
    pub fn parse(text: &str) -> Trace {
        Trace(
            text.lines()
                .enumerate()
                .map(|(i, line)| {
                    serde_json::from_str(line).unwrap_or_else(|e| {
                        panic!("line {} is not a record of the trace ({e}): {line}", i + 1)
                    })
                })
                .collect(),
        )
    }

    /// The records of the trace file at `path`.
    #[track_caller]
    pub fn read(path: &Path) -> Trace {
        let text = std::fs::read_to_string(path)
            .unwrap_or_else(|e| panic!("the trace {}: {e}", path.display()));
        Trace::parse(&text)
    }

    /// `record` as a line of the trace file says it, read back.
    pub fn line(record: &Record<'_>) -> Record<'static> {
        let line = serde_json::to_string(record).expect("an event is JSON");
        serde_json::from_str(&line).unwrap_or_else(|e| panic!("{e}: {line} does not read back"))
    }

    /// The records whose event `is`.
    pub fn find(&self, is: impl Fn(&Event) -> bool) -> Vec<&Record<'static>> {
        self.iter().filter(|r| is(&r.event)).collect()
    }

    /// The records of one kind of event.
    pub fn events(&self, kind: EventKind) -> Vec<&Record<'static>> {
        self.find(|e| e.kind() == kind)
    }

    /// The first record whose event `is`.
    #[track_caller]
    pub fn first(&self, is: impl Fn(&Event) -> bool) -> &Record<'static> {
        &self[self.index(is)]
    }

    /// The time of the first such event.
    #[track_caller]
    pub fn t(&self, is: impl Fn(&Event) -> bool) -> f64 {
        self.first(is).t
    }

    /// The index of the first such event in the trace.
    #[track_caller]
    pub fn index(&self, is: impl Fn(&Event) -> bool) -> usize {
        self.iter()
            .position(|r| is(&r.event))
            .unwrap_or_else(|| panic!("no such event in the trace:\n{}", self.dump()))
    }

    /// How each activity of `capability` on `actor` ended, in order.
    pub fn ends(&self, capability: &str, actor: &str) -> Vec<End<'_>> {
        self.iter()
            .filter_map(|r| match &r.event {
                Event::CapabilityEnd { actor: a, capability: c, args, status, .. }
                    if c == capability && a == actor =>
                {
                    Some(End { t: r.t, status: *status, args })
                }
                _ => None,
            })
            .collect()
    }

    /// Telemetry positions of a drone, by time.
    pub fn positions(&self, actor: &str) -> Vec<(f64, [f64; 3])> {
        positions_in(self, actor)
    }

    /// The trace as its file has it, one event a line.
    pub fn dump(&self) -> String {
        self.iter()
            .map(|r| serde_json::to_value(r).expect("an event is JSON").to_string())
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// How an activity ended (a `capability_end`): when, how, and the values it was given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct End<'r> {
    pub t: f64,
    pub status: Status,
    pub args: &'r Params<'static>,
}

/// Telemetry positions of a drone in a trace, by time.
pub fn positions_in(trace: &[Record<'static>], actor: &str) -> Vec<(f64, [f64; 3])> {
    trace
        .iter()
        .filter_map(|r| match &r.event {
            Event::Telemetry { actor: a, position, .. } if a == actor => {
                assert!(position.iter().all(|c| c.is_finite()), "a position unknown: {r:?}");
                Some((r.t, *position))
            }
            _ => None,
        })
        .collect()
}

/// The lookups most tests make, as predicates for [`Trace::find`] and the others.
pub mod is {
    use super::*;

    /// A `signal` of that name.
    pub fn signal(name: &str) -> impl Fn(&Event) -> bool + '_ {
        move |e| matches!(e, Event::Signal { name: n, .. } if n == name)
    }

    /// An `exception` of that name.
    pub fn exception(name: &str) -> impl Fn(&Event) -> bool + '_ {
        move |e| matches!(e, Event::Exception { name: n, .. } if n == name)
    }

    /// A `capability_start` of that capability.
    pub fn start_of(capability: &str) -> impl Fn(&Event) -> bool + '_ {
        move |e| matches!(e, Event::CapabilityStart { capability: c, .. } if c == capability)
    }

    /// A `capability_start` of an activity of that actor.
    pub fn start_by(actor: &str) -> impl Fn(&Event) -> bool + '_ {
        move |e| matches!(e, Event::CapabilityStart { actor: a, .. } if a == actor)
    }

    /// A `capability_end` of that capability.
    pub fn end_of(capability: &str) -> impl Fn(&Event) -> bool + '_ {
        move |e| matches!(e, Event::CapabilityEnd { capability: c, .. } if c == capability)
    }

    /// The `block_end` of that block.
    pub fn block_end(block: &str) -> impl Fn(&Event) -> bool + '_ {
        move |e| matches!(e, Event::BlockEnd { block: b, .. } if b == block)
    }

    /// A `handler_start` for that signal.
    pub fn handler_start(signal: &str) -> impl Fn(&Event) -> bool + '_ {
        move |e| matches!(e, Event::HandlerStart { signal: s, .. } if s == signal)
    }

    /// An `api_call` of that function (by any drone).
    pub fn call(function: Function) -> impl Fn(&Event) -> bool {
        move |e| matches!(e, Event::ApiCall { function: f, .. } if *f == function)
    }

    /// An `api_done` of that function (by any drone).
    pub fn done(function: Function) -> impl Fn(&Event) -> bool {
        move |e| matches!(e, Event::ApiDone { function: f, .. } if *f == function)
    }
}

/// The drone (or drones, by name, separated by spaces) an event is of, if it names one.
pub fn actor<'e>(event: &'e Event) -> Option<&'e str> {
    match event {
        Event::CapabilityStart { actor, .. }
        | Event::CapabilityEnd { actor, .. }
        | Event::ApiCall { actor, .. }
        | Event::ApiDone { actor, .. }
        | Event::Detection { actor, .. }
        | Event::Telemetry { actor, .. }
        | Event::Autopilot { actor, .. } => Some(actor),
        Event::HandlerStart { actor, .. }
        | Event::HandlerEnd { actor, .. }
        | Event::Signal { actor, .. }
        | Event::Exception { actor, .. } => actor.as_deref(),
        _ => None,
    }
}
