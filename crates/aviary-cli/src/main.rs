//! `aviary`: check, format (and later run) multi-drone missions.
//!
//! Exit codes (README.md): 0 success, 1 the files have errors (or `fmt --check` would
//! change them), 2 usage or IO problems.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

#[macro_use]
mod out;
mod bench;
mod check;
mod ctl;
mod ctl_table;
mod export;
mod export_plan;
mod files;
mod fmt;
mod gcs;
mod lsp;
mod replay;
mod report;
mod run;
mod serve;
mod test;
mod vehicle_figures;
mod vehicles;
mod zenoh;

/// mimalloc, tuned before `main` (`aviary_alloc`; docs/BENCHMARKS.md).
#[global_allocator]
static ALLOCATOR: aviary_alloc::MiMalloc = aviary_alloc::MiMalloc;

/// Before `main`, so before the first allocation: the first arena takes the options it
/// finds then (`aviary_alloc::tune`). Declared here rather than in the library: a
/// constructor in a library is linked only when something else of its object file is.
// `ctor` places the function in the constructors' section, which is `unsafe` to do: it
// runs before `main`, and touches only the allocator's options (no std runtime needed).
#[allow(unsafe_code)]
#[ctor::ctor(unsafe)]
fn tune_the_allocator() {
    aviary_alloc::tune();
}

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand, ValueEnum};

#[derive(Parser)]
#[command(name = "aviary", version, about = "Check, format and run multi-drone missions")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// `aviary run --clock`.
#[derive(Clone, Copy, ValueEnum, PartialEq, Eq, Debug)]
pub enum Clock {
    Vehicles,
    Wall,
}

#[derive(Clone, Copy, ValueEnum, PartialEq, Eq)]
pub enum Format {
    Text,
    Json,
}

