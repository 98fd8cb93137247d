//! `aviary bench campaign --runs N`: a campaign (`aviary test`, `aviary_campaign`) of the
//! paper's mission, `examples/search_and_rescue.mission`, with its world or another one
//! given as text (such as one with `[air]`): N seeds on J threads. Prints the wall time,
//! runs per second and the campaign's success, the figure docs/BENCHMARKS.md keeps.

use std::io::Write;
use std::time::Instant;

use aviary_campaign::report::Flew;
use aviary_campaign::{Campaign, Report, Seeds};
use aviary_pipeline::pipeline::{NotFlown, Source, Texts};

use crate::stages::{mib, peak_rss};
use crate::Error;

/// The paper's mission, as `aviary test examples/search_and_rescue.mission` reads it.
pub const PAPER_MISSION: &str = include_str!("../../../examples/search_and_rescue.mission");
/// Its world.
pub const PAPER_WORLD: &str = include_str!("../../../examples/search_and_rescue.world.toml");

/// `runs` seeds from 0 of the paper's mission in `world` (its own world when `None`), on
/// `jobs` threads.
pub fn campaign(
    runs: u64,
    jobs: usize,
    world: Option<&str>,
    out: &mut dyn Write,
) -> Result<(), Error> {
    let seeds = Seeds::new(0, runs).map_err(Error::Usage)?;
    if jobs == 0 {
        return Err(Error::Usage("--jobs must be at least 1".into()));
    }
    let started = Instant::now();
    let texts = Texts {
        mission: Source {
            name: "search_and_rescue.mission",
            bytes: PAPER_MISSION.as_bytes().to_vec(),
        },
        world: Source {
            name: "search_and_rescue.world.toml",
            bytes: world.unwrap_or(PAPER_WORLD).as_bytes().to_vec(),
        },
        files: &aviary_check::NoFiles,
    };
    let campaign = Campaign::prepare(texts).map_err(|e| {
        Error::Failed(match e {
            NotFlown::Errors { diagnostics, sources } => diagnostics
                .iter()
                .filter(|d| d.is_error())
                .map(|d| aviary_diagnostics::render_text(&sources, d, false))
                .collect(),
            NotFlown::Failed(why) => why,
            NotFlown::NoMission | NotFlown::Speed => "the paper's mission did not compile".into(),
        })
    })?;
    let prepared = started.elapsed();
    let flying = Instant::now();
    let records = campaign.run(&seeds.of(None), jobs, &|_| {}).map_err(Error::Failed)?;
    let flown = flying.elapsed().as_secs_f64();
    let report = Report::new(Flew::of(&campaign), seeds, None, records);
    let simulated: f64 = report.records.iter().map(|r| r.time).sum();
    writeln!(
        out,
        "aviary campaign mission=Search_and_Rescue runs={runs} jobs={jobs} wall={flown:.3}s ({:.1} runs/s, {:.2} ms a run per thread) prepare={:.3}s succeeded={} simulated={:.0}s ({:.0}x real time) peak={}",
        runs as f64 / flown.max(1e-9),
        1000.0 * flown * jobs as f64 / runs as f64,
        prepared.as_secs_f64(),
        report.succeeded,
        simulated,
        simulated / flown.max(1e-9),
        mib(peak_rss())
    )?;
    Ok(())
}
