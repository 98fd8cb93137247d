//! `aviary bench swarm --drones N`: N simulated drones, each sweeping its own cell with
//! detection on, with handlers for the finds (`aviary_bench::generate::swarm_mission`),
//! through the whole pipeline at `--speed max`. Prints simulated seconds per wall second
//! of the engine and simulator run.

use std::time::Instant;

use aviary_api::trace::{Event, Record};

use super::pipeline::{self, mib, peak_rss, Stages};

#[derive(Default)]
struct Tally {
    detections: u64,
    found_handled: u64,
    events: u64,
}

pub fn run(drones: usize, emit: bool, emit_world: bool) -> u8 {
    if drones == 0 {
        eprintln!("aviary: --drones must be at least 1");
        return 2;
    }
    let started = Instant::now();
    let mut stages = Stages::default();
    let mission = stages.time("generate", || aviary_bench::generate::swarm_mission(drones));
    if emit {
        out!("{mission}");
        return 0;
    }
    let world = stages.time("generate", || aviary_bench::generate::swarm_world(drones));
    if emit_world {
        out!("{world}");
        return 0;
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
    let ran = match pipeline::run(mission, world, &mut sink, &mut stages) {
        Ok(r) => r,
        Err(why) => {
            eprintln!("aviary: the swarm mission did not run:\n{why}");
            return 1;
        }
    };
    let flying = stages.get("engine + sim").map_or(0.0, |d| d.as_secs_f64());
    let ok =
        ran.outcome.status == aviary_engine::Status::Ok && tally.found_handled == tally.detections;
    outln!(
        "aviary swarm drones={drones} status={} simulated={:.1}s engine+sim wall={flying:.3}s speed={:.1}x real time; detections={} handled={} ok={ok}; whole process {:.3}s peak={}",
        ran.outcome.status.as_str(),
        ran.simulated,
        ran.simulated / flying.max(1e-9),
        tally.detections,
        tally.found_handled,
        started.elapsed().as_secs_f64(),
        mib(peak_rss())
    );
    outln!("stages: {}; {} trace events", stages.show(), tally.events);
    u8::from(!ok)
}