#[derive(Subcommand)]
enum Command {
    /// Parse, resolve and check missions; print every problem found
    Check {
        #[arg(value_parser = mission_file, required = true)]
        files: Vec<PathBuf>,
        /// The world file (default: NAME.world.toml beside NAME.mission, if it exists)
        #[arg(long, value_parser = world_file)]
        world: Option<PathBuf>,
        #[arg(long, value_enum, default_value = "text")]
        format: Format,
        /// Also print the energy and time plan: per drone, a timeline, distance, flight time and battery left.
        /// MAVLink drones are planned with their vehicles' own figures (asked for, at most 5 s)
        #[arg(long)]
        plan: bool,
        /// With --plan: do not ask MAVLink vehicles for their figures; plan with the world's
        #[arg(long, requires = "plan")]
        offline: bool,
        /// A folder whose .mission files USE may read, besides the mission's own (repeatable)
        #[arg(long, value_name = "DIR", value_parser = folder)]
        use_root: Vec<PathBuf>,
    },
    /// Rewrite missions in the one canonical layout
    Fmt {
        #[arg(value_parser = mission_file, required = true)]
        files: Vec<PathBuf>,
        /// Change nothing; exit 1 if a file is not formatted
        #[arg(long)]
        check: bool,
    },
    /// Compile a mission and fly it on the drones its world binds (the simulator by default)
    Run {
        #[arg(value_parser = mission_file)]
        file: PathBuf,
        /// The world file (default: NAME.world.toml beside NAME.mission)
        #[arg(long, value_parser = world_file)]
        world: Option<PathBuf>,
        /// `max` (as fast as possible; the default) or times real time, such as 1 or 10
        #[arg(long)]
        speed: Option<String>,
        /// The seed of the simulation's chances (a sensor's `probability`, a fault's range
        /// of times in the world file): the same files and seed give the same trace
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Write every event to this JSON Lines file
        #[arg(long, value_parser = trace_file)]
        trace: Option<PathBuf>,
        /// The most the trace may hold (such as 64MiB or 2GiB): reached, the mission
        /// stops, the fleet returns home, the trace is closed, and aviary exits 3
        #[arg(long, value_name = "SIZE", default_value = "1GiB", value_parser = run::parse_size)]
        max_trace_size: u64,
        /// Telemetry events per second of mission time (default: none)
        #[arg(long)]
        telemetry_hz: Option<f64>,
        /// Print nothing but errors
        #[arg(long)]
        quiet: bool,
        /// Serve the operator API on PORT (loopback) or HOST:PORT; runs in real time
        /// unless --speed says otherwise
        #[arg(long, value_name = "[HOST:]PORT")]
        serve: Option<String>,
        /// With --serve: also answer to this host name (the name a reverse proxy forwards,
        /// or this machine's name on the network); may be repeated
        #[arg(long, value_name = "NAME", requires = "serve")]
        allow_host: Vec<String>,
        /// Publish the mission on Zenoh (its events, telemetry and operator state) and answer
        /// the operator API there, with Zenoh's JSON5 configuration file CONFIG or Zenoh's
        /// defaults (docs/DISTRIBUTED.md); runs in real time unless --speed says otherwise
        #[arg(long, value_name = "CONFIG", num_args = 0..=1)]
        zenoh: Option<Option<PathBuf>>,
        /// With --zenoh: the key prefix of the mission's keys (default: aviary/MISSION)
        #[arg(long, value_name = "KEY", requires = "zenoh")]
        zenoh_prefix: Option<String>,
        /// With --zenoh: also for ROS 2 on rmw_zenoh, in the domain ROS_DOMAIN_ID (0 when
        /// unset): the events, and each drone's pose and fix (docs/ROS2.md)
        #[arg(long, requires = "zenoh")]
        ros: bool,
        /// A folder whose .mission files USE may read, besides the mission's own (repeatable)
        #[arg(long, value_name = "DIR", value_parser = folder)]
        use_root: Vec<PathBuf>,
        /// With MAVLink drones: the clock the mission keeps, the vehicles' own (a SITL
        /// faster than real time makes the mission faster too) or the wall's
        #[arg(long, value_enum, default_value_t = Clock::Vehicles)]
        clock: Clock,
    },
    /// Serve the ground station: a web page to open, check, fly, watch and steer the
    /// missions of a folder (docs/GCS.md)
    Gcs {
        /// The folder of missions and worlds (default: the current one)
        #[arg(default_value = ".", value_parser = folder)]
        dir: PathBuf,
        /// PORT (loopback) or HOST:PORT to listen on
        #[arg(long, value_name = "[HOST:]PORT", default_value = "7878")]
        listen: String,
        /// Also answer to this host name (the name a reverse proxy forwards, or this
        /// machine's name on the network); may be repeated
        #[arg(long, value_name = "NAME")]
        allow_host: Vec<String>,
        /// A folder whose .mission files USE may read, besides the mission's own (repeatable)
        #[arg(long, value_name = "DIR", value_parser = folder)]
        use_root: Vec<PathBuf>,
        /// Instead of a folder: the station of a run on another machine (`aviary run
        /// --zenoh`), reached with Zenoh's JSON5 configuration file CONFIG or Zenoh's
        /// defaults (docs/DISTRIBUTED.md)
        #[arg(long, value_name = "CONFIG", num_args = 0..=1, requires = "zenoh_prefix")]
        zenoh: Option<Option<PathBuf>>,
        /// With --zenoh: the run's key prefix, as it printed it (aviary/MISSION)
        #[arg(long, value_name = "KEY", requires = "zenoh")]
        zenoh_prefix: Option<String>,
        /// With --zenoh: the run's token, to steer it from the page (without it the station
        /// only watches)
        #[arg(long, env = "AVIARY_TOKEN", requires = "zenoh")]
        token: Option<String>,
    },
    /// Play a recorded trace back in the ground station: map, fleet grid, log and a
    /// scrubber over the mission's time (docs/GCS.md)
    Replay {
        /// The trace, as `aviary run --trace` writes it
        #[arg(value_parser = recorded_trace)]
        trace: PathBuf,
        /// The world file the mission flew in, for the map's areas, places and homes
        #[arg(long, value_parser = world_file)]
        world: Option<PathBuf>,
        /// PORT (loopback) or HOST:PORT to listen on
        #[arg(long, value_name = "[HOST:]PORT", default_value = "7878")]
        listen: String,
        /// Also answer to this host name; may be repeated
        #[arg(long, value_name = "NAME")]
        allow_host: Vec<String>,
    },
    /// Write one self-contained HTML report of a recorded trace: the summary, a map of
    /// every track, per-drone plots and the timeline (docs/GCS.md)
    Report {
        /// The trace, as `aviary run --trace` writes it
        #[arg(value_parser = recorded_trace)]
        trace: PathBuf,
        /// The world file the mission flew in, for the map's areas, places and homes
        #[arg(long, value_parser = world_file)]
        world: Option<PathBuf>,
        /// Where to write the report
        #[arg(short, long, value_name = "OUT.html", value_parser = report_file)]
        output: PathBuf,
    },
    /// Write a recorded trace as a ROS 2 bag (rosbag2, MCAP): every event, and each drone's
    /// pose and position on the Earth from the telemetry (docs/ROS2.md)
    Export {
        /// The trace, as `aviary run --trace` writes it
        #[arg(value_parser = recorded_trace)]
        trace: PathBuf,
        /// The world file the mission flew in, whose origin places the drones on the Earth
        #[arg(long, value_parser = world_file)]
        world: Option<PathBuf>,
        /// The bag to write: a new folder holding the MCAP file and metadata.yaml
        #[arg(long, value_name = "BAG", value_parser = folder)]
        mcap: PathBuf,
    },
    /// Write one drone's part of a mission as a QGroundControl plan (.plan): the waypoints
    /// its plan flies through (as `aviary check --plan` times them), the world's geofence
    /// and no-fly zones as the geofence, its places as rally points
    ExportPlan {
        #[arg(value_parser = mission_file)]
        mission: PathBuf,
        /// The world file (default: NAME.world.toml beside NAME.mission)
        #[arg(long, value_parser = world_file)]
        world: Option<PathBuf>,
        /// The drone whose waypoints are written
        #[arg(long)]
        drone: String,
        /// Where to write the plan
        #[arg(short, long, value_name = "OUT.plan")]
        output: PathBuf,
        /// A folder whose .mission files USE may read, besides the mission's own (repeatable)
        #[arg(long = "use-root", value_name = "DIR")]
        use_root: Vec<PathBuf>,
    },
    /// Talk to a running mission's operator API (see `aviary run --serve`)
    Ctl {
        /// The API's address, as the run printed it (not needed with --zenoh, which wins
        /// over an AVIARY_URL of the environment)
        #[arg(long, env = "AVIARY_URL", required_unless_present = "zenoh")]
        url: Option<String>,
        /// The run's token (needed for control calls)
        #[arg(long, env = "AVIARY_TOKEN")]
        token: Option<String>,
        /// Reach a run on Zenoh (`aviary run --zenoh`) instead, with Zenoh's JSON5
        /// configuration file CONFIG or Zenoh's defaults (docs/DISTRIBUTED.md)
        #[arg(long, value_name = "CONFIG", num_args = 0..=1, requires = "zenoh_prefix")]
        zenoh: Option<Option<PathBuf>>,
        /// With --zenoh: the run's key prefix, as it printed it (aviary/MISSION)
        #[arg(long, value_name = "KEY", requires = "zenoh")]
        zenoh_prefix: Option<String>,
        #[command(subcommand)]
        command: ctl::CtlCommand,
    },
    /// Serve the world's drones as simulated MAVLink vehicles (ArduCopter-like, or PX4) until Ctrl-C
    Vehicles {
        /// The world file whose drones to serve
        #[arg(long, value_parser = world_file)]
        world: PathBuf,
        /// tcp:HOST:PORT or udp:HOST:PORT (port 0: any free port; the first line printed says which)
        #[arg(long)]
        listen: String,
        /// Times real time, such as 1 (the default) or 20
        #[arg(long, default_value_t = 1.0)]
        speed: f64,
        /// MAVLink 2 signing: a passphrase (hashed with SHA-256) or 64 hex digits
        #[arg(long)]
        signing_key: Option<String>,
        /// The autopilot the vehicles answer as: ArduCopter's words, modes and parameters, or PX4's
        #[arg(long, value_enum, default_value = "ardupilot")]
        autopilot: vehicles::Autopilot,
    },
    /// Beside an autopilot: hold its MAVLink link and carry it on Zenoh, so that a mission
    /// on another machine flies it (`mavlink = "agent:NAME"` in its world), until Ctrl-C
    /// (docs/DISTRIBUTED.md)
    Agent {
        /// The agent's name, as the mission's world names it (letters, digits, -, _, .)
        #[arg(long)]
        name: String,
        /// The vehicle's link: tcp:HOST:PORT, udp:HOST:PORT, udpout:HOST:PORT, ... (as a
        /// world's `mavlink =` address)
        #[arg(long)]
        mavlink: String,
        /// Zenoh's JSON5 configuration file (Zenoh's defaults without one: a peer that
        /// finds others by multicast scouting)
        #[arg(long, value_name = "CONFIG")]
        zenoh: Option<PathBuf>,
    },
    /// Fly a mission on many seeds of the simulator at once and report how often it
    /// succeeds, how it fails, and the spread of its time, batteries and finds
    /// (docs/CAMPAIGNS.md); `aviary test merge`: the reports of shards as one
    Test(test::TestArgs),
    /// Explain a diagnostic code, such as E107
    Explain { code: String },
    /// Serve the Language Server Protocol over stdin and stdout, for editors: diagnostics
    /// as you type, hover, completion, definition, rename, formatting (docs/EDITORS.md)
    Lsp {
        /// A folder whose .mission files USE may read, besides the mission's own (repeatable)
        #[arg(long, value_name = "DIR", value_parser = folder)]
        use_root: Vec<PathBuf>,
        /// Speak over stdin and stdout (the only way; accepted because editors' clients
        /// such as vscode-languageclient pass it)
        #[arg(long)]
        stdio: bool,
    },
    /// Benchmarks on generated missions: the front end (parse), the engine (w), the simulator
    /// (swarm), the language server (lsp); and a campaign of the paper's mission (campaign)
    Bench {
        #[command(subcommand)]
        which: bench::BenchCommand,
    },
}

