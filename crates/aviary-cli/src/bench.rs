//! `aviary bench`: the arguments of the benchmarks, which `aviary_bench` runs and
//! reports (docs/BENCHMARKS.md): `parse` (the front end), `front` (all of `aviary check`),
//! `w` (the engine) and `swarm` (the simulator); and `lsp` (the language server: an
//! edit's time to its diagnostics), which `aviary_lsp::bench` times on a mission of
//! `aviary_bench`'s generator. Here only what the command line says and where the report
//! goes.

use aviary_bench::{Emit, Error};
use clap::{Subcommand, ValueEnum};

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
        shape: Shape,
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
    /// The language server: the time from an edit of a generated mission of N lines to
    /// its diagnostics, through the protocol; prints the median and the slowest
    Lsp {
        /// The mission's lines at least (whole waves of the `parse` mission are written)
        #[arg(long, default_value_t = 5000)]
        lines: usize,
        /// How many timed edits
        #[arg(long, default_value_t = 21)]
        runs: usize,
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
    /// A campaign (`aviary test`) of the paper's mission, examples/search_and_rescue.mission:
    /// N seeds at once; prints the wall time and runs per second
    Campaign {
        #[arg(long, default_value_t = 1000)]
        runs: u64,
        /// Runs at once (default: the number of cores)
        #[arg(long)]
        jobs: Option<usize>,
        /// Another world for the paper's mission (default: its own, examples/search_and_rescue.world.toml)
        #[arg(long, value_name = "FILE")]
        world: Option<std::path::PathBuf>,
    },
}

/// The threads of `bench campaign`: the machine's cores unless told.
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The generated mission's shape (`aviary_bench::Shape`).
#[derive(Clone, Copy, ValueEnum)]
pub enum Shape {
    /// N statements in one SEQUENTIAL block, all on one drone
    Sequential,
    /// N capabilities, each calling the next
    Chain,
    /// The realistic mission of `aviary bench parse`, of N MB
    Realistic,
}

pub fn run(which: BenchCommand) -> u8 {
    let out = &mut crate::out::Stdout;
    let ran = match which {
        BenchCommand::Parse { mb, runs } => aviary_bench::parse(mb, runs, out),
        BenchCommand::W { n, k, emit, emit_world, full_trace } => {
            aviary_bench::w(n, k, Emit::of(emit, emit_world), full_trace, out)
        }
        BenchCommand::Swarm { drones, emit, emit_world } => {
            aviary_bench::swarm(drones, Emit::of(emit, emit_world), out)
        }
        BenchCommand::Campaign { runs, jobs, world } => {
            let world = match world.as_deref().map(std::fs::read_to_string).transpose() {
                Ok(w) => w,
                Err(e) => {
                    eprintln!("aviary: cannot read the world file: {e}");
                    return 2;
                }
            };
            aviary_bench::campaign(runs, jobs.unwrap_or_else(cores), world.as_deref(), out)
        }
        BenchCommand::Front { shape, n, runs, emit, emit_world } => {
            let shape = match shape {
                Shape::Sequential => aviary_bench::Shape::Sequential,
                Shape::Chain => aviary_bench::Shape::Chain,
                Shape::Realistic => aviary_bench::Shape::Realistic,
            };
            aviary_bench::front(shape, n, runs, Emit::of(emit, emit_world), out)
        }
        BenchCommand::Lsp { lines, runs } => lsp(lines, runs),
    };
    match ran {
        Ok(()) => 0,
        Err(Error::Usage(why)) => {
            eprintln!("aviary: {why}");
            2
        }
        Err(Error::Failed(why)) => {
            eprintln!("aviary: {why}");
            1
        }
        Err(Error::NotOk) => 1,
        // `Stdout` says a failure itself, once, and then takes every write.
        Err(Error::Write(e)) => {
            eprintln!("aviary: cannot write to standard output: {e}");
            2
        }
    }
}

/// `aviary bench lsp`: the generated mission of at least `lines` lines, its edits timed.
fn lsp(lines: usize, runs: usize) -> Result<(), Error> {
    if lines == 0 || runs == 0 {
        return Err(Error::Usage("--lines and --runs must be at least 1".into()));
    }
    let mut bytes = lines * 30;
    let (mission, world) = loop {
        let (m, w) = aviary_bench::generate::large_mission(bytes);
        if m.lines().count() >= lines {
            break (m, w);
        }
        bytes += bytes / 4;
    };
    let timings = aviary_lsp::bench::edits(&mission, &world, runs).map_err(Error::Failed)?;
    if timings.errors > 0 {
        return Err(Error::Failed(format!(
            "the generated mission has {} errors after the edits",
            timings.errors
        )));
    }
    let mut sorted = timings.edits.clone();
    sorted.sort_unstable();
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1000.0;
    outln!(
        "lsp: {} lines, {} bytes, {} warnings and notes; edit to diagnostics over {runs} edits: median {:.1} ms, slowest {:.1} ms",
        mission.lines().count(),
        mission.len(),
        timings.diagnostics,
        ms(sorted[sorted.len() / 2]),
        ms(sorted[sorted.len() - 1])
    );
    Ok(())
}
