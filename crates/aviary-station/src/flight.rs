//! A flight started from the page: the mission and world texts the page holds, flown
//! through the same pipeline as `aviary run` (`aviary_pipeline::fly`) on a thread of its
//! own, its events fed to the operator API of that run, which the station serves while it
//! flies and after it has ended, until the next flight.

use std::sync::Arc;

use aviary_api::trace::Record;
use aviary_api::Backend;
use aviary_check::SourceProvider;
use aviary_engine::{Controller, RunOptions};
use aviary_ir::Mission;
use aviary_pipeline::pipeline::{Hooks, NotFlown, Options, Source, Stop, Texts};
use aviary_pipeline::trace_file::{Cut, SharedTrace, TraceFile, DEFAULT_MAX_BYTES};
use aviary_server::Feed;
use aviary_world::World;

use crate::checking::{map_of, Text};
use crate::wire::{VehiclePlan, VehicleWarning};
use crate::{Mode, Station};

/// The telemetry rate of a flight from the page, unless it asks for another: smooth
/// enough to watch and to replay.
pub const TELEMETRY_HZ: f64 = 4.0;

/// What the page asks to fly.
#[derive(Debug, serde::Deserialize)]
pub struct Request {
    pub mission: Text,
    pub world: Text,
    /// Times real time; `None` as fast as the machine goes.
    pub speed: Option<f64>,
    #[serde(default)]
    pub seed: u64,
    /// Telemetry samples per drone per second of mission time, 1 to 20 (default 4).
    pub telemetry_hz: Option<f64>,
}

/// Flies `request` on a new thread. The run's routes are installed as the mission
/// starts; `Err` is why it could not start (the page shows it).
pub fn start(
    station: Arc<Station>,
    request: Request,
    tree: serde_json::Value,
    files: Box<dyn SourceProvider + Send>,
    trace: Trace,
) -> Result<(), String> {
    if let Some(speed) = request.speed {
        if !(speed.is_finite() && speed > 0.0 && speed <= 1000.0) {
            return Err(format!("{speed} is not a speed: give a number of times real time, from just above 0 to 1000, or none for as fast as possible"));
        }
    }
    let telemetry_hz = request.telemetry_hz.unwrap_or(TELEMETRY_HZ);
    if !(1.0..=20.0).contains(&telemetry_hz) {
        return Err(format!(
            "{telemetry_hz} is not a telemetry rate: give 1 to 20 samples a second"
        ));
    }
    if station.flying.swap(true, std::sync::atomic::Ordering::SeqCst) {
        return Err("a mission is flying: wait for its end, or abort it, before the next".into());
    }
    let (ready, started) = std::sync::mpsc::channel::<Result<(), String>>();
    let landed = station.clone();
    let flying = station.clone();
    let spawned = std::thread::Builder::new()
        .name("aviary-flight".into())
        .stack_size(aviary_check::STACK)
        .spawn(move || {
            let options = Options {
                speed: request.speed,
                seed: request.seed,
                run: RunOptions { telemetry_hz: Some(telemetry_hz), ..RunOptions::default() },
                ..Options::default()
            };
            let texts = Texts {
                mission: Source {
                    name: &request.mission.path,
                    bytes: request.mission.text.into_bytes(),
                },
                world: Source { name: &request.world.path, bytes: request.world.text.into_bytes() },
                files: &*files,
            };
            let mut hooks = Flight {
                station: flying,
                tree,
                feed: None,
                ready: Some(ready),
                trace,
                file: None,
                controller: None,
                bounds: None,
                live: false,
            };
            let flown = aviary_pipeline::fly(texts, &options, &mut hooks);
            landed.flying.store(false, std::sync::atomic::Ordering::SeqCst);
            let why = match flown {
                Ok(_) => return,
                Err(NotFlown::Errors { .. }) => "the mission has errors: check it".to_string(),
                Err(NotFlown::NoMission) => "the file holds no MISSION to fly".into(),
                Err(NotFlown::Speed) => {
                    "the world has MAVLink drones, which fly in real time: fly without a speed"
                        .into()
                }
                Err(NotFlown::Failed(why)) => why,
            };
            match hooks.ready.take() {
                Some(ready) => {
                    let _ = ready.send(Err(why));
                }
                // Started, then ended before the engine ran (the MAVLink vehicles did not
                // connect): the page hears no `mission_end`, so the operator is told here.
                None => eprintln!("aviary: the flight from the page ended before it flew: {why}"),
            }
        });
    if let Err(e) = spawned {
        station.flying.store(false, std::sync::atomic::Ordering::SeqCst);
        return Err(format!("cannot start the flight: {e}"));
    }
    // The answer comes once the mission starts, or with why it did not.
    started.recv().unwrap_or_else(|_| Err("the flight stopped before it started".into()))
}

