//! [`SimBackend`]: the physics core behind the engine's [`Backend`] trait, driven by one
//! tokio task that steps it every `tick` seconds of tokio time.
//!
//! Tokio time is simulated time: the runtime runs on tokio's paused clock (its
//! `test-util` feature, kept in production builds on purpose), the one clock the engine's
//! timers and the simulator share, deterministic and free: with every task waiting, it
//! moves to the next tick at once. With [`SimOptions::speed`] the driver also waits for
//! the wall clock, off the engine's thread (see [`drive`]).

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
use tokio::time::MissedTickBehavior;

use crate::fleet::{Fleet, Release, Report};
use crate::pace::Pace;

/// How the simulator runs.
#[derive(Clone)]
pub struct SimOptions {
    /// Simulated seconds per physics step (default 0.05). Tokio's timer counts whole
    /// milliseconds, so keep it a multiple of 0.001.
    pub tick: f64,
    /// `None`: as fast as the tokio clock goes (with a paused clock, no real time at all).
    /// `Some(x)`: `x` times real time; the driver sleeps (blocking its thread) so that
    /// simulated time never runs ahead of `x` × wall time. Run the runtime with a paused
    /// clock in both cases, so that tokio time is simulated time.
    pub speed: Option<f64>,
    /// A live run's reference (with MAVLink drones): simulated time never runs ahead of
    /// it (the wall clock, or the vehicles' clocks once it follows them). Instead of
    /// `speed`.
    pub pace: Option<Arc<Pace>>,
}

impl Default for SimOptions {
    fn default() -> SimOptions {
        SimOptions { tick: 0.05, speed: None, pace: None }
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
    /// Builds the fleet of `world` and spawns the driver task. Call it inside a tokio
    /// runtime (for determinism and speed, a current-thread one with a paused clock).
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
    let mut interval = tokio::time::interval_at(tokio::time::Instant::now() + period, period);
    interval.set_missed_tick_behavior(MissedTickBehavior::Burst);
    let wall = std::time::Instant::now();
    let mut ticks: u64 = 0;
    loop {
        interval.tick().await;
        let Some(sim) = backend.upgrade() else { return };
        if sim.stopped.load(Ordering::SeqCst) {
            return;
        }
        sim.tick(options.tick);
        drop(sim);
        ticks += 1;
        if let Some(pace) = &options.pace {
            // Until the reference has reached this tick's time, in waits of a few
            // milliseconds, each a blocking task that holds the paused clock still.
            let due = ticks as f64 * options.tick;
            while pace.now() < due {
                let running =
                    backend.upgrade().is_some_and(|sim| !sim.stopped.load(Ordering::SeqCst));
                if !running {
                    return;
                }
                let _ = tokio::task::spawn_blocking(|| std::thread::sleep(PACE_POLL)).await;
            }
        } else if let Some(speed) = options.speed.filter(|s| s.is_finite() && *s > 0.0) {
            let due = Duration::from_secs_f64(ticks as f64 * options.tick / speed);
            let elapsed = wall.elapsed();
            if due > elapsed {
                // On the blocking pool, not on this thread: the engine shares it and goes
                // on with what does not need the clock (an operator's request, a drone
                // event). A blocking task also holds the paused clock still (tokio does
                // not advance it while one runs), so simulated time waits for the wall.
                let wait = due - elapsed;
                let _ = tokio::task::spawn_blocking(move || std::thread::sleep(wait)).await;
            }
        }
    }
}

/// How often a paced driver looks at its reference while it waits.
const PACE_POLL: Duration = Duration::from_millis(2);

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
