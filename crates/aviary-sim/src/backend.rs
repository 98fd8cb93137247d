//! [`SimBackend`]: the physics core behind the engine's [`Backend`] trait, driven by one
//! tokio task that steps it every `tick` seconds of the run's clock.
//!
//! The run's clock is simulated time: the runtime is an `aviary_clock::Runtime`, whose
//! virtual clock is the one the engine's timers and the simulator share, deterministic and
//! free: with every task waiting, it moves to the next tick at once. Pacing (`--speed`, or
//! a live run following the vehicles' clocks through [`crate::Pace`]) is the clock's own:
//! a paced runtime never lets it pass its reference, so the driver knows nothing of it.

use parking_lot::Mutex;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Weak};
use std::time::Duration;

use aviary_api::{
    Backend, CallEnd, CallId, DroneEvent, DroneId, Ending, FunctionCall, Interrupt, PendingCall,
    Telemetry,
};
use aviary_world::World;
use tokio::sync::{mpsc, oneshot};
use tokio::task::JoinHandle;

use crate::fleet::{Fleet, Release, Report};

/// How the simulator runs.
#[derive(Clone)]
pub struct SimOptions {
    /// Simulated seconds per physics step (default 0.05). The clock counts whole
    /// milliseconds (a deadline rounds up to the next), so keep it a multiple of 0.001.
    pub tick: f64,
}

impl Default for SimOptions {
    fn default() -> SimOptions {
        SimOptions { tick: 0.05 }
    }
}

struct State {
    fleet: Fleet,
    /// The answer channels of the calls in progress.
    waiting: BTreeMap<CallId, oneshot::Sender<CallEnd>>,
    events: mpsc::UnboundedSender<DroneEvent>,
}

impl State {
    fn answer(&mut self, call: CallId, end: CallEnd) {
        if let Some(tx) = self.waiting.remove(&call) {
            // The engine may have stopped waiting; nothing to do then.
            let _ = tx.send(end);
        }
    }
}

/// The built-in simulator as a [`Backend`].
///
/// The driver task stops at its next tick after [`SimBackend::stop`], or once every
/// `Arc<SimBackend>` is gone (it holds only a weak reference). After it stops, calls in
/// progress never end.
pub struct SimBackend {
    state: Mutex<State>,
    events: Mutex<Option<mpsc::UnboundedReceiver<DroneEvent>>>,
    stopped: AtomicBool,
    driver: Mutex<Option<JoinHandle<()>>>,
}

impl SimBackend {
    /// Builds the fleet of `world` and spawns the driver task. Call it inside an
    /// `aviary_clock::Runtime` (simulated time; elsewhere the steps follow the wall clock).
    ///
    /// # Panics
    /// Outside a tokio runtime, or when `options.tick` is not a positive number.
    pub fn start(world: &World, options: SimOptions) -> Arc<SimBackend> {
        SimBackend::start_with(Fleet::new(world), options)
    }

    /// As [`SimBackend::start`], with the fleet already built: by [`Fleet::new`], or by
    /// [`Fleet::from_world`] from a world the caller gives up. The same fleet gives the
    /// same run.
    ///
    /// # Panics
    /// Outside a tokio runtime, or when `options.tick` is not a positive number.
    pub fn start_with(fleet: Fleet, options: SimOptions) -> Arc<SimBackend> {
        assert!(
            options.tick.is_finite() && options.tick > 0.0,
            "SimOptions::tick must be positive"
        );
        let (tx, rx) = mpsc::unbounded_channel();
        let backend = Arc::new(SimBackend {
            state: Mutex::new(State { fleet, waiting: BTreeMap::new(), events: tx }),
            events: Mutex::new(Some(rx)),
            stopped: AtomicBool::new(false),
            driver: Mutex::new(None),
        });
        let handle = tokio::spawn(drive(Arc::downgrade(&backend), options));
        *backend.driver.lock() = Some(handle);
        backend
    }

    /// Asks the driver to stop at its next tick.
    pub fn stop(&self) {
        self.stopped.store(true, Ordering::SeqCst);
    }

    /// Stops the driver and waits until it has ended.
    pub async fn shutdown(&self) {
        self.stop();
        let handle = self.driver.lock().take();
        if let Some(handle) = handle {
            let _ = handle.await;
        }
    }

    /// The driver task's handle (once), to await its end elsewhere.
    pub fn take_driver(&self) -> Option<JoinHandle<()>> {
        self.driver.lock().take()
    }

    /// Simulated seconds so far.
    pub fn time(&self) -> f64 {
        self.state.lock().fleet.time()
    }

    /// Every `ReleasePayload` so far (drone, kind, position, time).
    pub fn releases(&self) -> Vec<Release> {
        self.state.lock().fleet.releases().to_vec()
    }

    /// Reads the physics core (under the lock: keep it short).
    pub fn with_fleet<R>(&self, f: impl FnOnce(&Fleet) -> R) -> R {
        f(&self.state.lock().fleet)
    }

    /// One physics step: answers the calls that ended and sends the events.
    fn tick(&self, dt: f64) {
        let mut state = self.state.lock();
        for report in state.fleet.step(dt) {
            match report {
                Report::Ended { call, end } => state.answer(call, end),
                Report::Event(event) => {
                    let _ = state.events.send(event);
                }
            }
        }
    }
}

async fn drive(backend: Weak<SimBackend>, options: SimOptions) {
    let period = Duration::from_secs_f64(options.tick);
    // Burst (the clock's only behaviour): a tick late in real time is not skipped, so the
    // steps stay on their grid of simulated time.
    let mut interval = aviary_clock::interval_at(aviary_clock::Instant::now() + period, period);
    loop {
        interval.tick().await;
        let Some(sim) = backend.upgrade() else { return };
        if sim.stopped.load(Ordering::SeqCst) {
            return;
        }
        sim.tick(options.tick);
    }
}

impl Backend for SimBackend {
    fn call(&self, drone: DroneId, call: &FunctionCall) -> PendingCall {
        let mut state = self.state.lock();
        let (id, end) = state.fleet.call(drone, call);
        let end = match end {
            Some(end) => Ending::Now(end),
            None => {
                let (tx, rx) = oneshot::channel();
                state.waiting.insert(id, tx);
                Ending::Later(rx)
            }
        };
        PendingCall { id, end }
    }

    fn interrupt(&self, call: CallId, how: Interrupt) {
        let mut state = self.state.lock();
        if let Some(end) = state.fleet.interrupt(call, how) {
            state.answer(call, end);
        }
    }

    fn telemetry(&self, drone: DroneId) -> Telemetry {
        self.state.lock().fleet.telemetry(drone).unwrap_or(Telemetry::LOST)
    }

    fn payload(&self, drone: DroneId) -> Option<String> {
        self.state.lock().fleet.carrying(drone).map(str::to_owned)
    }

    fn stopped(&self, drone: DroneId) -> Option<aviary_api::Progress> {
        self.state.lock().fleet.stopped(drone)
    }

    fn events(&self) -> Option<mpsc::UnboundedReceiver<DroneEvent>> {
        self.events.lock().take()
    }
}
