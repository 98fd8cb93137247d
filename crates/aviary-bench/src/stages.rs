//! The scale benchmarks' run: the pipeline of `aviary run` (`aviary_pipeline::fly`), from
//! text to the end of the mission, with the time each stage takes: world (TOML to
//! `World`), check (parse, load, infer, walk), compile, free front end, simulator start
//! (the physics core of every drone) and the engine's run.

use std::time::{Duration, Instant};

use aviary_api::trace::{EventKind, Record};
use aviary_api::Backend;
use aviary_diagnostics::{render_text, SourceMap};
use aviary_engine::TraceSink;
use aviary_pipeline::pipeline::{Flown, Hooks, NotFlown, Options, Source, Stage, Texts};

use aviary_check::NoFiles;

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

/// Checks, compiles and runs `mission` in `world` on the simulator (at `--speed max`),
/// through `aviary_pipeline::fly` as `aviary run` does, feeding every trace event to
/// `sink` and timing each stage into `stages`. A mission with errors is refused, as
/// `aviary run` refuses it. The texts are handed over, not copied: a large world's text
/// is megabytes.
pub fn fly(
    mission: String,
    world: String,
    sink: &mut dyn TraceSink,
    stages: &mut Stages,
) -> Result<Flown, String> {
    let texts = Texts {
        mission: Source { name: "bench.mission", bytes: mission.into_bytes() },
        world: Source { name: "bench.world.toml", bytes: world.into_bytes() },
        files: &NoFiles,
    };
    let mut timed = Timed { stages, sink, began: None, freeing: Duration::ZERO };
    aviary_pipeline::fly(texts, &Options::default(), &mut timed).map_err(|why| match why {
        NotFlown::Errors { diagnostics, sources } => render(&sources, &diagnostics),
        NotFlown::NoMission => "the mission has no MISSION".into(),
        NotFlown::Speed => "a speed was given for MAVLink drones".into(),
        NotFlown::Failed(why) => why,
    })
}

/// The pipeline's hooks for a benchmark: each stage timed, each event to the sink.
struct Timed<'a> {
    stages: &'a mut Stages,
    sink: &'a mut dyn TraceSink,
    began: Option<Instant>,
    /// Freeing the texts, which counts with freeing the tree: one stage, `free front end`.
    freeing: Duration,
}

impl Hooks for Timed<'_> {
    /// As `aviary run` does: the benchmark measures the process as the command runs it.
    fn texts_freed(&mut self) {
        aviary_alloc::give_back();
    }

    fn begin(&mut self, _stage: Stage) {
        self.began = Some(Instant::now());
    }

    fn end(&mut self, stage: Stage) {
        let took = self.began.take().map_or(Duration::ZERO, |t| t.elapsed());
        let name = match stage {
            Stage::FreeTexts => {
                self.freeing += took;
                return;
            }
            Stage::World => "world",
            Stage::Check => "check",
            Stage::Compile => "compile",
            Stage::FreeTree => "free front end",
            Stage::SimStart => "sim start",
            Stage::Flight => "engine + sim",
        };
        let took = if stage == Stage::FreeTree { took + self.freeing } else { took };
        self.stages.0.push((name, took, peak_rss()));
    }

    fn wants(&self, kind: EventKind) -> bool {
        self.sink.wants(kind)
    }

    fn record(&mut self, record: &Record<'_>, _backend: &dyn Backend) {
        self.sink.record(record);
    }
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
