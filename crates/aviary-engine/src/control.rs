//! Live control from outside the mission: an operator's leashes and signals, pausing
//! and aborting the whole mission (issue: operator API), steering one drone (`steer.rs`),
//! and a backend that died. What the operator does to the mission or a drone is written
//! to the trace as an `operator` event; leashes and signals are written as the mission's
//! own are.

use parking_lot::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use aviary_api::trace::{Event, EventKind, OperatorAction};
use aviary_api::{DroneId, Value};
use aviary_ir::{CapId, LeashAction, SignalId, TagId};
use tokio::sync::{mpsc, oneshot};

use crate::directory::spaced;
use crate::engine::Engine;

/// What an operator (or the process) asks of a running mission, by the mission's ids:
/// names are resolved before, by a [`crate::Directory`].
#[derive(Clone, Debug, PartialEq)]
pub enum Control {
    /// A leash, as a mission's own statement pulls it: `FlyCircle-C1 PAUSE`, with a
    /// section's arguments by parameter index.
    Leash {
        capability: CapId,
        tag: TagId,
        action: LeashAction,
        args: Vec<(usize, Value)>,
    },
    /// Raises a signal at mission level (no actor), as the mission's own `SIGNAL` would:
    /// one the mission declares with `OPERATOR SIGNAL`, and no other.
    Signal {
        signal: SignalId,
        args: Vec<Value>,
    },
    /// Holds every drone's activity where it is, until `Resume`.
    Pause,
    Resume,
    /// Steers one drone (`steer.rs`).
    Drone {
        drone: DroneId,
        action: DroneAction,
    },
    /// A name the mission does not have, refused in the engine's words: what runs now,
    /// which only the engine knows, is what the operator can pull instead.
    Unknown(Unknown),
    /// Ends the mission: the fleet returns home, and the mission ends `aborted`.
    Abort {
        reason: String,
    },
    /// The backend can no longer answer (its task panicked): end at once, `failed`.
    BackendLost {
        reason: String,
    },
}

/// A leash's name that resolves to nothing, with the name meant (`did you mean ...?`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Unknown {
    Capability { name: String, meant: Option<String> },
    Tag { capability: String, tag: String, meant: Option<String> },
}

/// What the operator does to one drone.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DroneAction {
    /// Pauses every activity of the drone, as a `PAUSE` leash would, and those that start
    /// while it is held; a group activity with it is held whole.
    Hold,
    /// Undoes `Hold` (not a pause of the whole mission: each holds on its own).
    Resume,
    /// Aborts every activity of the drone, as an `ABORT` leash would, and sends it home,
    /// out of the mission for the rest of the run.
    ReturnHome,
    /// As `ReturnHome`, but lands it where it is.
    Land,
}

impl DroneAction {
    /// As the trace writes it.
    pub fn traced(self) -> OperatorAction {
        match self {
            DroneAction::Hold => OperatorAction::Hold,
            DroneAction::Resume => OperatorAction::Resume,
            DroneAction::ReturnHome => OperatorAction::ReturnHome,
            DroneAction::Land => OperatorAction::Land,
        }
    }
}

/// A control and where to send its answer (`Err` says why it was refused).
pub type ControlRequest = (Control, oneshot::Sender<Result<(), String>>);

/// The sending side, for a server or a signal handler; cheap to clone, usable from any thread.
#[derive(Clone)]
pub struct Controller {
    tx: mpsc::UnboundedSender<ControlRequest>,
    interrupt: Arc<Interrupt>,
}

/// The engine's side of a [`Controller`], for [`crate::run_controlled`].
pub struct Controls {
    rx: mpsc::UnboundedReceiver<ControlRequest>,
    interrupt: Arc<Interrupt>,
}

/// A stop asked from outside the mission that the engine hears even when it never waits
/// (it reads controls only when it waits): a flag it looks at between the steps it takes
/// at one instant (every handler it starts, every signal and exception), so a mission
/// busy at one instant for as long as it likes is stopped all the same, the fleet sent
/// home. `heard` says the engine has stopped, for whatever reason (or has no more
/// mission to run: only the way home is left, and that waits): a caller that sees it
/// unset long after asking knows the engine is stuck where it does not look, and may end
/// the process.
#[derive(Default)]
pub(crate) struct Interrupt {
    asked: AtomicBool,
    reason: Mutex<Option<String>>,
    heard: AtomicBool,
}

impl Interrupt {
    pub fn asked(&self) -> bool {
        self.asked.load(Ordering::Acquire)
    }

    pub fn reason(&self) -> String {
        let reason = self.reason.lock();
        reason.clone().unwrap_or_else(|| "interrupted".into())
    }

    pub fn heard(&self) {
        self.heard.store(true, Ordering::Release);
    }
}

impl Controls {
    /// The next request, for a stand-in that answers requests itself instead of an
    /// engine (the operator API's fuzz target drives the router so, without a mission).
    pub async fn recv(&mut self) -> Option<ControlRequest> {
        self.rx.recv().await
    }

    pub(crate) fn into_parts(self) -> (mpsc::UnboundedReceiver<ControlRequest>, Arc<Interrupt>) {
        (self.rx, self.interrupt)
    }
}

impl Controller {
    /// A controller and the engine's side of it, to pass to [`crate::run_controlled`].
    pub fn new() -> (Controller, Controls) {
        let (tx, rx) = mpsc::unbounded_channel();
        let interrupt = Arc::new(Interrupt::default());
        (Controller { tx, interrupt: interrupt.clone() }, Controls { rx, interrupt })
    }

