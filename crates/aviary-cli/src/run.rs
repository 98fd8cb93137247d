//! `aviary run`: check, compile and fly a mission on the drones its world binds (the
//! built-in simulator), with a live progress line, a JSON Lines trace and a summary.

use std::io::Write;
use std::path::PathBuf;
use std::sync::Arc;

use aviary_api::trace::Record;
use aviary_api::Backend;
use aviary_diagnostics::{render_text, SourceMap};
use aviary_engine::{Control, ControlRequest, Controller, Outcome, RunOptions, Status};
use aviary_ir::Mission;
use aviary_sim::{Fleet, SimBackend, SimOptions};
use aviary_world::World;
use indicatif::ProgressBar;
use tokio::sync::mpsc::UnboundedReceiver;

mod summary;

use summary::{progress_bar, summary, Stats};

use crate::files::{color_wanted, use_roots, world_beside, DiskProvider};
use crate::trace_file::{lock, SharedTrace, TraceFile};

pub struct RunArgs {
    pub file: PathBuf,
    pub world: Option<PathBuf>,
    /// `None`: as fast as possible.
    pub speed: Option<f64>,
    /// The simulator's seed: every chance the world asks for is drawn from it.
    pub seed: u64,
    pub trace: Option<PathBuf>,
    pub telemetry_hz: Option<f64>,
    pub quiet: bool,
    /// Where to serve the operator API.
    pub serve: Option<crate::serve::Serve>,
    /// Folders whose .mission files USE may read, besides the mission's own.
    pub use_root: Vec<PathBuf>,
}

/// `7878` is loopback port 7878; `HOST:PORT` binds exactly that.
pub fn parse_serve(text: &str) -> Result<std::net::SocketAddr, String> {
    if let Ok(port) = text.parse::<u16>() {
        return Ok(std::net::SocketAddr::from(([127, 0, 0, 1], port)));
    }
    text.parse().map_err(|_| {
        format!("`{text}` is not a port or HOST:PORT for --serve: write 7878 or 127.0.0.1:7878")
    })
}

/// `max` or a positive number of times real time.
pub fn parse_speed(text: &str) -> Result<Option<f64>, String> {
    if text == "max" {
        return Ok(None);
    }
    match text.parse::<f64>() {
        Ok(x) if x > 0.0 && x.is_finite() => Ok(Some(x)),
        _ => Err(format!(
            "`{text}` is not a speed: write `max` or a positive number such as 1 or 10"
        )),
    }
}

pub fn run(args: &RunArgs) -> u8 {
    match run_mission(args) {
        Ok(code) => code,
        Err(why) => {
            eprintln!("aviary: {why}");
            2
        }
    }
}

