//! `aviary run`: check, compile and fly a mission on the drones its world binds (the
//! built-in simulator), with a live progress line, a JSON Lines trace and a summary.
//! The pipeline is `aviary_pipeline::fly`'s; here are the files, the terminal, the
//! signals and the operator server, through the pipeline's hooks.

use std::io::Write;
use std::path::PathBuf;

use aviary_api::trace::{Event, RaisedBy, Record};
use aviary_api::{Backend, DroneId};
use aviary_diagnostics::{render_text, SourceMap};
use aviary_engine::{Controller, RunOptions, Status};
use aviary_ir::Mission;
use aviary_pipeline::pipeline::{Hooks, NotFlown, Options, Source, Stop, Texts};
use aviary_world::World;
use indicatif::{ProgressBar, ProgressStyle};

use crate::files::{color_wanted, use_roots, world_beside, DiskProvider};
use aviary_pipeline::trace_file::{show_size, Cut, SharedTrace, TraceFile};

pub struct RunArgs {
    pub file: PathBuf,
    pub world: Option<PathBuf>,
    /// `None`: as fast as possible.
    pub speed: Option<f64>,
    /// The simulator's seed: every chance the world asks for is drawn from it.
    pub seed: u64,
    pub trace: Option<PathBuf>,
    /// `--max-trace-size`: the most the trace may hold, in bytes.
    pub max_trace_bytes: u64,
    pub telemetry_hz: Option<f64>,
    pub quiet: bool,
    /// Where to serve the operator API.
    pub serve: Option<crate::serve::Serve>,
    /// `--zenoh`: the mission on Zenoh too.
    pub zenoh: Option<Zenoh>,
    /// Folders whose .mission files USE may read, besides the mission's own.
    pub use_root: Vec<PathBuf>,
    /// What a run with MAVLink drones keeps time by.
    pub clock: aviary_pipeline::pipeline::LiveClock,
}