/// `ROS_DOMAIN_ID`, as ROS 2 reads it: 0 when unset.
fn ros_domain() -> Result<u32, String> {
    match std::env::var("ROS_DOMAIN_ID") {
        Ok(text) if !text.trim().is_empty() => text.trim().parse::<u32>().map_err(|_| {
            format!("ROS_DOMAIN_ID is `{text}`: it must be a whole number, such as 0 or 42")
        }),
        _ => Ok(0),
    }
}

/// A file name from the command line: not empty. (An empty one would read as "no such
/// file", or as clap's "none was supplied", neither of which says what was empty.)
fn nonempty(s: &str, what: &str) -> Result<PathBuf, String> {
    if s.is_empty() {
        return Err(format!("the name is empty: write the path of {what}"));
    }
    Ok(PathBuf::from(s))
}

fn mission_file(s: &str) -> Result<PathBuf, String> {
    nonempty(s, "a .mission file")
}

fn world_file(s: &str) -> Result<PathBuf, String> {
    nonempty(s, "a world file (NAME.world.toml)")
}

fn trace_file(s: &str) -> Result<PathBuf, String> {
    nonempty(s, "the file to write the trace to")
}

fn recorded_trace(s: &str) -> Result<PathBuf, String> {
    nonempty(s, "a trace (JSON Lines, as `aviary run --trace` writes it)")
}