/// Checks, compiles and flies the mission; the exit code, or why it stopped early (exit
/// code 2).
fn run_mission(args: &RunArgs) -> Result<u8, String> {
    let inputs = read_inputs(args)?;
    let api = aviary_sim::descriptor();
    let (checked, sources) = check(args, &inputs, &api)?;
    let (Some(program), Some(world)) = (checked.program, checked.world) else { return Ok(2) };
    let Some(mission) = aviary_lower::compile(&program, &world, &api) else {
        return Err(format!(
            "{} has no MISSION to run (it holds only capabilities)",
            args.file.display()
        ));
    };
    drop(program);
    let trace = open_trace(args, &mission)?;
    // Any MAVLink drone: the wall clock, and the simulated drones in real time with it.
    let live = !aviary_mavlink::bindings(&world).is_empty();
    if live && args.speed.is_some() {
        return Err(format!(
            "{} has MAVLink drones, which fly in real time: leave out --speed",
            inputs.world_path.display()
        ));
    }
    // Simulated drones only: the fleet takes the world's drones where they lie. With
    // MAVLink drones the world is kept to connect them.
    let (fleet, world) =
        if live { (Fleet::new(&world), Some(world)) } else { (Fleet::from_world(world), None) };
    // The chances the world asks for (a sensor's `probability`, a fault's range of
    // times) are drawn from the seed.
    let fleet = fleet.seeded(args.seed);
    let runtime = if live {
        aviary_backends::live_runtime()
    } else {
        tokio::runtime::Builder::new_current_thread().enable_time().start_paused(true).build()
    }
    .map_err(|e| format!("cannot start the runtime: {e}"))?;
    let (controller, controls) = Controller::new();
    // The first stop signal, also seen before the engine runs (while vehicles connect).
    let (stop_tx, stop_rx) = tokio::sync::watch::channel(None::<&'static str>);
    on_stop_signals(controller.clone(), stop_tx, trace.clone());
    let server = (args.serve.as_ref())
        .map(|serve| crate::serve::start(serve, &mission, controller.clone()))
        .transpose()?;
    let progress = progress_bar(args.quiet);
    let flight = Flight {
        mission: &mission,
        trace: &trace,
        controller: &controller,
        progress: &progress,
        feed: server.as_ref().map(|s| &s.feed),
        // The operator's view of the drones comes from telemetry events.
        telemetry_hz: args.telemetry_hz.or(server.as_ref().map(|_| 2.0)),
    };
    let ran = runtime.block_on(async {
        let sim = SimBackend::start_with(
            fleet,
            SimOptions { speed: args.speed, ..SimOptions::default() },
        );
        let mixed = match &world {
            Some(world) => {
                let mavlink = match connect_vehicles(world, stop_rx.clone(), &trace).await? {
                    Connected::Vehicles(mavlink) => mavlink,
                    Connected::Stopped(outcome) => return Ok((outcome, String::new())),
                };
                if let Some(sources) = &sources {
                    let facts = mavlink.facts();
                    crate::figures::before_flight(&mission, world, facts, sources, args.quiet);
                }
                Some(aviary_backends::Mixed::new(sim.clone(), mavlink))
            }
            None => None,
        };
        // The backends keep what they need of the world: a large fleet's is not held
        // through the flight.
        drop(world);
        drop(sources);
        Ok::<_, String>(flight.fly(&sim, mixed.as_ref(), controls).await)
    });
    let (outcome, summary) = ran.inspect_err(|_| progress.finish_and_clear())?;
    progress.finish_and_clear();
    Ok(finish(args, server.as_ref(), &outcome, &summary, &trace))
}

/// The mission's and the world's files, read, and what reads the files it USEs.
struct Inputs {
    bytes: Vec<u8>,
    provider: DiskProvider,
    world_path: PathBuf,
    world_bytes: Vec<u8>,
}

fn read_inputs(args: &RunArgs) -> Result<Inputs, String> {
    let roots = use_roots(&args.use_root)?;
    let bytes = std::fs::read(&args.file)
        .map_err(|e| format!("cannot read {}: {e}", args.file.display()))?;
    let provider = DiskProvider::new(&args.file, &roots)?;
    let Some(world_path) = args.world.clone().or_else(|| world_beside(&args.file)) else {
        let stem =
            args.file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        return Err(format!(
            "{} has no world file: put {stem}.world.toml beside it, or pass --world FILE",
            args.file.display()
        ));
    };
    let world_bytes = std::fs::read(&world_path)
        .map_err(|e| format!("cannot read the world file {}: {e}", world_path.display()))?;
    Ok(Inputs { bytes, provider, world_path, world_bytes })
}

/// Checks the mission against its world; its errors are shown. The source texts are kept
/// only when MAVLink drones fly (see below).
fn check(
    args: &RunArgs,
    inputs: &Inputs,
    api: &aviary_api::Descriptor,
) -> Result<(aviary_check::Checked, Option<SourceMap>), String> {
    let mut sources = SourceMap::new();
    let name = args.file.display().to_string();
    let world_name = inputs.world_path.display().to_string();
    let checked = aviary_check::check_sources(
        &mut sources,
        (&name, &inputs.bytes),
        Some((&world_name, &inputs.world_bytes)),
        &inputs.provider,
        api,
    );
    if checked.has_errors() {
        for d in checked.diagnostics.iter().filter(|d| d.is_error()) {
            eprint!("{}", render_text(&sources, d, color_wanted()));
        }
        return Err(format!("{} has errors, so it was not run", args.file.display()));
    }
    // The source texts are needed only to show errors: they go before the mission is
    // compiled (a large world's text is megabytes). With MAVLink drones the plan is made
    // again with the vehicles' figures, and its warnings point into them.
    let mavlink = checked.world.as_ref().is_some_and(|w| !aviary_mavlink::bindings(w).is_empty());
    let sources = if mavlink {
        Some(sources)
    } else {
        drop(sources);
        crate::alloc::give_back();
        None
    };
    Ok((checked, sources))
}

/// The trace file (`--trace`), or a sink.
fn open_trace(args: &RunArgs, mission: &Mission) -> Result<SharedTrace, String> {
    let out: Box<dyn Write + Send> = match &args.trace {
        Some(path) => Box::new(
            std::fs::File::create(path)
                .map_err(|e| format!("cannot write the trace {}: {e}", path.display()))?,
        ),
        None => Box::new(std::io::sink()),
    };
    Ok(TraceFile::new(
        out,
        args.trace.as_ref().map(|p| p.display().to_string()).unwrap_or_default(),
        mission.name.clone(),
    ))
}

/// How the MAVLink vehicles' connection ended.
enum Connected {
    Vehicles(aviary_mavlink::MavlinkBackend),
    /// A stop signal came first: the trace is closed, nothing flew.
    Stopped(Outcome),
}

/// Connects the world's MAVLink vehicles. A stop while they connect is answered at once:
/// nothing has flown, so there is nothing to bring home.
async fn connect_vehicles(
    world: &World,
    mut stop: tokio::sync::watch::Receiver<Option<&'static str>>,
    trace: &SharedTrace,
) -> Result<Connected, String> {
    tokio::select! {
        connected = aviary_mavlink::connect(world, aviary_mavlink::Tuning::default()) => {
            connected.map(Connected::Vehicles)
        }
        by = stop.wait_for(Option::is_some) => {
            let by = by.ok().and_then(|b| *b).unwrap_or("a stop signal");
            let reason = format!("stopped by {by} while the vehicles connected; nothing flew");
            lock(trace).close_now(&reason);
            Ok(Connected::Stopped(Outcome { status: Status::Aborted, reason: Some(reason) }))
        }
    }
}

/// What the engine's run is wired to: the trace, the progress line, the operator API's
/// feed, and the controls.
struct Flight<'a> {
    mission: &'a Mission,
    trace: &'a SharedTrace,
    controller: &'a Controller,
    progress: &'a ProgressBar,
    feed: Option<&'a aviary_server::Feed>,
    telemetry_hz: Option<f64>,
}

