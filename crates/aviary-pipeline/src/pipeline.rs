//! A run's whole pipeline, [`fly`]: from the texts of a mission and its world to the end
//! of the flight. The front end (the world, the check), the compiler, the backends the
//! world binds (the simulator; with MAVLink drones, the vehicles too, behind [`Mixed`])
//! and the engine. `aviary run` and the scale benchmarks (`aviary bench w`, `bench swarm`)
//! call this one function, so a benchmark measures what a user runs, and a change to the
//! pipeline is a change to both.
//!
//! Texts in, an outcome and diagnostics out: the caller reads the files, and writes the
//! trace and shows the run through its [`Hooks`], which hear each stage as it passes.

use std::borrow::Cow;
use std::convert::Infallible;
use std::sync::Arc;

use aviary_api::trace::{EventKind, Record, Status};
use aviary_api::{Backend, DroneId};
use aviary_check::SourceProvider;
use aviary_diagnostics::{Diagnostic, SourceMap};
use aviary_engine::{Control, Controller, Outcome, RunOptions, TraceSink};
use aviary_ir::Mission;
use aviary_sim::{Fleet, SimBackend, SimOptions};
use aviary_world::World;
use tokio::sync::watch;

use crate::{live_runtime, simulated_runtime, Mixed};

/// One file, as read: its name (as diagnostics show it) and its bytes, handed over (valid
/// UTF-8 becomes the text without a copy: a large world's file is megabytes).
pub struct Source<'a> {
    pub name: &'a str,
    pub bytes: Vec<u8>,
}

/// What a run starts from.
pub struct Texts<'a> {
    pub mission: Source<'a>,
    pub world: Source<'a>,
    /// The files the mission `USE`s (the CLI's reads the disk under the rules of
    /// `aviary_check::uses`) and those the world's `[imports]` names.
    pub files: &'a dyn SourceProvider,
}

/// How to fly.
#[derive(Clone, Default)]
pub struct Options {
    /// Times real time; `None`, as fast as possible, on the virtual clock. A world
    /// with MAVLink drones flies in real time (the vehicles' pace) and refuses any other
    /// speed than 1.
    pub speed: Option<f64>,
    /// The simulator's seed: every chance the world asks for is drawn from it.
    pub seed: u64,
    /// The engine's options (telemetry events, ...).
    pub run: RunOptions,
    /// What the time of a run with MAVLink drones follows.
    pub clock: LiveClock,
    /// What reaches the agents of the world's `agent:NAME` drones (Zenoh, for
    /// `aviary run --zenoh`); without one, such a drone is an error at connect.
    pub carrier: Option<Arc<dyn aviary_mavlink::Carrier>>,
}

/// The clock of a run with MAVLink drones: its `Hover`, `WAITFOR ELAPSED`, `ON EVERY`,
/// trace times, link timeouts and simulated drones all keep it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LiveClock {
    /// The vehicles' own (`aviary_mavlink::clock`): a SITL that runs faster than real
    /// time has a mission that does too. Real vehicles keep real time, and so does this.
    #[default]
    Vehicles,
    /// The wall clock, whatever the vehicles' say.
    Wall,
}

/// The stages of [`fly`], in order, each announced as it begins and ends
/// ([`Hooks::begin`], [`Hooks::end`]); `aviary bench` times them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The world file, TOML to `World`.
    World,
    /// The mission: parse, load, infer, walk (`aviary_check`).
    Check,
    /// The source texts dropped, and the memory given back to the system by whoever
    /// runs the process ([`Hooks::texts_freed`]). Not with MAVLink drones: their
    /// warnings point into the texts.
    FreeTexts,
    /// `aviary_lower::compile`.
    Compile,
    /// The checked tree dropped.
    FreeTree,
    /// The simulator's fleet (the physics core of every drone) and its driver.
    SimStart,
    /// The engine's run, the mission's start to its end with the fleet home.
    Flight,
}

/// What the caller of [`fly`] hears and does as the run goes. Everything but
/// [`Hooks::record`] is optional.
pub trait Hooks {
    fn begin(&mut self, _stage: Stage) {}
    fn end(&mut self, _stage: Stage) {}

    /// The source texts have been dropped (a large world's text is megabytes): a process
    /// that owns its allocator gives the memory back to the system here (`aviary run`
    /// and `aviary bench` call `aviary_alloc::give_back`); a library never does.
    fn texts_freed(&mut self) {}

