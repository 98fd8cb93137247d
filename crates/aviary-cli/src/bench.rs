//! `aviary bench parse`: generates a large mission and its world
//! (`aviary_bench::generate`), then times parsing alone and parse + check through the
//! same pipeline as `aviary check` (source map, world, `aviary_check::check`), and
//! prints each run and the median throughput. MB here is 10^6 bytes.
//! `aviary bench w` and `aviary bench swarm` (in `bench/`) run generated missions
//! through the whole pipeline.

mod front;
mod pipeline;
mod swarm;
mod w;

use std::time::{Duration, Instant};

use aviary_api::Descriptor;
// The generated missions USE nothing, so nothing is served.
use aviary_check::NoFiles;
use aviary_diagnostics::{FileId, SourceMap};
use clap::Subcommand;

pub(crate) const MB: f64 = 1_000_000.0;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// Parse and check a generated mission of about M megabytes (10^6 bytes)
    Parse {
        /// The size of the generated mission, in MB
        #[arg(long, default_value_t = 5.0)]
        mb: f64,
        /// How many timed runs; the median is reported
        #[arg(long, default_value_t = 5)]
        runs: usize,
    },
    /// The engine benchmark W(N, K) in the language: N actors in parallel, K steps each,
    /// then `Done` to one handler; prints wall time, peak memory and where the time went
    W {
        /// Actors (drones in the world's one group)
        #[arg(long, default_value_t = 100_000)]
        n: usize,
        /// Steps per actor
        #[arg(long, default_value_t = 10)]
        k: usize,
        /// Print the generated mission instead of running it
        #[arg(long)]
        emit: bool,
        /// Print the generated world instead of running it
        #[arg(long)]
        emit_world: bool,
        /// Build every trace event (as `aviary run --trace` does), not only those checked
        #[arg(long)]
        full_trace: bool,
    },
    /// All of `aviary check` (parse, check, compile, conflicts, plan) on a generated
    /// mission of a shape that once made the analyses quadratic; prints MB/s
    Front {
        /// `sequential`: N statements in one SEQUENTIAL block on one drone; `chain`: N
        /// capabilities, each calling the next; `realistic`: the mission of `bench parse`, of
        /// N MB
        #[arg(long, value_enum, default_value = "sequential")]
        shape: front::Shape,
        /// Statements, capabilities, or MB (realistic)
        #[arg(long, default_value_t = 100_000)]
        n: usize,
        /// How many timed runs; the median is reported
        #[arg(long, default_value_t = 3)]
        runs: usize,
        /// Print the generated mission instead of timing it (for `aviary check` on a file)
        #[arg(long)]
        emit: bool,
        /// Print the generated world instead of timing it
        #[arg(long)]
        emit_world: bool,
    },
    /// N simulated drones, each sweeping its own area with detection on; prints
    /// simulated seconds per wall second
    Swarm {
        #[arg(long, default_value_t = 10_000)]
        drones: usize,
        /// Print the generated mission instead of running it
        #[arg(long)]
        emit: bool,
        /// Print the generated world instead of running it
        #[arg(long)]
        emit_world: bool,
    },
}

pub fn run(which: BenchCommand) -> u8 {
    match which {
        BenchCommand::Parse { mb, runs } => parse(mb, runs),
        BenchCommand::W { n, k, emit, emit_world, full_trace } => {
            w::run(n, k, emit, emit_world, full_trace)
        }
        BenchCommand::Swarm { drones, emit, emit_world } => swarm::run(drones, emit, emit_world),
        BenchCommand::Front { shape, n, runs, emit, emit_world } => {
            front::run(shape, n, runs, emit, emit_world)
        }
    }
}

fn parse(mb: f64, runs: usize) -> u8 {
    if !(mb.is_finite() && mb > 0.0) || mb > 4000.0 {
        eprintln!("aviary: --mb must be a size in megabytes, above 0 and at most 4000");
        return 2;
    }
    let runs = runs.max(1);
    let started = Instant::now();
    let (mission, world) = aviary_bench::generate::large_mission((mb * MB) as usize);
    let size = mission.len();
    outln!(
        "generated a mission of {:.2} MB ({size} bytes, {} lines, {} capabilities) and a world of {} drones in {:.2} s",
        size as f64 / MB,
        mission.lines().count(),
        mission.matches("\nCAPABILITY ").count(),
        aviary_bench::generate::DRONES,
        started.elapsed().as_secs_f64()
    );

    // One run outside the timings, to say what the checker thinks of the mission.
    let (errors, others) = parse_and_check(&mission, &world);
    if errors > 0 || others > 0 {
        outln!("note: the check reports {errors} error(s) and {others} other diagnostic(s); the generator should give none");
    }

    let mut parse_times = Vec::with_capacity(runs);
    let mut check_times = Vec::with_capacity(runs);
    for run in 1..=runs {
        // Parse alone: lexing, layout and parsing into the tree (dropping the tree is
        // not timed here; it is in parse + check, as it is in `aviary check`).
        let start = Instant::now();
        let parsed = std::hint::black_box(aviary_syntax::parse(FileId(0), &mission));
        let parse_time = start.elapsed();
        drop(parsed);

        let start = Instant::now();
        std::hint::black_box(parse_and_check(&mission, &world));
        let check_time = start.elapsed();

        outln!(
            "run {run}: parse {:.3} s ({:.1} MB/s); parse + check {:.3} s ({:.1} MB/s)",
            parse_time.as_secs_f64(),
            rate(size, parse_time),
            check_time.as_secs_f64(),
            rate(size, check_time)
        );
        parse_times.push(parse_time);
        check_times.push(check_time);
    }
    let parse_median = median(&mut parse_times);
    let check_median = median(&mut check_times);
    outln!(
        "median of {runs} run(s) over {:.2} MB: parse {:.1} MB/s ({:.3} s); parse + check {:.1} MB/s ({:.3} s)",
        size as f64 / MB,
        rate(size, parse_median),
        parse_median.as_secs_f64(),
        rate(size, check_median),
        check_median.as_secs_f64()
    );
    0
}

/// What `aviary check` does with a mission and its world, minus reading and printing:
/// the number of errors and of other diagnostics.
fn parse_and_check(mission: &str, world_text: &str) -> (usize, usize) {
    let mut sources = SourceMap::new();
    let checked = aviary_check::check_sources(
        &mut sources,
        ("generated.mission", mission.as_bytes()),
        Some(("generated.world.toml", world_text.as_bytes())),
        &NoFiles,
        &Descriptor::standard(),
    );
    let errors = checked.diagnostics.iter().filter(|d| d.is_error()).count();
    (errors, checked.diagnostics.len() - errors)
}

pub(crate) fn rate(bytes: usize, time: Duration) -> f64 {
    bytes as f64 / MB / time.as_secs_f64().max(1e-9)
}

pub(crate) fn median(times: &mut [Duration]) -> Duration {
    times.sort_unstable();
    let n = times.len();
    if n % 2 == 1 {
        times[n / 2]
    } else {
        (times[n / 2 - 1] + times[n / 2]) / 2
    }
}