impl Flight<'_> {
    /// Runs the mission on the simulator, or on `mixed` with MAVLink drones, to its end;
    /// the outcome and the summary.
    async fn fly(
        &self,
        sim: &Arc<SimBackend>,
        mixed: Option<&aviary_backends::Mixed>,
        controls: UnboundedReceiver<ControlRequest>,
    ) -> (Outcome, String) {
        let backend: &dyn Backend = match mixed {
            Some(m) => m,
            None => &**sim,
        };
        let watch = watch_backend(sim.take_driver(), self.controller.clone());
        let mut stats = Stats::default();
        let mut sink = |record: &Record| {
            stats.observe(record, self.progress, backend, self.mission.drones.len());
            lock(self.trace).write(record);
            if let Some(feed) = self.feed {
                feed.publish(record);
            }
        };
        let options = RunOptions { telemetry_hz: self.telemetry_hz, ..RunOptions::default() };
        let outcome = tokio::select! {
            biased;
            outcome = aviary_engine::run_controlled(self.mission, backend, &mut sink, &options, controls) => outcome,
            _ = watch => unreachable!("the watch never ends"),
        };
        sim.stop();
        // A MAVLink drone's distance and flight time come from the track it reported.
        let odometry = |d: usize| match mixed.filter(|m| m.mavlink.serves(d)) {
            Some(m) => m.mavlink.odometry(d),
            None => Some(sim.with_fleet(|f| f.odometry(d))),
        };
        let summary = summary(self.mission, backend, &odometry, &stats);
        (outcome, summary)
    }
}

/// Shows the summary and how the mission ended; the exit code: 0 for a mission ended
/// `ok`, 1 for any other end, 3 when the trace is not whole.
fn finish(
    args: &RunArgs,
    server: Option<&aviary_server::Server>,
    outcome: &Outcome,
    summary: &str,
    trace: &SharedTrace,
) -> u8 {
    if let Some(s) = server {
        s.finish(std::time::Duration::from_secs(2));
    }
    if !args.quiet {
        out!("{summary}");
        match &outcome.reason {
            Some(reason) => outln!("mission {}: {reason}", outcome.status.as_str()),
            None => outln!("mission {}", outcome.status.as_str()),
        }
    }
    if let Some(why) = lock(trace).failed() {
        eprintln!(
            "aviary: the trace {} is not whole: {why}",
            args.trace.as_ref().map(|p| p.display().to_string()).unwrap_or_default()
        );
        return 3;
    }
    u8::from(outcome.status != Status::Ok)
}

/// The first Ctrl-C, SIGTERM or SIGHUP ends the mission gracefully: the fleet returns
/// home and the trace is closed with `mission_end`. SIGTERM and SIGHUP count as a first
/// Ctrl-C because they are how a session ends without a keyboard (a closed laptop lid,
/// a logout, a service manager): with MAVLink drones, stopping at once would leave them
/// without a ground station. A second signal of any of the three stops at once, still
/// closing the trace.
fn on_stop_signals(
    controller: Controller,
    stop: tokio::sync::watch::Sender<Option<&'static str>>,
    trace: SharedTrace,
) {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = match signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("aviary: Ctrl-C, SIGTERM and SIGHUP will stop at once: {e}");
            return;
        }
    };
    let spawned = std::thread::Builder::new().name("stop-signals".into()).spawn(move || {
        let mut presses = 0usize;
        for signal in signals.forever() {
            let by = match signal {
                SIGTERM => "SIGTERM",
                SIGHUP => "SIGHUP",
                _ => "Ctrl-C",
            };
            presses += 1;
            if presses == 1 {
                eprintln!("\naviary: stopping ({by}); the fleet returns home (press Ctrl-C again to stop at once)");
                controller.send(Control::Abort { reason: format!("interrupted by {by}") });
                stop.send_replace(Some(by));
            } else {
                lock(&trace).close_now(&format!("stopped at once by a second {by}"));
                std::process::exit(130);
            }
        }
    });
    if let Err(e) = spawned {
        eprintln!("aviary: Ctrl-C, SIGTERM and SIGHUP will stop at once: {e}");
    }
}

/// A panic in the simulator's task ends the mission at once, `failed`, with the reason.
async fn watch_backend(driver: Option<tokio::task::JoinHandle<()>>, controller: Controller) {
    if let Some(handle) = driver {
        if let Err(e) = handle.await {
            if e.is_panic() {
                controller.send(Control::BackendLost {
                    reason: "the simulator stopped: its task panicked".into(),
                });
            }
        }
    }
    std::future::pending::<()>().await
}