/// `--zenoh [CONFIG]` and `--zenoh-prefix KEY`.
pub struct Zenoh {
    /// Zenoh's JSON5 configuration file; Zenoh's defaults without one.
    pub config: Option<PathBuf>,
    /// `None`: `aviary/MISSION`.
    pub keys: Option<aviary_zenoh::Keys>,
    /// `--ros`: also for ROS 2 on rmw_zenoh, in this domain.
    pub ros: Option<u32>,
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

/// A size for `--max-trace-size`: a whole number of bytes, or with a unit: `KiB`, `MiB`,
/// `GiB`, `TiB` (powers of 1024; `K`, `M`, `G`, `T` alone too) or `KB`, `MB`, `GB`, `TB`
/// (powers of 1000), in any case. At least 4 KiB, the room the trace's first and last
/// events need.
pub fn parse_size(text: &str) -> Result<u64, String> {
    let wrong = || {
        format!("`{text}` is not a size for --max-trace-size: write a number of bytes, or one with a unit such as 64KiB, 500MB or 1GiB")
    };
    let digits = text.trim().find(|c: char| !c.is_ascii_digit()).unwrap_or(text.trim().len());
    let (number, unit) = text.trim().split_at(digits);
    let number: u64 = number.parse().map_err(|_| wrong())?;
    let scale: u64 = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1,
        "k" | "kib" => 1 << 10,
        "m" | "mib" => 1 << 20,
        "g" | "gib" => 1 << 30,
        "t" | "tib" => 1 << 40,
        "kb" => 1_000,
        "mb" => 1_000_000,
        "gb" => 1_000_000_000,
        "tb" => 1_000_000_000_000,
        _ => return Err(wrong()),
    };
    let bytes = number.checked_mul(scale).ok_or_else(wrong)?;
    let least = aviary_pipeline::trace_file::MIN_MAX_BYTES;
    if bytes < least {
        return Err(format!(
            "`{text}` is too small for --max-trace-size: a trace needs at least {}",
            show_size(least)
        ));
    }
    Ok(bytes)
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
    let name = args.file.display().to_string();
    let world_name = world_path.display().to_string();
    let texts = Texts {
        mission: Source { name: &name, bytes },
        world: Source { name: &world_name, bytes: world_bytes },
        files: &provider,
    };
    // Opened before the vehicles connect: the world's `agent:NAME` drones are reached on it.
    let session = match args.zenoh.as_ref().map(crate::zenoh::open).transpose() {
        Ok(session) => session,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let options = Options {
        speed: args.speed,
        seed: args.seed,
        // The operator's view of the drones comes from telemetry events.
        run: RunOptions {
            telemetry_hz: args
                .telemetry_hz
                .or((args.serve.is_some() || args.zenoh.is_some()).then_some(2.0)),
            ..RunOptions::default()
        },
        clock: args.clock,
        carrier: session.clone().map(|s| {
            std::sync::Arc::new(aviary_zenoh::Agents::new(s))
                as std::sync::Arc<dyn aviary_mavlink::Carrier>
        }),
    };
    let mut shown = Shown {
        args,
        session,
        trace: None,
        controller: None,
        server: None,
        feed: None,
        zenoh: None,
        map: serde_json::Value::Null,
        bounds: None,
        zenoh_world: None,
        progress: None,
        stats: Stats::default(),
        drones: 0,
        summary: String::new(),
        expected: None,
    };
    let flown = aviary_pipeline::fly(texts, &options, &mut shown);
    let Shown { trace, server, zenoh, progress, summary, expected, .. } = shown;
    if let (Ok(flown), Some(trace)) = (&flown, &trace) {
        if !flown.flew {
            // Stopped while the vehicles connected: the trace is whole all the same.
            if let Some(why) =
                trace.lock().close_now(flown.outcome.reason.as_deref().unwrap_or_default())
            {
                eprintln!("aviary: {why}");
            }
        }
    }
    if let Some(progress) = &progress {
        progress.finish_and_clear();
    }
    let outcome = match flown {
        Ok(flown) => flown.outcome,
        Err(not) => {
            return refused(not, &args.file, &|| {
                format!(
                    "{} has MAVLink drones, which fly in real time: leave out --speed",
                    world_path.display()
                )
            })
        }
    };
    if let Some((_, feed)) = &server {
        feed.finish(std::time::Duration::from_secs(2));
    }
    if let Some((bridge, _)) = zenoh {
        bridge.finish(std::time::Duration::from_secs(2));
    }
    if !args.quiet {
        out!("{summary}");
        match &outcome.reason {
            Some(reason) => outln!("mission {}: {reason}", outcome.status.as_str()),
            None => outln!("mission {}", outcome.status.as_str()),
        }
    }
    // What `[expect]` asks, beyond an `ok` end: each one not met is said, and fails the run.
    let unmet = match expected {
        Some(Expected { observer, expect, targets }) if !expect.is_empty() => {
            let record = observer.finish(args.seed, &outcome, &expect, targets, None);
            let unmet: Vec<String> = expect
                .iter()
                .zip(&record.expectations)
                .filter(|(_, met)| !**met)
                .map(|(e, _)| e.to_string())
                .collect();
            if !unmet.is_empty() {
                outln!("expectation not met: {}", unmet.join(", "));
            } else if !args.quiet {
                let all: Vec<String> = expect.iter().map(ToString::to_string).collect();
                outln!("expectations met: {}", all.join(", "));
            }
            !unmet.is_empty()
        }
        _ => false,
    };
    if let Some(why) = trace.as_ref().and_then(|t| t.lock().failed().map(str::to_owned)) {
        eprintln!(
            "aviary: the trace {} is not whole: {why}",
            args.trace.as_ref().map(|p| p.display().to_string()).unwrap_or_default()
        );
        return 3;
    }
    u8::from(outcome.status != Status::Ok || unmet)
}

/// What a run is held to by its world's `[expect]`, and what it did.
struct Expected {
    observer: aviary_campaign::Observer,
    expect: Vec<aviary_world::Expectation>,
    targets: usize,
}

/// What a run shows as it goes, and where its trace goes: the hooks of the pipeline.
struct Shown<'a> {
    args: &'a RunArgs,
    /// Opened once the mission compiled.
    trace: Option<SharedTrace>,
    /// The run's, once it starts: a trace at its size limit stops the run.
    controller: Option<Controller>,
    /// The station serving this run, and where the run's events go.
    server: Option<(aviary_station::Serving, aviary_server::Feed)>,
    feed: Option<aviary_server::Feed>,
    /// The run's Zenoh session (`--zenoh`), until the bridge takes it.
    session: Option<aviary_zenoh::Session>,
    /// The run on Zenoh, and where its events go.
    zenoh: Option<(aviary_zenoh::Bridge, aviary_server::Feed)>,
    /// The world as the station's map draws it, and where it lets the operator send a
    /// drone, kept from `compiled` for `starting`.
    map: serde_json::Value,
    bounds: Option<aviary_server::Bounds>,
    /// The same, for the operator API on Zenoh.
    zenoh_world: Option<crate::zenoh::Seen>,
    /// Made once the run starts.
    progress: Option<ProgressBar>,
    stats: Stats,
    drones: usize,
    summary: String,
    /// Made as the mission is compiled.
    expected: Option<Expected>,
}

