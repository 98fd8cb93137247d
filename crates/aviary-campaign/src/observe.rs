//! What one run comes to, heard from its events as they are made (no trace is written):
//! [`Observer`] gathers it, and [`Observer::finish`] sums it up as a [`RunRecord`].

use aviary_api::trace::{Event, EventKind, Record, Status};
use aviary_api::{Backend, DroneId};
use aviary_diagnostics::SourceMap;
use aviary_engine::Outcome;
use aviary_ir::{Mission, Origin};
use aviary_world::Expectation;
use serde::{Deserialize, Serialize};

/// One run of a campaign, as its report keeps it: enough to make every figure of the
/// report again (`aviary test merge`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    pub seed: u64,
    /// `ok`, `failed` or `aborted`: the mission's own end, as `aviary run` prints it.
    pub status: Status,
    pub reason: Option<String>,
    /// Mission time at the end, in seconds (the fleet home).
    pub time: f64,
    /// Each drone's lowest battery reading, a fraction, in the world's order of drones.
    pub lowest_battery: Vec<f64>,
    /// How many targets were found (each counted once, however many drones saw it).
    pub found: u64,
    /// Whether the run met each expectation of `[expect]`, in its order.
    pub expectations: Vec<bool>,
    /// The mission ended `ok` and met every expectation.
    pub success: bool,
    /// Where and how it failed, when the mission did not end `ok`.
    pub failure: Option<Failure>,
}

/// How a run failed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    /// The unhandled exception that failed it, if one did.
    pub exception: Option<String>,
    /// The drone it was raised on (none for a `THROW` at mission level).
    pub drone: Option<String>,
    /// The statement it was raised at (`Outcome::at`).
    pub statement: Option<Statement>,
    /// Where the drone was then, local metres.
    pub position: Option<[f64; 3]>,
}

/// A place in a mission's text.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Statement {
    pub file: String,
    pub line: usize,
    pub column: usize,
    /// Byte offsets of its span in the file.
    pub span: [u32; 2],
}

impl std::fmt::Display for Statement {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

impl Statement {
    pub fn of(origin: Origin, sources: &SourceMap) -> Statement {
        let at = sources.line_col(origin.file, origin.span.start);
        Statement {
            file: sources.name(origin.file).to_owned(),
            line: at.line,
            column: at.column,
            span: [origin.span.start, origin.span.end],
        }
    }
}

/// The kinds of event an [`Observer`] reads; the engine makes no other (`TraceSink::wants`).
pub fn wants(kind: EventKind) -> bool {
    matches!(kind, EventKind::Exception | EventKind::Detection | EventKind::MissionEnd)
}

/// What one run did, as it goes.
pub struct Observer {
    drones: aviary_api::Names,
    lowest: Vec<f64>,
    /// Each find once: its kind and where (the bits of its coordinates).
    finds: Vec<(String, [u64; 3])>,
    /// The first unhandled exception: its name, drone and the drone's position then.
    unhandled: Option<(String, Option<String>, Option<[f64; 3]>)>,
    end: f64,
}

impl Observer {
    pub fn new(mission: &Mission) -> Observer {
        Observer {
            drones: mission.drones.clone(),
            lowest: vec![f64::INFINITY; mission.drones.len()],
            finds: Vec::new(),
            unhandled: None,
            end: 0.0,
        }
    }

    fn battery(&mut self, actor: &str, backend: &dyn Backend) -> [f64; 3] {
        let Some(d) = self.drones.position(actor) else { return [f64::NAN; 3] };
        let t = backend.telemetry(d);
        if let Some(low) = self.lowest.get_mut(d.0) {
            *low = low.min(t.battery);
        }
        t.position
    }

    pub fn record(&mut self, record: &Record<'_>, backend: &dyn Backend) {
        match &record.event {
            Event::Detection { actor, kind, location } => {
                self.battery(actor, backend);
                let key = (kind.to_string(), location.map(f64::to_bits));
                if !self.finds.contains(&key) {
                    self.finds.push(key);
                }
            }
            Event::Exception { name, actor, handled: false, during: None, .. } => {
                let position = actor.as_deref().map(|a| self.battery(a, backend));
                if self.unhandled.is_none() {
                    let actor = actor.as_deref().map(str::to_owned);
                    self.unhandled = Some((name.to_string(), actor, position));
                }
            }
            Event::MissionEnd { .. } => self.end = record.t,
            _ => {}
        }
    }

    /// The fleet is home: each drone's battery now.
    pub fn landed(&mut self, backend: &dyn Backend) {
        for (d, low) in self.lowest.iter_mut().enumerate() {
            *low = low.min(backend.telemetry(DroneId(d)).battery);
        }
    }

    /// The run's record. `sources`: the texts `outcome.at` points into, when kept.
    pub fn finish(
        self,
        seed: u64,
        outcome: &Outcome,
        expect: &[Expectation],
        targets: usize,
        sources: Option<&SourceMap>,
    ) -> RunRecord {
        let found = self.finds.len() as u64;
        let lowest = self.lowest.iter().copied().fold(f64::INFINITY, f64::min);
        let expectations: Vec<bool> =
            expect.iter().map(|e| met(*e, found, targets, self.end, lowest)).collect();
        let failure = (outcome.status != Status::Ok).then(|| {
            let (exception, drone, position) = match self.unhandled {
                Some((name, drone, position)) => (Some(name), drone, position),
                None => (None, None, None),
            };
            Failure {
                exception,
                drone,
                statement: outcome.at.zip(sources).map(|(at, s)| Statement::of(at, s)),
                position: position.filter(|p| p.iter().all(|x| x.is_finite())),
            }
        });
        RunRecord {
            seed,
            status: outcome.status,
            reason: outcome.reason.clone(),
            time: self.end,
            lowest_battery: self
                .lowest
                .iter()
                .map(|b| if b.is_finite() { *b } else { 1.0 })
                .collect(),
            found,
            success: outcome.status == Status::Ok && expectations.iter().all(|m| *m),
            expectations,
            failure,
        }
    }
}

/// Whether a run met `e`: it found `found` of the world's `targets`, ended at `time` with
/// `lowest` the lowest battery of any drone.
pub fn met(e: Expectation, found: u64, targets: usize, time: f64, lowest: f64) -> bool {
    match e {
        Expectation::AllFound => found >= targets as u64,
        Expectation::MinFound(k) => found >= k,
        Expectation::MaxTime(s) => time <= s,
        Expectation::MinBattery(b) => lowest >= b,
    }
}