    /// Ends the mission as [`Control::Abort`] does, with `reason`, and is heard even by an
    /// engine that never waits ([`Interrupt`]): for Ctrl-C, SIGTERM, SIGHUP, and a trace
    /// that reached its size limit. The first reason given stands.
    pub fn interrupt(&self, reason: String) {
        {
            let mut held = self.interrupt.reason.lock();
            held.get_or_insert_with(|| reason.clone());
        }
        self.interrupt.asked.store(true, Ordering::Release);
        // Wakes an engine that waits: it applies the abort at once.
        self.send(Control::Abort { reason });
    }

    /// Whether the engine has stopped the mission (an interrupt, an abort, a failure, its
    /// end) and has only the way home left, or has no more to do.
    pub fn heard(&self) -> bool {
        self.interrupt.heard.load(Ordering::Acquire) || self.tx.is_closed()
    }
    /// Sends without waiting for the answer (for signal handlers).
    pub fn send(&self, control: Control) {
        let (answer, _) = oneshot::channel();
        let _ = self.tx.send((control, answer));
    }
    /// Sends and waits for the engine's answer.
    pub async fn ask(&self, control: Control) -> Result<(), String> {
        let (answer, rx) = oneshot::channel();
        self.tx.send((control, answer)).map_err(|_| "the mission has ended".to_string())?;
        rx.await.unwrap_or_else(|_| Err("the mission has ended".to_string()))
    }
}

impl Default for Controller {
    fn default() -> Self {
        Controller::new().0
    }
}

impl<'m> Engine<'m> {
    /// A stop asked from outside ([`Controller::interrupt`]), looked at between the steps
    /// the engine takes at one instant: heard even when the mission never waits.
    #[inline]
    pub(crate) fn heed_interrupt(&self) {
        if let Some(interrupt) = self.interrupt.get() {
            if interrupt.asked() && !self.stopped() {
                self.interrupted(interrupt);
            }
        }
    }

    #[cold]
    fn interrupted(&self, interrupt: &Interrupt) {
        self.operator(OperatorAction::Abort, None);
        self.end_with(crate::Status::Aborted, interrupt.reason(), true);
    }

    pub(crate) async fn controls(&self, mut rx: mpsc::UnboundedReceiver<ControlRequest>) {
        while let Some((control, answer)) = rx.recv().await {
            let _ = answer.send(self.apply(control));
        }
        std::future::pending::<()>().await;
    }

    /// The `operator` event: what the operator did, to a drone or (`None`) the mission.
    pub(crate) fn operator(&self, action: OperatorAction, drone: Option<aviary_api::DroneId>) {
        self.trace(EventKind::Operator, || Event::Operator {
            action,
            drone: drone.map(|d| self.name(d).into()),
        });
    }

    fn apply(&self, control: Control) -> Result<(), String> {
        if self.stopped() {
            return Err("the mission is ending".into());
        }
        match control {
            Control::Leash { capability, tag, action, args } => {
                // Ids from a directory of this mission are always its own; others are
                // refused, never followed.
                let cap = self.m.capabilities.get(capability).ok_or("no such capability")?;
                cap.action_name(action).ok_or("no such section")?;
                if self.m.tags.get(tag).is_none()
                    || args.iter().any(|(p, _)| *p >= cap.params.len())
                {
                    return Err("no such tag or parameter".into());
                }
                self.leash_by_id(capability, tag, action, args, None);
                Ok(())
            }
            Control::Unknown(Unknown::Capability { name, meant }) => Err(format!(
                "no capability is called {name} ({}){}",
                self.running_leashes(),
                spaced(meant)
            )),
            Control::Unknown(Unknown::Tag { capability, tag, meant }) => Err(format!(
                "no statement starts an activity tagged {capability}-{tag} ({}){}",
                self.running_leashes(),
                spaced(meant)
            )),
            Control::Signal { signal, args } => {
                // Only the signals the mission declares with OPERATOR SIGNAL.
                if !self.m.operator_signals.contains(&signal) {
                    return Err("not an operator signal of the mission".into());
                }
                self.raise_from_outside(signal, args);
                Ok(())
            }
            Control::Pause | Control::Resume => {
                let pause = control == Control::Pause;
                self.operator(
                    if pause { OperatorAction::Pause } else { OperatorAction::Resume },
                    None,
                );
                self.mission_paused.set(pause);
                for (instance, _) in
                    self.instances.borrow().all().iter().filter(|(i, _)| i.root.is_none())
                {
                    // A drone the operator holds stays held, a body a section holds too.
                    let before = instance.holding();
                    instance.paused.set(pause);
                    self.rehold(instance, before);
                }
                Ok(())
            }
            Control::Drone { drone, action } => self.steer(drone, action),
            Control::Abort { reason } => {
                self.operator(OperatorAction::Abort, None);
                self.end_with(crate::Status::Aborted, reason, true);
                Ok(())
            }
            Control::BackendLost { reason } => {
                self.end_with(crate::Status::Failed, reason, false);
                Ok(())
            }
        }
    }
}

impl Engine<'_> {
    /// The tagged activities running now, as a leash names them, for a refused leash:
    /// what the operator can pull instead.
    fn running_leashes(&self) -> String {
        let running: Vec<String> = self
            .instances
            .borrow()
            .tags()
            .into_iter()
            .map(|(c, t)| format!("{}-{}", self.m.capabilities[c].name, self.m.tags[t]))
            .collect();
        if running.is_empty() {
            "no tagged activity is running now".to_owned()
        } else {
            format!("running now: {}", running.join(", "))
        }
    }
}