impl Hooks for Shown<'_> {
    fn texts_freed(&mut self) {
        aviary_alloc::give_back();
    }

    fn compiled(&mut self, mission: &Mission, world: &World) -> Result<(), String> {
        if self.args.serve.is_some() {
            self.map = aviary_station::checking::map_of(world);
            self.bounds = Some(aviary_server::Bounds::of(world));
        }
        if self.args.zenoh.is_some() {
            self.zenoh_world = Some(crate::zenoh::Seen::of(world));
        }
        self.expected = Some(Expected {
            observer: aviary_campaign::Observer::new(mission),
            expect: world.expect.clone(),
            targets: world.targets.len(),
        });
        let out: Box<dyn Write + Send> = match &self.args.trace {
            Some(path) => match std::fs::File::create(path) {
                Ok(f) => Box::new(f),
                Err(e) => return Err(format!("cannot write the trace {}: {e}", path.display())),
            },
            None => Box::new(std::io::sink()),
        };
        // Without a file nothing is written, so nothing can fill a disk.
        let limit = match &self.args.trace {
            Some(_) => self.args.max_trace_bytes,
            None => u64::MAX,
        };
        self.trace = Some(TraceFile::new(
            out,
            self.args.trace.as_ref().map(|p| p.display().to_string()).unwrap_or_default(),
            mission.name.clone(),
            limit,
        ));
        Ok(())
    }

    fn starting(
        &mut self,
        mission: &Mission,
        controller: &Controller,
        stop: &Stop,
    ) -> Result<(), String> {
        if let Some(trace) = &self.trace {
            on_stop_signals(controller.clone(), stop.clone(), trace.clone());
        }
        self.controller = Some(controller.clone());
        if let Some(serve) = &self.args.serve {
            let map = std::mem::take(&mut self.map);
            let Some(bounds) = self.bounds.take() else {
                return Err("the run starts before its world was read".into());
            };
            let (serving, feed) =
                crate::serve::start(serve, mission, bounds, map, controller.clone())?;
            self.feed = Some(feed.clone());
            self.server = Some((serving, feed));
        }
        if let (Some(zenoh), Some(session)) = (&self.args.zenoh, self.session.take()) {
            let seen = self.zenoh_world.take().ok_or("the run starts before its world was read")?;
            let token = self.server.as_ref().map(|(serving, _)| serving.token.clone());
            self.zenoh = Some(crate::zenoh::start(
                session,
                zenoh,
                mission,
                seen,
                controller.clone(),
                token,
            )?);
        }
        self.progress = Some(progress_bar(self.args.quiet));
        self.drones = mission.drones.len();
        Ok(())
    }

    fn connected(&mut self, replan: &aviary_pipeline::replan::Replan, sources: &SourceMap) {
        crate::vehicle_figures::before_flight(replan, sources, self.args.quiet);
    }

    fn record(&mut self, record: &Record<'_>, backend: &dyn Backend) {
        if let Some(expected) = &mut self.expected {
            expected.observer.record(record, backend);
        }
        if let Some(progress) = &self.progress {
            self.stats.observe(record, progress, backend, self.drones);
        }
        if let Some(trace) = &self.trace {
            let cut = trace.lock().write(record);
            match cut {
                Some(Cut::Failed(why)) => eprintln!(
                    "\naviary: {why}; the mission goes on without it, and aviary will exit 3"
                ),
                // A mission that makes events without end would fill the disk: it stops,
                // and its fleet comes home.
                Some(full @ Cut::Full { .. }) => {
                    eprintln!("\naviary: {full} (--max-trace-size); the mission stops, the fleet returns home, and aviary will exit 3");
                    if let Some(controller) = &self.controller {
                        controller.interrupt(format!("{full} (--max-trace-size)"));
                    }
                }
                None => {}
            }
        }
        if let Some(feed) = &self.feed {
            feed.publish(record);
        }
        if let Some((_, feed)) = &self.zenoh {
            feed.publish(record);
        }
    }

    fn landed(
        &mut self,
        mission: &Mission,
        backend: &dyn Backend,
        odometry: &dyn Fn(usize) -> Option<(f64, f64)>,
    ) {
        self.summary = summary(mission, backend, odometry, &self.stats);
        if let Some(expected) = &mut self.expected {
            expected.observer.landed(backend);
        }
    }
}

/// How long the engine has to take a first stop before the process ends at once.
const GRACE: std::time::Duration = std::time::Duration::from_secs(5);

