//! A world with MAVLink drones: each drone goes to the backend that flies it, the
//! simulator (then in real time) or MAVLink, behind one [`Backend`] for the engine.

use parking_lot::Mutex;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use aviary_api::{
    Backend, CallId, DroneEvent, DroneId, Ending, FunctionCall, Interrupt, PendingCall, Progress,
    Telemetry,
};
use aviary_ir::TiVec;
use aviary_mavlink::MavlinkBackend;
use aviary_sim::SimBackend;
use tokio::sync::{mpsc, oneshot};

pub struct Mixed {
    pub sim: Arc<SimBackend>,
    pub mavlink: MavlinkBackend,
    /// The engine's call ids → (by MAVLink, the backend's own id): the two backends
    /// number their calls independently.
    calls: Arc<Mutex<BTreeMap<CallId, (bool, CallId)>>>,
    next: AtomicU64,
    events: Mutex<Option<mpsc::UnboundedReceiver<DroneEvent>>>,
}

impl Mixed {
    /// Call inside the tokio runtime (it starts the task that merges the event streams).
    pub fn new(sim: Arc<SimBackend>, mavlink: MavlinkBackend) -> Mixed {
        let (tx, rx) = mpsc::unbounded_channel();
        let served: TiVec<DroneId, bool> =
            (0..sim.with_fleet(|f| f.len())).map(|d| mavlink.serves(DroneId(d))).collect();
        if let Some(mut from_sim) = sim.events() {
            let tx = tx.clone();
            let served = served.clone();
            tokio::spawn(async move {
                while let Some(e) = from_sim.recv().await {
                    // The simulator also models the MAVLink drones (idle at home): drop
                    // what it says of them.
                    if !served.get(e.drone()).copied().unwrap_or(false) && tx.send(e).is_err() {
                        return;
                    }
                }
            });
        }
        if let Some(mut from_mav) = mavlink.events() {
            tokio::spawn(async move {
                while let Some(e) = from_mav.recv().await {
                    if tx.send(e).is_err() {
                        return;
                    }
                }
            });
        }
        Mixed {
            sim,
            mavlink,
            calls: Arc::default(),
            next: AtomicU64::new(1),
            events: Mutex::new(Some(rx)),
        }
    }
}

impl Backend for Mixed {
    fn call(&self, drone: DroneId, call: &FunctionCall) -> PendingCall {
        let by_mavlink = self.mavlink.serves(drone);
        let inner =
            if by_mavlink { self.mavlink.call(drone, call) } else { self.sim.call(drone, call) };
        let id = CallId(self.next.fetch_add(1, Ordering::SeqCst));
        let inner_end = match inner.end {
            Ending::Now(end) => return PendingCall { id, end: Ending::Now(end) },
            Ending::Later(rx) => rx,
        };
        self.calls.lock().insert(id, (by_mavlink, inner.id));
        // Pass the end on, and forget the call once it has ended.
        let (tx, rx) = oneshot::channel();
        let calls = Arc::clone(&self.calls);
        tokio::spawn(async move {
            let end = inner_end.await;
            calls.lock().remove(&id);
            if let Ok(end) = end {
                let _ = tx.send(end);
            }
        });
        PendingCall { id, end: Ending::Later(rx) }
    }

    fn interrupt(&self, call: CallId, how: Interrupt) {
        let Some((by_mavlink, inner)) = self.calls.lock().get(&call).copied() else {
            return;
        };
        if by_mavlink {
            self.mavlink.interrupt(inner, how);
        } else {
            self.sim.interrupt(inner, how);
        }
    }

    fn telemetry(&self, drone: DroneId) -> Telemetry {
        if self.mavlink.serves(drone) {
            self.mavlink.telemetry(drone)
        } else {
            self.sim.telemetry(drone)
        }
    }

    fn payload(&self, drone: DroneId) -> Option<String> {
        if self.mavlink.serves(drone) {
            self.mavlink.payload(drone)
        } else {
            self.sim.payload(drone)
        }
    }

    fn stopped(&self, drone: DroneId) -> Option<Progress> {
        if self.mavlink.serves(drone) {
            self.mavlink.stopped(drone)
        } else {
            self.sim.stopped(drone)
        }
    }

    fn events(&self) -> Option<mpsc::UnboundedReceiver<DroneEvent>> {
        self.events.lock().take()
    }
}

/// The runtime of a run with MAVLink drones: one thread on the run's virtual clock, as a
/// simulated run (the engine relies on both), with sockets, paced by the run's
/// `aviary_sim::Pace`: without it, an idle runtime would jump to its next timer.
pub fn live_runtime(pace: Arc<aviary_sim::Pace>) -> std::io::Result<aviary_clock::Runtime> {
    aviary_clock::Builder::new().enable_io().paced(pace).build()
}

/// The runtime of a simulated run: one thread, the virtual clock, no sockets; at `speed`
/// times real time if asked (the clock then never runs ahead of the wall clock times it).
pub fn simulated_runtime(speed: Option<f64>) -> std::io::Result<aviary_clock::Runtime> {
    let builder = aviary_clock::Builder::new();
    match speed.filter(|s| s.is_finite() && *s > 0.0) {
        Some(speed) => builder.paced(Arc::new(aviary_clock::Speed::new(speed))).build(),
        None => builder.build(),
    }
}
