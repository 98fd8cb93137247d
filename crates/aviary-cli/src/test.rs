//! `aviary test`: a campaign (`aviary_campaign`, docs/CAMPAIGNS.md): the mission flown on
//! many seeds at once, and its report as text, JSON or HTML; `aviary test merge`: the
//! reports of shards as the report of the whole. Here the files, the progress bar and the
//! exit codes: 0 when every run succeeded, 1 when one did not, 2 for usage and files.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use aviary_campaign::report::Flew;
use aviary_campaign::{Campaign, Report, Seeds, Shard};
use aviary_pipeline::pipeline::{Source, Texts};
use clap::{Args, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::files::{use_roots, world_beside, DiskProvider};
use crate::Format;

#[derive(Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct TestArgs {
    #[command(subcommand)]
    merge: Option<TestCommand>,
    /// The mission to fly
    #[arg(value_parser = crate::mission_file, required = true)]
    file: Option<PathBuf>,
    /// The world file (default: NAME.world.toml beside NAME.mission)
    #[arg(long, value_parser = crate::world_file)]
    world: Option<PathBuf>,
    /// How many runs: the seeds S, S+1, ... S+N-1
    #[arg(long, required = true, value_parser = clap::value_parser!(u64).range(1..))]
    runs: Option<u64>,
    /// The first seed, S
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Runs at once, each on a thread of its own (default: the number of cores)
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    jobs: Option<u64>,
    /// Fly only the I-th of N shares of the seeds: the k-th run (from 0) when k mod N = I-1
    #[arg(long, value_name = "I/N", value_parser = Shard::parse)]
    shard: Option<Shard>,
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Also write the report as one self-contained HTML file
    #[arg(long, value_name = "OUT.html", value_parser = crate::report_file)]
    html: Option<PathBuf>,
    /// A folder whose .mission files USE may read, besides the mission's own (repeatable)
    #[arg(long, value_name = "DIR", value_parser = crate::folder)]
    use_root: Vec<PathBuf>,
}

#[derive(Subcommand)]
enum TestCommand {
    /// Merge the JSON reports of a campaign's shards into the report of the whole campaign
    Merge {
        /// The shards' reports (`aviary test ... --shard I/N --format json`)
        #[arg(required = true)]
        reports: Vec<PathBuf>,
        #[arg(long, value_enum, default_value = "text")]
        format: Format,
        /// Also write the report as one self-contained HTML file
        #[arg(long, value_name = "OUT.html", value_parser = crate::report_file)]
        html: Option<PathBuf>,
    },
}

pub fn run(args: TestArgs) -> u8 {
    match args.merge {
        Some(TestCommand::Merge { reports, format, html }) => {
            merge(&reports, format, html.as_deref())
        }
        None => match (args.file.as_deref(), args.runs) {
            (Some(file), Some(runs)) => campaign(file, runs, &args),
            // clap requires both without `merge`.
            _ => 2,
        },
    }
}

fn campaign(file: &Path, runs: u64, args: &TestArgs) -> u8 {
    let seeds = match Seeds::new(args.seed, runs) {
        Ok(s) => s,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let roots = match use_roots(&args.use_root) {
        Ok(r) => r,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let bytes = match std::fs::read(file) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("aviary: cannot read {}: {e}", file.display());
            return 2;
        }
    };
    let provider = match DiskProvider::new(file, &roots) {
        Ok(p) => p,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let Some(world_path) = args.world.clone().or_else(|| world_beside(file)) else {
        let stem = file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        eprintln!(
            "aviary: {} has no world file: put {stem}.world.toml beside it, or pass --world FILE",
            file.display()
        );
        return 2;
    };
    let world_bytes = match std::fs::read(&world_path) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("aviary: cannot read the world file {}: {e}", world_path.display());
            return 2;
        }
    };
    let name = file.display().to_string();
    let world_name = world_path.display().to_string();
    let texts = Texts {
        mission: Source { name: &name, bytes },
        world: Source { name: &world_name, bytes: world_bytes },
        files: &provider,
    };
    let campaign = match Campaign::prepare(texts) {
        Ok(c) => c,
        Err(not) => {
            return crate::run::refused(not, file, &|| {
                format!("{world_name} has MAVLink drones: a campaign flies simulated drones only")
            })
        }
    };
    let list = seeds.of(args.shard);
    let jobs = args.jobs.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        |j| usize::try_from(j).unwrap_or(usize::MAX),
    );
    let bar = progress(list.len() as u64, args.format);
    let records = campaign.run(&list, jobs, &|_| bar.inc(1));
    bar.finish_and_clear();
    let records = match records {
        Ok(r) => r,
        Err(why) => {
            eprintln!("aviary: the campaign stopped: {why}");
            return 2;
        }
    };
    let report = Report::new(Flew::of(&campaign), seeds, args.shard, records);
    show(&report, args.format, args.html.as_deref(), Some(&campaign.prepared.world))
}

/// A bar on standard error, only on a terminal and never with JSON.
fn progress(runs: u64, format: Format) -> ProgressBar {
    if format == Format::Json || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(runs), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {elapsed} (about {eta} left)")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}

fn merge(paths: &[PathBuf], format: Format, html: Option<&Path>) -> u8 {
    let mut parts = Vec::new();
    for path in paths {
        let name = path.display().to_string();
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) => {
                eprintln!("aviary: cannot read {name}: {e}");
                return 2;
            }
        };
        match Report::read(&name, &text) {
            Ok(r) => parts.push(r),
            Err(why) => {
                eprintln!("aviary: {why}");
                return 2;
            }
        }
    }
    let report = match Report::merge(parts) {
        Ok(r) => r,
        Err(why) => {
            eprintln!("aviary: cannot merge: {why}");
            return 2;
        }
    };
    // The map's world, when its file is where the campaign read it.
    let world = html.and_then(|_| {
        let path = Path::new(&report.flew.world_file);
        match crate::files::world_alone(path) {
            Ok(w) => Some(w),
            Err(_) => {
                eprintln!(
                    "aviary: {} cannot be read here: the HTML map shows the failures without the world",
                    path.display()
                );
                None
            }
        }
    });
    show(&report, format, html, world.as_ref())
}

/// Prints the report, writes its HTML, and says how the campaign went in the exit code.
fn show(
    report: &Report,
    format: Format,
    html: Option<&Path>,
    world: Option<&aviary_world::World>,
) -> u8 {
    if let Some(out) = html {
        let page = match aviary_station::campaign::render(report, world) {
            Ok(p) => p,
            Err(why) => {
                eprintln!("aviary: {why}");
                return 2;
            }
        };
        // Written beside and renamed over: a report is whole or not there.
        let temporary = out.with_extension("html.writing");
        if let Err(e) =
            std::fs::write(&temporary, page).and_then(|()| std::fs::rename(&temporary, out))
        {
            let _ = std::fs::remove_file(&temporary);
            eprintln!("aviary: cannot write {}: {e}", out.display());
            return 2;
        }
    }
    match format {
        Format::Text => out!("{}", report.text()),
        Format::Json => out!("{}", report.json()),
    }
    if let (Some(out), Format::Text) = (html, format) {
        outln!("wrote {}", out.display());
    }
    u8::from(report.succeeded < report.runs)
}