/// The first Ctrl-C, SIGTERM or SIGHUP ends the mission gracefully: the fleet returns
/// home and the trace is closed with `mission_end`. SIGTERM and SIGHUP count as a first
/// Ctrl-C because they are how a session ends without a keyboard (a closed laptop lid,
/// a logout, a service manager): with MAVLink drones, stopping at once would leave them
/// without a ground station. A second signal of any of the three stops at once, still
/// closing the trace.
///
/// The stop is an interrupt the engine hears even when it never waits (it looks at it
/// between the steps it takes at one instant). Should it still not take it within
/// [`GRACE`] (busy somewhere it does not look), the process stops at once as on a
/// second signal: a stop must never hang. Once the engine has taken it, the way home
/// may take as long as it takes.
/// Says why a mission was not flown (`aviary run`, `aviary test`), on standard error: its
/// errors, or that it has no MISSION, or the reason; `speed` says why its world's drones
/// cannot fly as asked. The exit code, 2.
pub fn refused(not: NotFlown, file: &std::path::Path, speed: &dyn Fn() -> String) -> u8 {
    match not {
        NotFlown::Errors { diagnostics, sources } => {
            for d in diagnostics.iter().filter(|d| d.is_error()) {
                eprint!("{}", render_text(&sources, d, color_wanted()));
            }
            eprintln!("aviary: {} has errors, so it was not run", file.display());
        }
        NotFlown::NoMission => {
            eprintln!(
                "aviary: {} has no MISSION to run (it holds only capabilities)",
                file.display()
            );
        }
        NotFlown::Speed => eprintln!("aviary: {}", speed()),
        NotFlown::Failed(why) => eprintln!("aviary: {why}"),
    }
    2
}

fn on_stop_signals(controller: Controller, stop: Stop, trace: SharedTrace) {
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
                controller.interrupt(format!("interrupted by {by}"));
                stop.by(by);
                unless_heard(controller.clone(), trace.clone(), by);
            } else {
                if let Some(why) =
                    trace.lock().close_now(&format!("stopped at once by a second {by}"))
                {
                    eprintln!("aviary: {why}");
                }
                std::process::exit(130);
            }
        }
    });
    if let Err(e) = spawned {
        eprintln!("aviary: Ctrl-C, SIGTERM and SIGHUP will stop at once: {e}");
    }
}

/// Ends the process at once, the trace closed, if the engine has not taken the stop
/// within [`GRACE`].
fn unless_heard(controller: Controller, trace: SharedTrace, by: &'static str) {
    let _ = std::thread::Builder::new().name("stop-grace".into()).spawn(move || {
        std::thread::sleep(GRACE);
        if controller.heard() {
            return;
        }
        let reason = format!(
            "stopped at once: the mission did not take the {by} within {} s",
            GRACE.as_secs()
        );
        eprintln!("aviary: {reason}");
        if let Some(why) = trace.lock().close_now(&reason) {
            eprintln!("aviary: {why}");
        }
        std::process::exit(130);
    });
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
    /// Each exception by name, drone and whether it was handled, with how many times: a
    /// handler re-entered at one instant until it was cut off takes its exception a
    /// hundred times over.
    exceptions: Vec<(Raised, usize)>,
    /// What the operator did, and each drone's autopilot on its own, as the summary says
    /// it, in the order it happened.
    operator: Vec<String>,
    autopilot: Vec<String>,
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
        self.count(record);
        let t = if record.t.is_finite() { record.t } else { 0.0 };
        let ended = matches!(record.event, Event::MissionEnd { .. });
        if t - self.last_shown >= 1.0 || ended {
            self.last_shown = t;
            let flying =
                (0..drones).filter(|d| backend.telemetry(DroneId(*d)).state.airborne()).count();
            progress.set_message(format!(
                "t = {t:7.1} s   activities running: {:3}   drones in the air: {flying}",
                self.running
            ));
            progress.tick();
        }
    }

    /// What the summary counts of one event.
    fn count(&mut self, record: &Record) {
        match &record.event {
            Event::CapabilityStart { .. } => self.running += 1,
            Event::CapabilityEnd { .. } => self.running -= 1,
            Event::Detection { .. } => self.detections += 1,
            Event::Signal { name, by, .. } => {
                // A signal the operator raised is one of the operator's actions too.
                if let Some(RaisedBy::Operator) = by {
                    self.operator.push(format!("signal {name} at {:.1} s", record.t));
                }
                match self.signals.iter_mut().find(|(n, _)| n == name) {
                    Some((_, count)) => *count += 1,
                    None => self.signals.push((name.to_string(), 1)),
                }
            }
            Event::Exception { name, actor, handled, .. } => {
                let raised = Raised {
                    name: name.to_string(),
                    actor: actor.as_deref().map(str::to_owned),
                    handled: *handled,
                };
                match self.exceptions.iter_mut().find(|(r, _)| *r == raised) {
                    Some((_, count)) => *count += 1,
                    None => self.exceptions.push((raised, 1)),
                }
            }
            Event::Operator { action, drone } => self.operator.push(match drone {
                Some(d) => format!("{} {d} at {:.1} s", action.as_str(), record.t),
                None => format!("{} at {:.1} s", action.as_str(), record.t),
            }),
            Event::Autopilot { reason, .. } => {
                self.autopilot.push(format!("{reason} (at {:.1} s)", record.t));
            }
            _ => {}
        }
    }
}

