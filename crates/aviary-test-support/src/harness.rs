//! Runs a mission text on the built-in simulator and returns its outcome and trace; and
//! the steps before it (check, compile) for tests that stop there or run the compiled
//! mission their own way.

use aviary_check::Checked;
use aviary_diagnostics::SourceMap;
use aviary_engine::{Control, Controller, Directory, DroneAction, Outcome, Record, RunOptions};
use aviary_sim::{SimBackend, SimOptions};

use crate::trace::Trace;
use crate::NoFiles;

/// A small world: drones a, b, c at the origin's corners, a place and an area.
pub const WORLD: &str = r#"
[site]
geofence = [[-1000, -1000], [1000, -1000], [1000, 1000], [-1000, 1000]]
max_altitude = 120.0
[places]
Home = [0, 0]
North = [0, 100]
Far = [0, 400]
[areas]
Field = [[100, 100], [200, 100], [200, 200], [100, 200]]
[drones.a]
home = [0, 0]
group = "team"
sensors = ["camera", "thermal"]
payload = ["Box"]
[drones.b]
home = [10, 0]
group = "team"
sensors = ["camera"]
[drones.c]
home = [20, 0]
[sensors.thermal]
detects = ["Body"]
range = 20.0
[[targets]]
kind = "Body"
at = [150, 150]
"#;

pub struct Run {
    pub outcome: Outcome,
    /// The run's events, each as the trace file would have it (see [`Trace`], which a
    /// run reads as).
    pub trace: Trace,
    /// Every payload release: (drone, kind, position).
    pub releases: Vec<(usize, String, [f64; 3])>,
}

pub fn run(mission: &str) -> Run {
    run_in(mission, WORLD)
}

pub fn run_in(mission: &str, world: &str) -> Run {
    run_with(mission, world, &RunOptions::default())
}

/// The mission (`m.mission`) checked against the world (`w.toml`), as `aviary check`
/// does it, with every diagnostic; and the texts, to render them.
pub fn check(mission: &str, world: &str) -> (SourceMap, Checked) {
    let mut sources = SourceMap::new();
    let checked = aviary_check::check_sources(
        &mut sources,
        ("m.mission", mission.as_bytes()),
        Some(("w.toml", world.as_bytes())),
        &NoFiles,
    );
    (sources, checked)
}

/// The mission checked (without errors) and compiled for the world, and the world.
pub fn compile(mission: &str, world: &str) -> (aviary_ir::Mission, aviary_world::World) {
    try_compile(mission, world).unwrap_or_else(|errors| panic!("{errors:#?}"))
}

/// As [`compile`]; the checker's errors, if it finds any.
pub fn try_compile(
    mission: &str,
    world: &str,
) -> Result<(aviary_ir::Mission, aviary_world::World), Vec<String>> {
    let (_, checked) = check(mission, world);
    let errors: Vec<String> = checked
        .diagnostics
        .iter()
        .filter(|d| d.is_error())
        .map(|d| format!("{}: {}", d.code, d.message))
        .collect();
    if !errors.is_empty() {
        return Err(errors);
    }
    let world = checked.world.expect("world");
    let mission =
        aviary_lower::compile(&checked.program.expect("program"), &world).expect("mission");
    Ok((mission, world))
}

/// The runtime a simulated run takes: one thread and a virtual clock (`aviary_clock`),
/// so that simulated time passes as soon as every task waits and a run takes no real time.
pub fn simulated_runtime() -> aviary_clock::Runtime {
    aviary_clock::Runtime::new().expect("runtime")
}

pub fn run_with(mission: &str, world: &str, options: &RunOptions) -> Run {
    let (mission, world) = compile(mission, world);
    run_compiled(&mission, &world, options, Vec::new(), Path::AsUsersRun).0
}

/// Which way activities run: as users run them, or every one on the general path
/// (`aviary_engine::testing`), to hold the instant path to the general one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Path {
    AsUsersRun,
    GeneralOnly,
}