    /// The mission compiled for its world and nothing has started: the caller opens where
    /// its trace goes. An `Err` ends the run here, with that reason ([`NotFlown::Failed`]).
    fn compiled(&mut self, _mission: &Mission, _world: &World) -> Result<(), String> {
        Ok(())
    }

    /// The runtime is up; `controller` reaches the engine once it runs (an operator, a
    /// signal), and `stop` ends the run while MAVLink vehicles connect, before the
    /// engine hears controls. The backends start next. An `Err` ends the run here.
    fn starting(
        &mut self,
        _mission: &Mission,
        _controller: &Controller,
        _stop: &Stop,
    ) -> Result<(), String> {
        Ok(())
    }

    /// The MAVLink vehicles answered, with their own figures, and the plan was made again
    /// with them; nothing has flown yet. `sources` holds the texts, for diagnostics that
    /// point into them.
    fn connected(&mut self, _replan: &crate::replan::Replan, _sources: &SourceMap) {}

    /// As [`TraceSink::wants`]: asked once per kind as the engine starts.
    fn wants(&self, _kind: EventKind) -> bool {
        true
    }

    /// Each trace event, as the engine makes it, with the backend that flies the drones
    /// (to read their telemetry).
    fn record(&mut self, record: &Record<'_>, backend: &dyn Backend);

    /// The flight has ended, the fleet home: what the backend says of each drone now, and
    /// each one's distance (m) and time in the air (s), `None` where nobody knows.
    fn landed(
        &mut self,
        _mission: &Mission,
        _backend: &dyn Backend,
        _odometry: &dyn Fn(usize) -> Option<(f64, f64)>,
    ) {
    }
}

/// Ends a run while its MAVLink vehicles connect (a first Ctrl-C): nothing has flown, so
/// the run ends at once, `aborted` ([`Flown::flew`] false). Once the engine runs, a stop
/// is a `Control::Abort` through the `Controller`.
#[derive(Clone)]
pub struct Stop(Arc<watch::Sender<Option<&'static str>>>);

impl Stop {
    /// `by` is what stopped the run, for the reason: `Ctrl-C`, `SIGTERM`.
    pub fn by(&self, by: &'static str) {
        self.0.send_replace(Some(by));
    }
}

/// How a run that started ended.
#[derive(Debug)]
pub struct Flown {
    pub outcome: Outcome,
    /// False when it was stopped while the vehicles connected: the engine never ran, so
    /// the caller's trace has no event yet.
    pub flew: bool,
    /// Seconds of simulated time at the end.
    pub simulated: f64,
}

/// Why a run did not start, or ended before its flight.
pub enum NotFlown {
    /// The files have errors: every diagnostic, and the texts they point into.
    Errors { diagnostics: Vec<Diagnostic>, sources: SourceMap },
    /// The mission file holds only capabilities.
    NoMission,
    /// A speed other than 1 was asked of a world with MAVLink drones, which fly in real
    /// time.
    Speed,
    /// Anything else: the runtime, a hook, the vehicles' connection.
    Failed(String),
}

/// Checks, compiles and flies the mission of `texts` on the drones its world binds (the
/// simulator; with MAVLink drones, in real time, the vehicles too), feeding every trace
/// event to `hooks`. A mission with errors is refused before anything starts.
///
/// The source texts go once the mission checks clean (unless MAVLink drones need them for
/// their warnings), the tree once it is compiled, and a world of simulated drones is
/// given up to the simulator's fleet, each drone where it lies
/// ([`aviary_sim::Fleet::from_world`]): a large world and its fleet are never held whole
/// at once. Runs on the calling thread, which needs the stack of
/// `aviary_check::STACK`: the checker and the engine follow capability calls by recursion.
pub fn fly(texts: Texts<'_>, options: &Options, hooks: &mut dyn Hooks) -> Result<Flown, NotFlown> {
    // The trace names the world it was flown in, so that a replay draws that one.
    let stamp = aviary_api::trace::WorldStamp::of(texts.world.name, &texts.world.bytes);
    let run = RunOptions { world: Some(stamp), ..options.run.clone() };
    let (program, world, sources) = front_end(texts, hooks)?;
    // Any MAVLink drone: the wall clock, and the simulated drones in real time with it.
    let live = !aviary_mavlink::bindings(&world).is_empty();
    // The source texts are needed only to show errors: they go before the mission is
    // compiled (a large world's text is megabytes). With MAVLink drones the plan is made
    // again with the vehicles' figures, and its warnings point into them.
    let sources = if live {
        Some(sources)
    } else {
        hooks.begin(Stage::FreeTexts);
        drop(sources);
        hooks.texts_freed();
        hooks.end(Stage::FreeTexts);
        None
    };
    hooks.begin(Stage::Compile);
    let mission = aviary_lower::compile(&program, &world);
    hooks.end(Stage::Compile);
    let Some(mission) = mission else { return Err(NotFlown::NoMission) };
    hooks.begin(Stage::FreeTree);
    drop(program);
    hooks.end(Stage::FreeTree);
    hooks.compiled(&mission, &world).map_err(NotFlown::Failed)?;
    // 1 is real time, which a served run asks by default: a live run keeps it anyway.
    if live && options.speed.is_some_and(|x| x != 1.0) {
        return Err(NotFlown::Speed);
    }
    // Every run is on a virtual clock (`aviary_clock`), which moves as fast as it goes, at
    // `speed`, or, with MAVLink drones, at the pace of the wall clock and then of the
    // vehicles' (`aviary_sim::Pace`).
    let pace = live.then(|| Arc::new(aviary_sim::Pace::default()));
    let runtime = match &pace {
        Some(pace) => live_runtime(pace.clone()),
        None => simulated_runtime(options.speed),
    }
    .map_err(|e| NotFlown::Failed(format!("cannot start the runtime: {e}")))?;
    let (controller, controls) = Controller::new();
    // The first stop, also seen before the engine runs (while vehicles connect).
    let (stop, stopped) = watch::channel(None::<&'static str>);
    let stop = Stop(Arc::new(stop));
    hooks.starting(&mission, &controller, &stop).map_err(NotFlown::Failed)?;
    runtime.block_on(async {
        hooks.begin(Stage::SimStart);
        // Simulated drones only: the fleet takes the world's drones where they lie. With
        // MAVLink drones the world is kept to connect them.
        let (fleet, world) =
            if live { (Fleet::new(&world), Some(world)) } else { (Fleet::from_world(world), None) };
        // The chances the world asks for (a sensor's `probability`, a fault's range of
        // times) are drawn from the seed.
        let fleet = fleet.seeded(options.seed);
        let sim = SimBackend::start_with(fleet, SimOptions::default());
        hooks.end(Stage::SimStart);
        let mixed = match &world {
            Some(world) => {
                let mut stopped = stopped.clone();
                // A stop while the vehicles connect is answered at once: nothing has
                // flown, so there is nothing to bring home.
                let mavlink = tokio::select! {
                    connected = aviary_mavlink::connect_through(world, aviary_mavlink::Tuning::default(), options.carrier.as_deref()) => {
                        connected.map_err(NotFlown::Failed)?
                    }
                    by = stopped.wait_for(Option::is_some) => {
                        let by = by.ok().and_then(|b| *b).unwrap_or("a stop signal");
                        let reason = format!("stopped by {by} while the vehicles connected; nothing flew");
                        let outcome = Outcome { status: Status::Aborted, reason: Some(reason), at: None };
                        return Ok(Flown { outcome, flew: false, simulated: sim.time() });
                    }
                };
                if let Some(sources) = &sources {
                    let replan = crate::replan::replan(&mission, world, mavlink.facts());
                    hooks.connected(&replan, sources);
                }
                if let (Some(pace), LiveClock::Vehicles) = (&pace, options.clock) {
                    let mut clocks = mavlink.clocks();
                    pace.follow(Box::new(move || clocks.moved()));
                }
                Some(Mixed::new(sim.clone(), mavlink))
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
        hooks.begin(Stage::Flight);
        let mut sink = Sink { hooks: &mut *hooks, backend };
        let outcome = tokio::select! {
            biased;
            outcome = aviary_engine::run_controlled(&mission, backend, &mut sink, &run, controls) => outcome,
            never = watch => match never {},
        };
        hooks.end(Stage::Flight);
        sim.stop();
        // A MAVLink drone's distance and flight time come from the track it reported.
        let odometry = |d: usize| match mixed.as_ref().filter(|m| m.mavlink.serves(DroneId(d))) {
            Some(m) => m.mavlink.odometry(DroneId(d)),
            None => Some(sim.with_fleet(|f| f.odometry(DroneId(d)))),
        };
        hooks.landed(&mission, backend, &odometry);
        Ok(Flown { outcome, flew: true, simulated: sim.time() })
    })
}

/// The world read and the mission checked against it ([`Stage::World`], [`Stage::Check`]):
/// its program, the world and the texts, or its errors.
fn front_end(
    texts: Texts<'_>,
    hooks: &mut dyn Hooks,
) -> Result<(aviary_check::Program, World, SourceMap), NotFlown> {
    let mut sources = SourceMap::new();
    hooks.begin(Stage::World);
    let world = aviary_check::read_world(
        &mut sources,
        texts.world.name,
        Cow::Owned(texts.world.bytes),
        texts.files,
    );
    hooks.end(Stage::World);
    hooks.begin(Stage::Check);
    let checked = aviary_check::check_against(
        &mut sources,
        (texts.mission.name, Cow::Owned(texts.mission.bytes)),
        Some(world),
        texts.files,
    );
    hooks.end(Stage::Check);
    match (checked.has_errors(), checked.program, checked.world) {
        (false, Some(program), Some(world)) => Ok((program, world, sources)),
        _ => Err(NotFlown::Errors { diagnostics: checked.diagnostics, sources }),
    }
}

/// Hooks that hear nothing.
struct NoHooks;

impl Hooks for NoHooks {
    fn record(&mut self, _record: &Record<'_>, _backend: &dyn Backend) {}
}

/// A mission checked and compiled once for its world, to fly many times (`aviary test`):
/// each flight a fleet of its own from the world, seeded with its own seed.
pub struct Prepared {
    pub mission: Mission,
    pub world: World,
    /// The texts, for the places [`Outcome::at`] points into.
    pub sources: SourceMap,
}

/// The front end and the compiler of [`fly`], once, for a world of simulated drones only
/// (a campaign cannot fly MAVLink vehicles thousands of times): [`NotFlown::Failed`] for
/// a world with MAVLink drones.
pub fn prepare(texts: Texts<'_>) -> Result<Prepared, NotFlown> {
    let (program, world, sources) = front_end(texts, &mut NoHooks)?;
    let live = aviary_mavlink::bindings(&world);
    if let Some((drone, address, ..)) = live.first() {
        let name = world.drones.get(*drone).map_or("", |d| d.name.as_str());
        return Err(NotFlown::Failed(format!(
            "the world binds {name} to a MAVLink vehicle at {address} ({} such drones in all): only simulated drones fly many times",
            live.len()
        )));
    }
    let mission = aviary_lower::compile(&program, &world).ok_or(NotFlown::NoMission)?;
    Ok(Prepared { mission, world, sources })
}

/// One flight of a [`Prepared`] mission on the simulator, with `options.seed`, as fast as
/// it goes: what [`fly`] does after the compiler for a world of simulated drones, with the
/// same engine call, so a seed flies here exactly as `aviary run --seed` flies it. Hooks
/// hear [`Stage::SimStart`] and [`Stage::Flight`] and every event they want.
pub fn fly_prepared(
    prepared: &Prepared,
    options: &Options,
    hooks: &mut dyn Hooks,
) -> Result<Flown, NotFlown> {
    let runtime = simulated_runtime(None)
        .map_err(|e| NotFlown::Failed(format!("cannot start the runtime: {e}")))?;
    let (controller, controls) = Controller::new();
    let mission = &prepared.mission;
    runtime.block_on(async {
        hooks.begin(Stage::SimStart);
        let fleet = Fleet::new(&prepared.world).seeded(options.seed);
        let sim = SimBackend::start_with(fleet, SimOptions::default());
        hooks.end(Stage::SimStart);
        let backend: &dyn Backend = &*sim;
        let watch = watch_backend(sim.take_driver(), controller.clone());
        hooks.begin(Stage::Flight);
        let mut sink = Sink { hooks: &mut *hooks, backend };
        let outcome = tokio::select! {
            biased;
            outcome = aviary_engine::run_controlled(mission, backend, &mut sink, &options.run, controls) => outcome,
            never = watch => match never {},
        };
        hooks.end(Stage::Flight);
        sim.stop();
        let odometry = |d: usize| Some(sim.with_fleet(|f| f.odometry(DroneId(d))));
        hooks.landed(mission, backend, &odometry);
        Ok(Flown { outcome, flew: true, simulated: sim.time() })
    })
}

/// The engine's sink: the caller's hooks, with the backend.
struct Sink<'a, 'b> {
    hooks: &'a mut dyn Hooks,
    backend: &'b dyn Backend,
}

impl TraceSink for Sink<'_, '_> {
    fn wants(&self, kind: EventKind) -> bool {
        self.hooks.wants(kind)
    }

    fn record(&mut self, record: &Record<'_>) {
        self.hooks.record(record, self.backend);
    }
}

/// A panic in the simulator's task ends the mission at once, `failed`, with the reason.
/// Never ends.
async fn watch_backend(
    driver: Option<tokio::task::JoinHandle<()>>,
    controller: Controller,
) -> Infallible {
    if let Some(handle) = driver {
        if let Err(e) = handle.await {
            if e.is_panic() {
                controller.send(Control::BackendLost {
                    reason: "the simulator stopped: its task panicked".into(),
                });
            }
        }
    }
    std::future::pending().await
}

#[cfg(test)]
mod tests {
    use super::*;
    use aviary_check::NoFiles;

    /// What the hooks heard, in order.
    #[derive(Default)]
    struct Heard {
        said: Vec<String>,
        events: Vec<String>,
    }

    impl Hooks for Heard {
        fn begin(&mut self, stage: Stage) {
            self.said.push(format!("begin {stage:?}"));
        }
        fn end(&mut self, stage: Stage) {
            self.said.push(format!("end {stage:?}"));
        }
        fn compiled(&mut self, mission: &Mission, _world: &World) -> Result<(), String> {
            self.said.push(format!("compiled {}", mission.name));
            Ok(())
        }
        fn starting(&mut self, _: &Mission, _: &Controller, _: &Stop) -> Result<(), String> {
            self.said.push("starting".into());
            Ok(())
        }
        fn record(&mut self, record: &Record<'_>, _: &dyn Backend) {
            self.events.push(record.event.kind().as_str().into());
        }
        fn landed(
            &mut self,
            mission: &Mission,
            backend: &dyn Backend,
            _: &dyn Fn(usize) -> Option<(f64, f64)>,
        ) {
            let landed =
                (0..mission.drones.len()).all(|d| !backend.telemetry(DroneId(d)).state.airborne());
            self.said.push(format!("landed {landed}"));
        }
    }

    const WORLD: &str = "[site]\norigin = { lat = 46.6, lon = 14.2, alt = 440 }\n\
                         [drones.d]\nhome = [0, 0]\n";

    fn fly_text(mission: &str, hooks: &mut Heard) -> Result<Flown, NotFlown> {
        let texts = Texts {
            mission: Source { name: "m.mission", bytes: mission.as_bytes().to_vec() },
            world: Source { name: "m.world.toml", bytes: WORLD.as_bytes().to_vec() },
            files: &NoFiles,
        };
        fly(texts, &Options::default(), hooks)
    }

    #[test]
    fn a_mission_flies_through_every_stage_in_order() {
        let mut heard = Heard::default();
        let flown = fly_text("MISSION Up:\n    d TakeOff WITH 10m\n", &mut heard)
            .unwrap_or_else(|_| panic!("the mission flies"));
        assert_eq!(flown.outcome.status, Status::Ok);
        assert!(flown.flew && flown.simulated > 0.0);
        let stages = |s: &str| [format!("begin {s}"), format!("end {s}")];
        let mut expected: Vec<String> = ["World", "Check", "FreeTexts", "Compile", "FreeTree"]
            .iter()
            .flat_map(|s| stages(s))
            .collect();
        expected.extend(["compiled Up".to_string(), "starting".into()]);
        expected.extend(stages("SimStart"));
        expected.extend(stages("Flight"));
        expected.push("landed true".into());
        assert_eq!(heard.said, expected);
        assert_eq!(heard.events.first().map(String::as_str), Some("mission_start"));
        assert_eq!(heard.events.last().map(String::as_str), Some("mission_end"));
    }

    #[test]
    fn a_mission_with_errors_is_refused_before_anything_starts() {
        let mut heard = Heard::default();
        let Err(NotFlown::Errors { diagnostics, sources }) =
            fly_text("MISSION Up:\n    nobody TakeOff WITH 10m\n", &mut heard)
        else {
            panic!("refused with its errors");
        };
        assert!(diagnostics.iter().any(|d| d.is_error()));
        assert_eq!(sources.name(diagnostics[0].primary.file), "m.mission");
        assert!(heard.said.iter().all(|s| !s.starts_with("compiled")) && heard.events.is_empty());
    }

    #[test]
    fn capabilities_alone_are_no_mission_to_fly() {
        let text = "CAPABILITY Up BY d:\n    PERFORM:\n        d TakeOff WITH 10m\n";
        assert!(matches!(fly_text(text, &mut Heard::default()), Err(NotFlown::NoMission)));
    }
}