fn report_file(s: &str) -> Result<PathBuf, String> {
    nonempty(s, "the report to write (OUT.html)")
}

fn folder(s: &str) -> Result<PathBuf, String> {
    nonempty(s, "a folder")
}

/// The stack the command runs on: the front end's (the engine also follows capability
/// calls by recursion); the main thread's 8 MiB would overflow on a long chain.
const STACK: usize = aviary_check::STACK;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let worker = std::thread::Builder::new()
        .name("aviary".into())
        .stack_size(STACK)
        .spawn(move || command(cli));
    match worker.map(|w| w.join()) {
        Ok(Ok(code)) => ExitCode::from(code),
        Ok(Err(_)) => ExitCode::from(101),
        Err(e) => {
            eprintln!("aviary: cannot start: {e}");
            ExitCode::from(2)
        }
    }
}

fn command(cli: Cli) -> u8 {
    if matches!(cli.command, Command::Check { .. } | Command::Fmt { .. }) {
        aviary_alloc::short_lived();
    }
    let code = match cli.command {
        Command::Check { files, world, format, plan, offline, use_root } => check::run(
            &files,
            world.as_deref(),
            format,
            check::Plan { plan, ask: plan && !offline },
            &use_root,
        ),
        Command::Fmt { files, check } => fmt::run(&files, check),
        Command::Run {
            file,
            world,
            speed,
            seed,
            trace,
            max_trace_size,
            telemetry_hz,
            quiet,
            serve,
            allow_host,
            zenoh,
            zenoh_prefix,
            ros,
            use_root,
            clock,
        } => {
            // Served to an operator, a mission runs in real time unless told otherwise.
            let served = serve.is_some() || zenoh.is_some();
            let speed = speed.unwrap_or_else(|| if served { "1".into() } else { "max".into() });
            let zenoh = zenoh
                .map(|config| {
                    let keys = zenoh_prefix.as_deref().map(aviary_zenoh::Keys::new).transpose()?;
                    let ros = ros.then(ros_domain).transpose()?;
                    Ok::<_, String>(run::Zenoh { config, keys, ros })
                })
                .transpose();
            match (
                run::parse_speed(&speed),
                serve.as_deref().map(run::parse_serve).transpose(),
                zenoh,
            ) {
                (Ok(speed), Ok(serve), Ok(zenoh)) => {
                    let serve =
                        serve.map(|address| serve::Serve { address, allowed_hosts: allow_host });
                    run::run(&run::RunArgs {
                        file,
                        world,
                        speed,
                        seed,
                        trace,
                        max_trace_bytes: max_trace_size,
                        telemetry_hz,
                        quiet,
                        serve,
                        zenoh,
                        use_root,
                        clock: match clock {
                            Clock::Vehicles => aviary_pipeline::pipeline::LiveClock::Vehicles,
                            Clock::Wall => aviary_pipeline::pipeline::LiveClock::Wall,
                        },
                    })
                }
                (Err(why), _, _) | (_, Err(why), _) | (_, _, Err(why)) => {
                    eprintln!("aviary: {why}");
                    2
                }
            }
        }
        Command::Gcs { dir, listen, allow_host, use_root, zenoh, zenoh_prefix, token } => {
            match run::parse_serve(&listen) {
                Ok(address) => {
                    let serve = serve::Serve { address, allowed_hosts: allow_host };
                    match (zenoh, zenoh_prefix) {
                        (Some(_), _) if dir != std::path::Path::new(".") => {
                            eprintln!("aviary: a station serves a folder (DIR) or a run on Zenoh (--zenoh), not both: leave out {}", dir.display());
                            2
                        }
                        (Some(config), Some(prefix)) => {
                            match zenoh::client(config.as_deref(), &prefix) {
                                Ok(client) => zenoh::station(client, token, &serve),
                                Err(why) => {
                                    eprintln!("aviary: {why}");
                                    2
                                }
                            }
                        }
                        _ => gcs::run(&dir, &serve, &use_root),
                    }
                }
                Err(why) => {
                    eprintln!("aviary: {}", why.replace("--serve", "--listen"));
                    2
                }
            }
        }
        Command::Replay { trace, world, listen, allow_host } => match run::parse_serve(&listen) {
            Ok(address) => replay::run(
                &trace,
                world.as_deref(),
                &serve::Serve { address, allowed_hosts: allow_host },
            ),
            Err(why) => {
                eprintln!("aviary: {}", why.replace("--serve", "--listen"));
                2
            }
        },
        Command::Report { trace, world, output } => report::run(&trace, world.as_deref(), &output),
        Command::Export { trace, world, mcap } => export::run(&trace, world.as_deref(), &mcap),
        Command::ExportPlan { mission, world, drone, output, use_root } => {
            export_plan::run(&mission, world.as_deref(), &drone, &output, &use_root)
        }
        Command::Ctl { url, token, zenoh, zenoh_prefix, command } => {
            let reach = match (url, zenoh, zenoh_prefix) {
                (_, Some(config), Some(prefix)) => {
                    zenoh::client(config.as_deref(), &prefix).map(ctl::Reach::Zenoh)
                }
                (Some(url), None, _) => Ok(ctl::Reach::Http(url.trim_end_matches('/').to_string())),
                _ => Err("say where the run is: --url URL, or --zenoh [CONFIG] --zenoh-prefix KEY"
                    .into()),
            };
            match reach {
                Ok(reach) => ctl::run(&reach, token.as_deref(), command),
                Err(why) => {
                    eprintln!("aviary: {why}");
                    2
                }
            }
        }
        Command::Vehicles { world, listen, speed, signing_key, autopilot } => {
            vehicles::run(&vehicles::VehiclesArgs {
                world: &world,
                listen: &listen,
                speed,
                signing_key: signing_key.as_deref(),
                autopilot,
            })
        }
        Command::Agent { name, mavlink, zenoh } => zenoh::agent(&name, &mavlink, zenoh.as_deref()),
        Command::Test(args) => test::run(args),
        Command::Explain { code } => explain(&code),
        Command::Lsp { use_root, stdio: _ } => lsp::run(&use_root),
        Command::Bench { which } => bench::run(which),
    };
    code
}

fn explain(code: &str) -> u8 {
    match aviary_diagnostics::Code::from_str(&code.to_ascii_uppercase()) {
        Some(c) => {
            outln!("{} ({}): {}", c.as_str(), c.severity().as_str(), c.summary());
            outln!("See docs/DIAGNOSTICS.md for an example and the fix.");
            0
        }
        None => {
            eprintln!(
                "aviary: no diagnostic has the code `{code}`; codes look like E107, W201 or N301"
            );
            2
        }
    }
}
