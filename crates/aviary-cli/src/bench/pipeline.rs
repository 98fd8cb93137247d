//! The whole pipeline of `aviary run`, from text to the end of the mission, with the time
//! each stage takes: world (TOML to `World`), check (parse, load, infer, walk), compile,
//! simulator start (the physics core of every drone) and the engine's run.

use std::time::{Duration, Instant};

use aviary_check::NoFiles;
use aviary_diagnostics::{render_text, SourceMap};
use aviary_engine::{Outcome, RunOptions, TraceSink};
use aviary_sim::{Fleet, SimBackend, SimOptions};

/// Wall time of each stage, in order, and the peak RSS once it had run.
#[derive(Default)]
pub struct Stages(pub Vec<(&'static str, Duration, Option<u64>)>);

impl Stages {
    pub fn time<R>(&mut self, name: &'static str, f: impl FnOnce() -> R) -> R {
        let start = Instant::now();
        let r = f();
        self.0.push((name, start.elapsed(), peak_rss()));
        r
    }

    /// `world 0.012 s (peak 20.1 MiB), check 0.030 s (peak ...), ...`
    pub fn show(&self) -> String {
        self.0
            .iter()
            .map(|(n, d, p)| format!("{n} {:.3} s (peak {})", d.as_secs_f64(), mib(*p)))
            .collect::<Vec<_>>()
            .join(", ")
    }

    pub fn get(&self, name: &str) -> Option<Duration> {
        self.0.iter().find(|s| s.0 == name).map(|s| s.1)
    }
}

/// What the engine's run gave, and the simulated seconds it took.
pub struct Ran {
    pub outcome: Outcome,
    pub simulated: f64,
}

/// Checks, compiles and runs `mission` in `world` on the simulator (at `--speed max`),
/// feeding every trace event to `sink`. Every stage really runs; a mission with errors
/// is refused, as `aviary run` refuses it. As in `aviary run`, the source texts go once
/// the mission checks clean, and the simulator's fleet takes the world's drones where
/// they lie ([`aviary_sim::Fleet::from_world`]).
/// The texts are handed over (to the source map), not copied: a large world's text is
/// megabytes.
pub fn run(
    mission: String,
    world: String,
    sink: &mut dyn TraceSink,
    stages: &mut Stages,
) -> Result<Ran, String> {
    let api = aviary_sim::descriptor();
    let mut sources = SourceMap::new();
    let wid = sources.add("bench.world.toml", world);
    let (world, diags) = stages.time("world", || aviary_world::parse_world(wid, sources.text(wid)));
    let Some(world) = world else { return Err(render(&sources, &diags)) };
    let root = sources.add("bench.mission", mission);
    let (program, diags) = stages
        .time("check", || aviary_check::check(&mut sources, root, Some(&world), &NoFiles, &api));
    if diags.iter().any(|d| d.is_error()) {
        return Err(render(&sources, &diags));
    }
    // The source texts are needed only to show errors.
    let freeing = Instant::now();
    drop(sources);
    crate::alloc::give_back();
    let texts_freed = freeing.elapsed();
    let compiled = stages.time("compile", || aviary_lower::compile(&program, &world, &api));
    let Some(compiled) = compiled else { return Err("the mission has no MISSION".into()) };
    // The tree is not needed to fly either.
    let freeing = Instant::now();
    drop(program);
    stages.0.push(("free front end", texts_freed + freeing.elapsed(), peak_rss()));
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_time()
        .start_paused(true)
        .build()
        .map_err(|e| format!("cannot start the runtime: {e}"))?;
    runtime.block_on(async {
        let sim = stages.time("sim start", || {
            SimBackend::start_with(Fleet::from_world(world), SimOptions::default())
        });
        let outcome = {
            let start = Instant::now();
            let outcome = aviary_engine::run(&compiled, &*sim, sink, &RunOptions::default()).await;
            stages.0.push(("engine + sim", start.elapsed(), peak_rss()));
            outcome
        };
        sim.stop();
        Ok(Ran { outcome, simulated: sim.time() })
    })
}

fn render(sources: &SourceMap, diags: &[aviary_diagnostics::Diagnostic]) -> String {
    diags.iter().filter(|d| d.is_error()).take(5).map(|d| render_text(sources, d, false)).collect()
}

/// The peak resident set of this process so far, in bytes: `VmHWM` of
/// `/proc/self/status` (Linux), the same figure as `/usr/bin/time -f %M`.
pub fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

pub fn mib(bytes: Option<u64>) -> String {
    bytes.map_or_else(|| "unknown".into(), |b| format!("{:.1} MiB", b as f64 / (1024.0 * 1024.0)))
}
