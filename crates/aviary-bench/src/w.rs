//! `aviary bench w --n N --k K`: the engine benchmark W(N, K) of
//! docs/BENCHMARKS.md, written in the language
//! ([`crate::generate::w_mission`]) and run through the whole pipeline of `aviary run`.
//! The sink checks from the trace that the work was done: N `Done` signals, each taken
//! by the handler, whose indices sum to N(N-1)/2 (and, with `--full-trace`, N·K steps
//! that ended ok). By default it asks the engine only for the events it checks
//! (`TraceSink::wants`), and reads their fields where the engine made them: writing the
//! other 40-odd lines per actor that `aviary run --trace` writes would measure
//! serde_json, not the language. `--full-trace` takes every event and writes each line
//! as `aviary run --trace` does (to memory).

use std::io::Write;
use std::time::Instant;

use aviary_api::trace::{Event, EventKind, Record, Shown, Status};
use aviary_engine::TraceSink;

use crate::stages::{self, mib, peak_rss, Stages};
use crate::{Emit, Error};

/// Counts what W must have done, from the trace.
#[derive(Default)]
struct Tally {
    full: bool,
    done_signals: u64,
    index_sum: u64,
    handled: u64,
    steps: u64,
    events: u64,
    /// With `--full-trace`: the line each event is written to, as `aviary run --trace`
    /// writes it.
    line: Vec<u8>,
}

impl TraceSink for Tally {
    fn wants(&self, kind: EventKind) -> bool {
        self.full || matches!(kind, EventKind::Signal | EventKind::HandlerStart)
    }

    fn record(&mut self, record: &Record<'_>) {
        self.events += 1;
        if self.full {
            self.line.clear();
            if serde_json::to_writer(&mut self.line, record).is_ok() {
                self.line.push(b'\n');
            }
        }
        match &record.event {
            Event::Signal { name, args, .. } if name == "Done" => {
                self.done_signals += 1;
                let index = args.first().and_then(Shown::as_number);
                self.index_sum += index.unwrap_or(f64::NAN) as u64;
            }
            Event::HandlerStart { signal, .. } if signal == "Done" => self.handled += 1,
            Event::CapabilityEnd { capability, status: Status::Ok, .. } if capability == "Step" => {
                self.steps += 1
            }
            _ => {}
        }
    }
}

/// W(`n`, `k`); with `full_trace`, every event built and written as a trace line; or,
/// with `emit`, the mission or its world instead.
pub fn w(
    n: usize,
    k: usize,
    emit: Emit,
    full_trace: bool,
    out: &mut dyn Write,
) -> Result<(), Error> {
    if n == 0 || k == 0 {
        return Err(Error::Usage("--n and --k must be at least 1".into()));
    }
    let started = Instant::now();
    let mut stages = Stages::default();
    let mission = stages.time("generate", || crate::generate::w_mission(k));
    if emit == Emit::Mission {
        return Ok(write!(out, "{mission}")?);
    }
    let world = stages.time("generate", || crate::generate::w_world(n));
    if emit == Emit::World {
        return Ok(write!(out, "{world}")?);
    }
    let mut tally = Tally { full: full_trace, ..Tally::default() };
    let ran = stages::fly(mission, world, &mut tally, &mut stages)
        .map_err(|why| Error::Failed(format!("the W mission did not run:\n{why}")))?;
    let wall = started.elapsed().as_secs_f64();
    let (n64, k64) = (n as u64, k as u64);
    let ok = ran.outcome.status == aviary_engine::Status::Ok
        && tally.done_signals == n64
        && tally.handled == n64
        && tally.index_sum == n64 * (n64 - 1) / 2
        && (!full_trace || tally.steps == n64 * k64);
    let steps = if full_trace { format!(" steps={}", tally.steps) } else { String::new() };
    writeln!(
        out,
        "aviary W N={n} K={k} done={} handled={} sum={}{steps} ok={ok} elapsed={wall:.3}s peak={}",
        tally.done_signals,
        tally.handled,
        tally.index_sum,
        mib(peak_rss())
    )?;
    writeln!(out, "stages: {}; {} trace events", stages.show(), tally.events)?;
    if ok {
        Ok(())
    } else {
        Err(Error::NotOk)
    }
}
