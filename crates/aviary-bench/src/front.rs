//! `aviary bench front`: the whole of `aviary check` on a generated mission: the realistic
//! mission of `aviary bench parse` ([`crate::generate::large_mission`]), or a shape
//! that once made the pre-flight analyses quadratic (`generate/front.rs`):
//! N statements in one SEQUENTIAL block on one drone, or a chain of N capabilities.
//! Times parse + check, compile, and the analyses (conflicts and the plan), and prints
//! each run and the median throughput of the whole. MB is 10^6 bytes.

use std::io::Write;
use std::time::{Duration, Instant};

use aviary_check::NoFiles;
use aviary_diagnostics::SourceMap;

use crate::generate;
use crate::{median, rate, Emit, Error, MB};

/// The generated mission's shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    /// N statements in one SEQUENTIAL block, all on one drone
    Sequential,
    /// N capabilities, each calling the next
    Chain,
    /// The realistic mission of `aviary bench parse`, of N MB
    Realistic,
}

/// One run's stages: parse + check, compile, analyses; and the diagnostics found.
struct Timed {
    check: Duration,
    compile: Duration,
    analyses: Duration,
    errors: usize,
    others: usize,
}

/// All of `aviary check` on a generated mission of `shape` and size `n` (statements,
/// capabilities, or MB for [`Shape::Realistic`]), `runs` times; or, with `emit`, the
/// mission or its world instead.
pub fn front(
    shape: Shape,
    n: usize,
    runs: usize,
    emit: Emit,
    out: &mut dyn Write,
) -> Result<(), Error> {
    if n == 0 || n > 50_000_000 {
        return Err(Error::Usage("--n must be from 1 to 50000000".into()));
    }
    let runs = runs.max(1);
    let (mission, world, what) = match shape {
        Shape::Sequential => (
            generate::sequential_mission(n),
            generate::front_world(),
            "statements in one SEQUENTIAL block",
        ),
        Shape::Chain => {
            (generate::chain_mission(n), generate::front_world(), "capabilities in a chain")
        }
        Shape::Realistic if n > 4000 => {
            return Err(Error::Usage("--n is in MB for the realistic shape: at most 4000".into()));
        }
        Shape::Realistic => {
            let (mission, world) = generate::large_mission(n * MB as usize);
            (mission, world, "MB of the realistic mission (waves of sectors)")
        }
    };
    match emit {
        Emit::Mission => return Ok(write!(out, "{mission}")?),
        Emit::World => return Ok(write!(out, "{world}")?),
        Emit::Nothing => {}
    }
    let size = mission.len();
    writeln!(out, "generated a mission of {n} {what}: {:.2} MB ({size} bytes)", size as f64 / MB)?;
    let mut totals = Vec::with_capacity(runs);
    for r in 1..=runs {
        let t = once(&mission, &world);
        let total = t.check + t.compile + t.analyses;
        writeln!(
            out,
            "run {r}: parse + check {:.3} s, compile {:.3} s, analyses {:.3} s; all {:.3} s ({:.1} MB/s); {} error(s), {} other diagnostic(s)",
            t.check.as_secs_f64(),
            t.compile.as_secs_f64(),
            t.analyses.as_secs_f64(),
            total.as_secs_f64(),
            rate(size, total),
            t.errors,
            t.others
        )?;
        if t.errors > 0 {
            return Err(Error::Failed(
                "the generated mission has errors; the generator is wrong".into(),
            ));
        }
        totals.push(total);
    }
    let m = median(&mut totals);
    writeln!(
        out,
        "median of {runs} run(s) over {:.2} MB: parse + check + analyses {:.1} MB/s ({:.3} s)",
        size as f64 / MB,
        rate(size, m),
        m.as_secs_f64()
    )?;
    Ok(())
}

/// What `aviary check` does with the mission, minus reading and printing: the front end,
/// then `aviary_verify::preflight`'s two steps, each timed.
fn once(mission: &str, world: &str) -> Timed {
    let start = Instant::now();
    let mut sources = SourceMap::new();
    let checked = aviary_check::check_sources(
        &mut sources,
        ("front.mission", mission.as_bytes()),
        Some(("front.world.toml", world.as_bytes())),
        &NoFiles,
    );
    let check = start.elapsed();
    let mut errors = checked.diagnostics.iter().filter(|d| d.is_error()).count();
    let mut others = checked.diagnostics.len() - errors;
    let (mut compile, mut analyses) = (Duration::ZERO, Duration::ZERO);
    if let (false, Some(program), Some(w)) = (checked.has_errors(), checked.program, &checked.world)
    {
        let start = Instant::now();
        // As `aviary_verify::preflight` does: the tree is dropped before the analyses.
        let compiled = aviary_lower::compile(&program, w);
        drop(program);
        compile = start.elapsed();
        if let Some(compiled) = compiled {
            let start = Instant::now();
            let v = std::hint::black_box(aviary_verify::verify(&compiled, w));
            analyses = start.elapsed();
            errors += v.diagnostics.iter().filter(|d| d.is_error()).count();
            others += v.diagnostics.iter().filter(|d| !d.is_error()).count();
        }
    }
    Timed { check, compile, analyses, errors, others }
}