/// Where a flight's trace goes: a new file of the station's folder, by its name there
/// (as the page shows it).
pub struct Trace {
    pub shown: String,
}

struct Flight {
    station: Arc<Station>,
    tree: serde_json::Value,
    feed: Option<Feed>,
    ready: Option<std::sync::mpsc::Sender<Result<(), String>>>,
    trace: Trace,
    file: Option<SharedTrace>,
    /// The flight's, once it starts: a trace at its size limit stops it.
    controller: Option<Controller>,
    /// Where the world lets the operator send a drone, from `compiled` for `starting`.
    bounds: Option<aviary_server::Bounds>,
    /// The world has MAVLink drones: the plan is made again when they answer.
    live: bool,
}

impl Hooks for Flight {
    fn compiled(&mut self, mission: &Mission, world: &World) -> Result<(), String> {
        self.station.set_map(map_of(world));
        self.bounds = Some(aviary_server::Bounds::of(world));
        self.live =
            world.drones.iter().any(|d| matches!(d.backend, aviary_world::Backend::Mavlink(_)));
        // Made as every file of the folder is reached: checked by `Folder::place`.
        let Mode::Folder { folder, .. } = &self.station.mode else {
            return Err("a flight from the page needs the station's folder".into());
        };
        let out = folder
            .record(&self.trace.shown)
            .map_err(|why| format!("cannot write the trace: {why}"))?;
        self.file = Some(TraceFile::new(
            Box::new(out),
            self.trace.shown.clone(),
            mission.name.clone(),
            DEFAULT_MAX_BYTES,
        ));
        Ok(())
    }

    fn starting(
        &mut self,
        mission: &Mission,
        controller: &Controller,
        _stop: &Stop,
    ) -> Result<(), String> {
        self.controller = Some(controller.clone());
        let tree = std::mem::take(&mut self.tree);
        let trace = Some(self.trace.shown.clone());
        let Some(bounds) = self.bounds.take() else {
            return Err("the flight starts before its world was read".into());
        };
        self.feed = Some(self.station.start_run(controller.clone(), mission, bounds, tree, trace));
        if self.live {
            self.station.set_vehicle_plan(VehiclePlan::Due);
        }
        if let Some(ready) = self.ready.take() {
            let _ = ready.send(Ok(()));
        }
        Ok(())
    }

    /// The plan again with the vehicles' figures, as `aviary run` makes it: its warnings
    /// go to the page, which shows each as an alarm before the drones are far.
    fn connected(
        &mut self,
        replan: &aviary_pipeline::replan::Replan,
        _sources: &aviary_diagnostics::SourceMap,
    ) {
        let mut warnings: Vec<VehicleWarning> = replan
            .low_reserve
            .iter()
            .map(|d| {
                let text = match &d.help {
                    Some(help) => format!("{} ({help})", d.message),
                    None => d.message.clone(),
                };
                VehicleWarning { drone: None, code: d.code.as_str(), text, severe: false }
            })
            .collect();
        warnings.extend(replan.runs_out.iter().map(|r| {
            let drone = Some(r.drone.to_string());
            VehicleWarning { drone, code: "W204", text: r.warning(), severe: true }
        }));
        self.station.set_vehicle_plan(VehiclePlan::Made(warnings));
    }

    fn record(&mut self, record: &Record<'_>, _backend: &dyn Backend) {
        if let Some(file) = &self.file {
            let cut = file.lock().write(record);
            match cut {
                Some(Cut::Failed(why)) => eprintln!("aviary: {why}; the flight goes on without it"),
                // As `aviary run`'s: a flight that makes events without end stops, and its
                // fleet comes home.
                Some(full @ Cut::Full { .. }) => {
                    eprintln!("aviary: {full}; the flight stops and its fleet returns home");
                    if let Some(controller) = &self.controller {
                        controller.interrupt(full.to_string());
                    }
                }
                None => {}
            }
        }
        if let Some(feed) = &self.feed {
            feed.publish(record);
        }
    }
}
