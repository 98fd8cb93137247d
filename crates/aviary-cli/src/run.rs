//! `aviary run`: check, compile and fly a mission on the drones its world binds (the
//! built-in simulator), with a live progress line, a JSON Lines trace and a summary.

use std::io::Write;
use std::path::PathBuf;

use aviary_api::trace::{Event, Record};
use aviary_api::Backend;
use aviary_diagnostics::{render_text, SourceMap};
use aviary_engine::{Control, Controller, Outcome, RunOptions, Status};
use aviary_sim::{Fleet, SimBackend, SimOptions};
use indicatif::{ProgressBar, ProgressStyle};

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
    let roots = match use_roots(&args.use_root) {
        Ok(r) => r,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let bytes = match std::fs::read(&args.file) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("aviary: cannot read {}: {e}", args.file.display());
            return 2;
        }
    };
    let provider = match DiskProvider::new(&args.file, &roots) {
        Ok(p) => p,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let Some(world_path) = args.world.clone().or_else(|| world_beside(&args.file)) else {
        let stem =
            args.file.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        eprintln!(
            "aviary: {} has no world file: put {stem}.world.toml beside it, or pass --world FILE",
            args.file.display()
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
    let mut sources = SourceMap::new();
    let name = args.file.display().to_string();
    let world_name = world_path.display().to_string();
    let api = aviary_sim::descriptor();
    let checked = aviary_check::check_sources(
        &mut sources,
        (&name, &bytes),
        Some((&world_name, &world_bytes)),
        &provider,
        &api,
    );
    if checked.has_errors() {
        for d in checked.diagnostics.iter().filter(|d| d.is_error()) {
            eprint!("{}", render_text(&sources, d, color_wanted()));
        }
        eprintln!("aviary: {} has errors, so it was not run", args.file.display());
        return 2;
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
    let (Some(program), Some(world)) = (checked.program, checked.world) else { return 2 };
    let Some(mission) = aviary_lower::compile(&program, &world, &api) else {
        eprintln!(
            "aviary: {} has no MISSION to run (it holds only capabilities)",
            args.file.display()
        );
        return 2;
    };
    drop(program);
    let out: Box<dyn Write + Send> = match &args.trace {
        Some(path) => match std::fs::File::create(path) {
            Ok(f) => Box::new(f),
            Err(e) => {
                eprintln!("aviary: cannot write the trace {}: {e}", path.display());
                return 2;
            }
        },
        None => Box::new(std::io::sink()),
    };
    let trace = TraceFile::new(
        out,
        args.trace.as_ref().map(|p| p.display().to_string()).unwrap_or_default(),
        mission.name.clone(),
    );
    // Any MAVLink drone: the wall clock, and the simulated drones in real time with it.
    let live = !aviary_mavlink::bindings(&world).is_empty();
    if live && args.speed.is_some() {
        eprintln!(
            "aviary: {} has MAVLink drones, which fly in real time: leave out --speed",
            world_path.display()
        );
        return 2;
    }
    // Simulated drones only: the fleet takes the world's drones where they lie. With
    // MAVLink drones the world is kept to connect them.
    let (fleet, world) =
        if live { (Fleet::new(&world), Some(world)) } else { (Fleet::from_world(world), None) };
    // The chances the world asks for (a sensor's `probability`, a fault's range of
    // times) are drawn from the seed.
    let fleet = fleet.seeded(args.seed);
    let runtime = match if live {
        aviary_backends::live_runtime()
    } else {
        tokio::runtime::Builder::new_current_thread().enable_time().start_paused(true).build()
    } {
        Ok(r) => r,
        Err(e) => {
            eprintln!("aviary: cannot start the runtime: {e}");
            return 2;
        }
    };
    let (controller, controls) = Controller::new();
    // The first stop signal, also seen before the engine runs (while vehicles connect).
    let (stop_tx, stop_rx) = tokio::sync::watch::channel(None::<&'static str>);
    on_stop_signals(controller.clone(), stop_tx, trace.clone());
    let server = match args
        .serve
        .as_ref()
        .map(|serve| crate::serve::start(serve, &mission, controller.clone()))
        .transpose()
    {
        Ok(s) => s,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let feed = server.as_ref().map(|s| s.feed.clone());
    // The operator's view of the drones comes from telemetry events.
    let telemetry_hz = args.telemetry_hz.or(server.as_ref().map(|_| 2.0));
    let progress = progress_bar(args.quiet);
    let ran = runtime.block_on(async {
        let sim = SimBackend::start_with(fleet, SimOptions { speed: args.speed, ..SimOptions::default() });
        let mixed = match &world {
            Some(world) => {
                let mut stop = stop_rx.clone();
                // A stop while the vehicles connect is answered at once: nothing has
                // flown, so there is nothing to bring home.
                let mavlink = tokio::select! {
                    connected = aviary_mavlink::connect(world, aviary_mavlink::Tuning::default()) => connected?,
                    by = stop.wait_for(Option::is_some) => {
                        let by = by.ok().and_then(|b| *b).unwrap_or("a stop signal");
                        let reason = format!("stopped by {by} while the vehicles connected; nothing flew");
                        lock(&trace).close_now(&reason);
                        return Ok((Outcome { status: Status::Aborted, reason: Some(reason) }, String::new()));
                    }
                };
                if let Some(sources) = &sources {
                    crate::figures::before_flight(&mission, world, mavlink.facts(), sources, args.quiet);
                }
                Some(aviary_backends::Mixed::new(sim.clone(), mavlink))
            }
            None => None,
        };
        // The backends keep what they need of the world: a large fleet's is not held
        // through the flight.
        drop(world);
        drop(sources);
        let backend: &dyn Backend = match &mixed {
            Some(m) => m,
            None => &*sim,
        };
        let watch = watch_backend(sim.take_driver(), controller.clone());
        let mut stats = Stats::default();
        let mut sink = |record: &Record| {
            stats.observe(record, &progress, backend, mission.drones.len());
            lock(&trace).write(record);
            if let Some(feed) = &feed {
                feed.publish(record);
            }
        };
        let options = RunOptions { telemetry_hz, ..RunOptions::default() };
        let outcome = tokio::select! {
            biased;
            outcome = aviary_engine::run_controlled(&mission, backend, &mut sink, &options, controls) => outcome,
            _ = watch => unreachable!("the watch never ends"),
        };
        sim.stop();
        // A MAVLink drone's distance and flight time come from the track it reported.
        let odometry = |d: usize| match mixed.as_ref().filter(|m| m.mavlink.serves(d)) {
            Some(m) => m.mavlink.odometry(d),
            None => Some(sim.with_fleet(|f| f.odometry(d))),
        };
        let summary = summary(&mission, backend, &odometry, &stats);
        Ok::<_, String>((outcome, summary))
    });
    let (outcome, summary) = match ran {
        Ok(r) => r,
        Err(why) => {
            progress.finish_and_clear();
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    progress.finish_and_clear();
    if let Some(s) = &server {
        s.finish(std::time::Duration::from_secs(2));
    }
    if !args.quiet {
        out!("{summary}");
        match &outcome.reason {
            Some(reason) => outln!("mission {}: {reason}", outcome.status.as_str()),
            None => outln!("mission {}", outcome.status.as_str()),
        }
    }
    if let Some(why) = lock(&trace).failed() {
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

fn progress_bar(quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar
}

/// What the summary counts, from the trace as it is written.
#[derive(Default)]
struct Stats {
    running: i64,
    signals: Vec<(String, usize)>,
    exceptions: Vec<(String, bool)>,
    detections: usize,
    last_shown: f64,
}

impl Stats {
    fn observe(
        &mut self,
        record: &Record,
        progress: &ProgressBar,
        backend: &dyn Backend,
        drones: usize,
    ) {
        match &record.event {
            Event::CapabilityStart { .. } => self.running += 1,
            Event::CapabilityEnd { .. } => self.running -= 1,
            Event::Detection { .. } => self.detections += 1,
            Event::Signal { name, .. } => match self.signals.iter_mut().find(|(n, _)| n == name) {
                Some((_, count)) => *count += 1,
                None => self.signals.push((name.to_string(), 1)),
            },
            Event::Exception { name, handled, .. } => {
                self.exceptions.push((name.to_string(), *handled))
            }
            _ => {}
        }
        let t = if record.t.is_finite() { record.t } else { 0.0 };
        let ended = matches!(record.event, Event::MissionEnd { .. });
        if t - self.last_shown >= 1.0 || ended {
            self.last_shown = t;
            let flying = (0..drones).filter(|d| backend.telemetry(*d).state.airborne()).count();
            progress.set_message(format!(
                "t = {t:7.1} s   activities running: {:3}   drones in the air: {flying}",
                self.running
            ));
            progress.tick();
        }
    }
}

fn summary(
    mission: &aviary_ir::Mission,
    backend: &dyn Backend,
    odometry: &dyn Fn(usize) -> Option<(f64, f64)>,
    stats: &Stats,
) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "{:<16} {:>12} {:>12} {:>9}  {}\n",
        "drone", "distance m", "flight s", "battery", "state"
    ));
    for (d, name) in mission.drones.iter().enumerate() {
        let t = backend.telemetry(d);
        let (distance, airborne) = match odometry(d) {
            Some((m, s)) => (format!("{m:.0}"), format!("{s:.0}")),
            None => ("-".to_owned(), "-".to_owned()),
        };
        // A drone without a link is not shown as what it last said (often `Flying`):
        // what it does now is unknown, so the summary says so and where it was last seen.
        let state = if t.link {
            t.state.as_str().to_owned()
        } else {
            let p = t.position;
            format!(
                "no link: last seen {} at ({:.0}, {:.0}, {:.0})",
                t.state.as_str(),
                p[0],
                p[1],
                p[2]
            )
        };
        out.push_str(&format!(
            "{name:<16} {distance:>12} {airborne:>12} {:>8.0}%  {state}\n",
            t.battery * 100.0
        ));
    }
    let signals: Vec<String> = stats
        .signals
        .iter()
        .map(|(n, c)| if *c == 1 { n.clone() } else { format!("{n} ×{c}") })
        .collect();
    out.push_str(&format!(
        "signals: {}\n",
        if signals.is_empty() { "none".to_string() } else { signals.join(", ") }
    ));
    out.push_str(&format!("detections: {}\n", stats.detections));
    let exceptions: Vec<String> = stats
        .exceptions
        .iter()
        .map(|(n, h)| format!("{n} ({})", if *h { "handled" } else { "unhandled" }))
        .collect();
    out.push_str(&format!(
        "exceptions: {}\n",
        if exceptions.is_empty() { "none".to_string() } else { exceptions.join(", ") }
    ));
    out
}