fn summary(
    mission: &Mission,
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
        let t = backend.telemetry(DroneId(d));
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
    out.push_str(&what_happened(stats));
    out
}

/// The summary's lines of what happened to whom: exceptions, the operator's actions and
/// what autopilots did on their own.
fn what_happened(stats: &Stats) -> String {
    let mut out = String::new();
    let exceptions: Vec<String> = stats
        .exceptions
        .iter()
        .map(|(r, c)| {
            let handled = if r.handled { "handled" } else { "unhandled" };
            let on = r.actor.as_deref().map(|a| format!(" on {a}")).unwrap_or_default();
            let times = if *c == 1 { String::new() } else { format!(" ×{c}") };
            format!("{}{on} ({handled}){times}", r.name)
        })
        .collect();
    let listed = |items: &[String], separator: &str| {
        if items.is_empty() {
            "none".to_string()
        } else {
            items.join(separator)
        }
    };
    out.push_str(&format!("exceptions: {}\n", listed(&exceptions, ", ")));
    out.push_str(&format!("operator actions: {}\n", listed(&stats.operator, ", ")));
    if !stats.autopilot.is_empty() {
        out.push_str(&format!("autopilot, on its own: {}\n", listed(&stats.autopilot, "; ")));
    }
    out
}

/// An exception as the summary counts it: by name, drone (none for a `THROW` at mission
/// level) and whether a handler took it.
#[derive(PartialEq)]
struct Raised {
    name: String,
    actor: Option<String>,
    handled: bool,
}

#[cfg(test)]
mod tests {
    use super::{what_happened, Stats};

    #[test]
    fn the_summary_names_each_exceptions_drone_and_lists_what_the_operator_and_autopilots_did() {
        let mut stats = Stats::default();
        for line in [
            r#"{"t":3.0,"event":"operator","action":"hold","drone":"a"}"#,
            r#"{"t":4.25,"event":"operator","action":"resume","drone":"a"}"#,
            r#"{"t":4.5,"event":"signal","name":"Go_Home","actor":null,"args":[],"by":"operator"}"#,
            r#"{"t":4.75,"event":"signal","name":"Found","actor":"a","args":[]}"#,
            r#"{"t":5.0,"event":"exception","name":"ConnectionLost","actor":"b","args":["b: link lost"],"handled":true,"handler":"M/ON EXCEPTION ConnectionLost"}"#,
            r#"{"t":5.0,"event":"autopilot","actor":"b","action":"hold","reason":"b: link lost: holds where it is"}"#,
            r#"{"t":6.0,"event":"exception","name":"CommandFailed","actor":"a","args":["no"],"handled":true,"handler":"H"}"#,
            r#"{"t":6.0,"event":"exception","name":"CommandFailed","actor":"a","args":["no"],"handled":true,"handler":"H"}"#,
            r#"{"t":7.0,"event":"exception","name":"Late","actor":null,"args":[],"handled":false,"handler":null}"#,
            r#"{"t":8.0,"event":"operator","action":"abort","drone":null}"#,
        ] {
            stats.count(&serde_json::from_str(line).expect("a trace line"));
        }
        assert_eq!(
            what_happened(&stats),
            "exceptions: ConnectionLost on b (handled), CommandFailed on a (handled) ×2, \
             Late (unhandled)\n\
             operator actions: hold a at 3.0 s, resume a at 4.2 s, signal Go_Home at 4.5 s, \
             abort at 8.0 s\n\
             autopilot, on its own: b: link lost: holds where it is (at 5.0 s)\n"
        );
        assert_eq!(
            what_happened(&Stats::default()),
            "exceptions: none\noperator actions: none\n",
            "no autopilot line when no autopilot acted"
        );
    }
}
