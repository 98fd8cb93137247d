//! `aviary bench parse`: generates a large mission and its world
//! ([`crate::generate::large_mission`]), then times parsing alone and parse + check
//! through the same pipeline as `aviary check` (source map, world,
//! `aviary_check::check`), and writes each run and the median throughput. MB here is
//! 10^6 bytes.

use std::io::Write;
use std::time::Instant;

use aviary_check::NoFiles;
use aviary_diagnostics::{FileId, SourceMap};

use crate::{median, rate, Error, MB};

/// Parses and checks a generated mission of about `mb` MB, `runs` times.
pub fn parse(mb: f64, runs: usize, out: &mut dyn Write) -> Result<(), Error> {
    if !(mb.is_finite() && mb > 0.0) || mb > 4000.0 {
        return Err(Error::Usage(
            "--mb must be a size in megabytes, above 0 and at most 4000".into(),
        ));
    }
    let runs = runs.max(1);
    let started = Instant::now();
    let (mission, world) = crate::generate::large_mission((mb * MB) as usize);
    let size = mission.len();
    writeln!(
        out,
        "generated a mission of {:.2} MB ({size} bytes, {} lines, {} capabilities) and a world of {} drones in {:.2} s",
        size as f64 / MB,
        mission.lines().count(),
        mission.matches("\nCAPABILITY ").count(),
        crate::generate::DRONES,
        started.elapsed().as_secs_f64()
    )?;

    // One run outside the timings, to say what the checker thinks of the mission.
    let (errors, others) = parse_and_check(&mission, &world);
    if errors > 0 || others > 0 {
        writeln!(out, "note: the check reports {errors} error(s) and {others} other diagnostic(s); the generator should give none")?;
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

        writeln!(
            out,
            "run {run}: parse {:.3} s ({:.1} MB/s); parse + check {:.3} s ({:.1} MB/s)",
            parse_time.as_secs_f64(),
            rate(size, parse_time),
            check_time.as_secs_f64(),
            rate(size, check_time)
        )?;
        parse_times.push(parse_time);
        check_times.push(check_time);
    }
    let parse_median = median(&mut parse_times);
    let check_median = median(&mut check_times);
    writeln!(
        out,
        "median of {runs} run(s) over {:.2} MB: parse {:.1} MB/s ({:.3} s); parse + check {:.1} MB/s ({:.3} s)",
        size as f64 / MB,
        rate(size, parse_median),
        parse_median.as_secs_f64(),
        rate(size, check_median),
        check_median.as_secs_f64()
    )?;
    Ok(())
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
    );
    let errors = checked.diagnostics.iter().filter(|d| d.is_error()).count();
    (errors, checked.diagnostics.len() - errors)
}
