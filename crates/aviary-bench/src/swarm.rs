//! `aviary bench swarm --drones N`: N simulated drones, each sweeping its own cell with
//! detection on, with handlers for the finds ([`crate::generate::swarm_mission`]),
//! through the whole pipeline of `aviary run` at `--speed max`. Prints simulated seconds per wall second
//! of the engine and simulator run.

use std::io::Write;
use std::time::Instant;

use aviary_api::trace::{Event, Record};

use crate::stages::{self, mib, peak_rss, Stages};
use crate::{Emit, Error};

#[derive(Default)]
struct Tally {
    detections: u64,
    found_handled: u64,
    events: u64,
}

/// `drones` drones sweeping; or, with `emit`, the mission or its world instead.
pub fn swarm(drones: usize, emit: Emit, out: &mut dyn Write) -> Result<(), Error> {
    if drones == 0 {
        return Err(Error::Usage("--drones must be at least 1".into()));
    }
    let started = Instant::now();
    let mut stages = Stages::default();
    let mission = stages.time("generate", || crate::generate::swarm_mission(drones));
    if emit == Emit::Mission {
        return Ok(write!(out, "{mission}")?);
    }
    let world = stages.time("generate", || crate::generate::swarm_world(drones));
    if emit == Emit::World {
        return Ok(write!(out, "{world}")?);
    }
    let mut tally = Tally::default();
    let mut sink = |r: &Record| {
        tally.events += 1;
        match &r.event {
            Event::Detection { .. } => tally.detections += 1,
            Event::HandlerStart { signal, .. } if signal == "Found" => tally.found_handled += 1,
            _ => {}
        }
    };
    let ran = stages::fly(mission, world, &mut sink, &mut stages)
        .map_err(|why| Error::Failed(format!("the swarm mission did not run:\n{why}")))?;
    let flying = stages.get("engine + sim").map_or(0.0, |d| d.as_secs_f64());
    let ok =
        ran.outcome.status == aviary_engine::Status::Ok && tally.found_handled == tally.detections;
    writeln!(
        out,
        "aviary swarm drones={drones} status={} simulated={:.1}s engine+sim wall={flying:.3}s speed={:.1}x real time; detections={} handled={} ok={ok}; whole process {:.3}s peak={}",
        ran.outcome.status.as_str(),
        ran.simulated,
        ran.simulated / flying.max(1e-9),
        tally.detections,
        tally.found_handled,
        started.elapsed().as_secs_f64(),
        mib(peak_rss())
    )?;
    writeln!(out, "stages: {}; {} trace events", stages.show(), tally.events)?;
    if ok {
        Ok(())
    } else {
        Err(Error::NotOk)
    }
}