/// A control as an operator asks it: by the names a person uses, resolved against the
/// compiled mission as the operator API resolves them ([`Directory`]), or one the engine
/// takes as it is.
#[derive(Clone, Debug, PartialEq)]
pub enum Ask {
    Leash {
        capability: String,
        tag: String,
        action: String,
        args: Vec<(String, aviary_api::Value)>,
    },
    Signal {
        name: String,
        args: Vec<aviary_api::Value>,
    },
    Drone {
        drone: String,
        action: DroneAction,
    },
    Control(Control),
}

impl Ask {
    /// A leash without arguments: `Ask::leash("FlyTo", "F1", "PAUSE")`.
    pub fn leash(capability: &str, tag: &str, action: &str) -> Ask {
        Ask::Leash {
            capability: capability.into(),
            tag: tag.into(),
            action: action.into(),
            args: Vec::new(),
        }
    }

    pub fn drone(drone: &str, action: DroneAction) -> Ask {
        Ask::Drone { drone: drone.into(), action }
    }

    /// The control, or why the operator API refuses it before the engine hears it.
    pub fn resolve(self, directory: &Directory) -> Result<Control, String> {
        match self {
            Ask::Leash { capability, tag, action, args } => {
                // As the operator API does: each parameter by its name, once.
                let args = match directory.capability(&capability) {
                    Some(c) => args
                        .into_iter()
                        .map(|(name, v)| Ok((directory.param(c, &name)?, v)))
                        .collect::<Result<Vec<_>, String>>()?,
                    None => Vec::new(),
                };
                directory.leash(&capability, &tag, &action, args)
            }
            Ask::Signal { name, args } => {
                let signal = directory.operator_signal(&name)?;
                Ok(Control::Signal { signal, args })
            }
            Ask::Drone { drone, action } => directory.drone(&drone, action),
            Ask::Control(control) => Ok(control),
        }
    }
}

impl From<Control> for Ask {
    fn from(control: Control) -> Ask {
        Ask::Control(control)
    }
}

/// Runs a compiled mission, sending each control at its mission time; the run and the
/// answers to the controls (a refusal by name is the directory's, as the operator API's).
pub fn run_compiled(
    mission: &aviary_ir::Mission,
    world: &aviary_world::World,
    options: &RunOptions,
    controls: Vec<(f64, Ask)>,
    path: Path,
) -> (Run, Vec<Result<(), String>>) {
    let directory = Directory::of(mission);
    simulated_runtime().block_on(async {
        let sim = SimBackend::start(world, SimOptions::default());
        let (controller, rx) = Controller::new();
        // Without controls, as a run without an operator: no channel at all.
        let rx = (!controls.is_empty()).then_some(rx);
        let mut trace = Vec::new();
        let mut sink = |r: &Record| trace.push(Trace::line(r));
        let operator = async {
            let start = aviary_clock::Instant::now();
            let mut answers = Vec::new();
            for (at, ask) in controls {
                aviary_clock::sleep_until(start + std::time::Duration::from_secs_f64(at)).await;
                answers.push(match ask.resolve(&directory) {
                    Ok(control) => controller.ask(control).await,
                    Err(why) => Err(why),
                });
            }
            answers
        };
        let run = async {
            match (path, rx) {
                (Path::AsUsersRun, None) => {
                    aviary_engine::run(mission, &*sim, &mut sink, options).await
                }
                (Path::AsUsersRun, Some(rx)) => {
                    aviary_engine::run_controlled(mission, &*sim, &mut sink, options, rx).await
                }
                (Path::GeneralOnly, rx) => {
                    aviary_engine::testing::run_on_the_general_path(
                        mission, &*sim, &mut sink, options, rx,
                    )
                    .await
                }
            }
        };
        let (outcome, answers) = tokio::join!(run, operator);
        sim.shutdown().await;
        let releases =
            sim.releases().into_iter().map(|r| (r.drone.0, r.kind, r.position)).collect();
        (Run { outcome, trace: Trace(trace), releases }, answers)
    })
}

/// A run reads as its trace: `run.find(..)`, `run.t(..)`, `run.iter()`.
impl std::ops::Deref for Run {
    type Target = Trace;
    fn deref(&self) -> &Trace {
        &self.trace
    }
}
