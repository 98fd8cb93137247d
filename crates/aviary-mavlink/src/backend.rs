//! [`MavlinkBackend`]: the engine's [`Backend`] over MAVLink. Each call runs as a tokio
//! task of MAVLink exchanges; a watchdog turns a silent vehicle into `ConnectionLost`
//! (and its return into `ConnectionRestored`), and an RTL or LAND the autopilot chose by
//! itself into the matching exception. A fault ends the drone's calls `Interrupted`.

use parking_lot::Mutex;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use aviary_api::{
    Backend, BuiltinException, BuiltinSignal, CallEnd, CallId, DroneEvent, DroneId, Ending,
    Failure, Function, FunctionCall, Interrupt, PendingCall, Progress, Telemetry,
};
use aviary_world::Sensor;
use tokio::sync::{mpsc, oneshot, watch};
use tokio::task::AbortHandle;

use crate::drone::{failed, Craft, Doing};
use crate::facts::Facts;
use crate::functions;

struct Slot {
    drone: DroneId,
    function: Function,
    task: AbortHandle,
    paused: watch::Sender<bool>,
    end: oneshot::Sender<CallEnd>,
}

pub(crate) struct Inner {
    pub crafts: Vec<Option<Arc<Craft>>>,
    pub sensors: Vec<Sensor>,
    calls: Mutex<BTreeMap<CallId, Slot>>,
    next: AtomicU64,
    pub events: mpsc::UnboundedSender<DroneEvent>,
    taken: Mutex<Option<mpsc::UnboundedReceiver<DroneEvent>>>,
    lost: Mutex<Vec<bool>>,
    /// Per drone: `BatteryLow` signalled, `BatteryCritical` raised (each once).
    battery: Mutex<Vec<(bool, bool)>>,
    /// Per drone: where its last `Sweep` or `FollowPath` stopped (`Backend::stopped`).
    stops: Mutex<Vec<Option<Progress>>>,
}

/// MAVLink drones as a [`Backend`]. Drones of the world that are not MAVLink drones are
/// not served here (calls on them fail); `aviary run` sends those to the simulator.
pub struct MavlinkBackend {
    inner: Arc<Inner>,
    facts: Vec<Facts>,
}

impl MavlinkBackend {
    /// The clocks of the vehicles this backend flies, as one (`clock`): what a live
    /// run's time follows.
    pub fn clocks(&self) -> crate::clock::Clocks {
        let vehicles = self.inner.crafts.iter().flatten().map(|c| Arc::clone(&c.v)).collect();
        crate::clock::Clocks::new(vehicles)
    }

    pub(crate) fn new(
        crafts: Vec<Option<Arc<Craft>>>,
        facts: Vec<Facts>,
        sensors: Vec<Sensor>,
        events: (mpsc::UnboundedSender<DroneEvent>, mpsc::UnboundedReceiver<DroneEvent>),
        alarms: mpsc::UnboundedReceiver<(DroneId, Failure)>,
        heartbeat_timeout: Duration,
    ) -> MavlinkBackend {
        let n = crafts.len();
        let inner = Arc::new(Inner {
            crafts,
            sensors,
            calls: Mutex::new(BTreeMap::new()),
            next: AtomicU64::new(1),
            events: events.0,
            taken: Mutex::new(Some(events.1)),
            lost: Mutex::new(vec![false; n]),
            battery: Mutex::new(vec![(false, false); n]),
            stops: Mutex::new(vec![None; n]),
        });
        tokio::spawn(alarms_task(Arc::downgrade(&inner), alarms));
        tokio::spawn(watchdog(Arc::downgrade(&inner), heartbeat_timeout));
        MavlinkBackend { inner, facts }
    }

    /// What each vehicle said of itself at connect, one per MAVLink drone in the world's
    /// order: already applied to the figures the backend flies it with (the battery
    /// rule's, the acceleration). Apply them to the world's drones to plan with them.
    pub fn facts(&self) -> &[Facts] {
        &self.facts
    }

    /// Whether `drone` is one of this backend's.
    pub fn serves(&self, drone: DroneId) -> bool {
        self.inner.crafts.get(drone.0).is_some_and(Option::is_some)
    }

    /// Metres flown and seconds in the air, from the track the drone reported.
    pub fn odometry(&self, drone: DroneId) -> Option<(f64, f64)> {
        let c = self.inner.crafts.get(drone.0)?.as_ref()?;
        let seen = c.v.seen();
        Some((seen.odometer, seen.flight_time))
    }

    /// Whether the video stream is on, and what the drone carries.
    pub fn payload_state(&self, drone: DroneId) -> Option<(bool, Option<String>)> {
        let c = self.inner.crafts.get(drone.0)?.as_ref()?;
        Some((c.streaming(), c.carrying.lock().clone()))
    }
}

impl Inner {
    fn finish(&self, call: CallId, end: CallEnd) {
        if let Some(slot) = self.calls.lock().remove(&call) {
            if end != CallEnd::Done {
                self.note_stop(&slot);
            }
            let _ = slot.end.send(end);
        }
    }

    /// Notes where a path call that ends early stops: the point of its path the drone was
    /// flying to, and where the vehicle last said it was. Nothing when it had not begun
    /// to fly (refused before a target was sent).
    fn note_stop(&self, slot: &Slot) {
        if !matches!(slot.function, Function::Sweep | Function::FollowPath) {
            return;
        }
        let Some(Some(c)) = self.crafts.get(slot.drone.0) else { return };
        let (Some(next), Some(fix)) = (c.flying_to(), c.fix()) else { return };
        if let Some(stop) = self.stops.lock().get_mut(slot.drone.0) {
            *stop = Some(Progress { next, at: fix.pos });
        }
    }

    /// A fault: the event first, then every call of the drone ends `Interrupted` (so the
    /// engine raises one exception, once); where a path call stopped is noted before both.
    fn fault(&self, drone: DroneId, failure: Failure) {
        if failure.exception == BuiltinException::BatteryCritical {
            // The rule below and the autopilot's battery failsafe may both see it: one
            // fault, one exception.
            let mut flags = self.battery.lock();
            if flags[drone.0].1 {
                return;
            }
            flags[drone.0].1 = true;
        }
        let cut: Vec<Slot> = {
            let mut calls = self.calls.lock();
            let ids: Vec<CallId> =
                calls.iter().filter(|(_, s)| s.drone == drone).map(|(id, _)| *id).collect();
            ids.into_iter().filter_map(|id| calls.remove(&id)).collect()
        };
        // Where a path call stopped is known before the engine hears of the fault: a
        // handler of it may read what is left at once.
        for slot in &cut {
            slot.task.abort();
            self.note_stop(slot);
        }
        let _ = self.events.send(DroneEvent::Fault { drone, failure });
        for slot in cut {
            let _ = slot.end.send(CallEnd::Interrupted);
        }
        if let Some(Some(c)) = self.crafts.get(drone.0) {
            c.set_doing(Doing::Other);
        }
    }
}

impl Inner {
    /// The battery rule of docs/WORLD.md, on the charge the vehicle reports and its own
    /// figures (`battery`): with `need` the share of a full battery it takes to fly home at
    /// `max_speed`, wait and land as the vehicle does, at the current it has been drawing,
    /// `BatteryLow` under `2 × need + 10 %`, `BatteryCritical` under `need + 10 %`.
    fn battery_rule(&self, drone: DroneId, c: &Craft) {
        let now = aviary_clock::Instant::now();
        let (fix, battery, drawn) = {
            let seen = c.v.seen();
            (seen.fix, seen.battery, seen.draw.average(now))
        };
        let (Some(fix), Some(battery)) = (fix, battery) else {
            return;
        };
        if !c.state().airborne() {
            return;
        }
        let home = aviary_api::geometry::dist([fix.pos[0], fix.pos[1]], c.home);
        let need = c.battery.need(home, fix.pos[2], drawn);
        let (is_low, is_critical) = crate::battery::alarms(battery, need);
        let (low, critical) = self.battery.lock()[drone.0];
        if !low && is_low {
            self.battery.lock()[drone.0].0 = true;
            let _ =
                self.events.send(DroneEvent::Signal { drone, signal: BuiltinSignal::BatteryLow });
        }
        if !critical && is_critical {
            let reason = format!(
                "{}: {:.0}% left, about what it needs to get home",
                c.name,
                battery * 100.0
            );
            self.fault(drone, Failure::new(BuiltinException::BatteryCritical, reason));
        }
    }
}

async fn alarms_task(
    inner: std::sync::Weak<Inner>,
    mut alarms: mpsc::UnboundedReceiver<(DroneId, Failure)>,
) {
    while let Some((drone, failure)) = alarms.recv().await {
        let Some(inner) = inner.upgrade() else { return };
        inner.fault(drone, failure);
    }
}

/// HEARTBEAT watchdog: none for `limit` → `ConnectionLost`; the first one after →
/// `ConnectionRestored`.
async fn watchdog(inner: std::sync::Weak<Inner>, limit: Duration) {
    let mut every = aviary_clock::interval(Duration::from_millis(100));
    loop {
        every.tick().await;
        let Some(inner) = inner.upgrade() else { return };
        let now = aviary_clock::Instant::now();
        for (drone, craft) in inner.crafts.iter().enumerate() {
            let Some(c) = craft else { continue };
            inner.battery_rule(DroneId(drone), c);
            // Lost only when silent by both clocks. The mission's follows the vehicles'
            // (`clock`): on a machine too busy for its SITLs one vehicle may lag a second
            // of the wall's while the others set the pace, which is many seconds of theirs,
            // and it has not gone. At real time the two clocks agree.
            let fresh = {
                let seen = c.v.seen();
                seen.heartbeat.is_some_and(|t| now.duration_since(t) < limit)
                    || seen.heartbeat_wall.is_some_and(|t| t.elapsed() < limit)
            };
            let was_lost = inner.lost.lock()[drone];
            if was_lost == fresh {
                inner.lost.lock()[drone] = !fresh;
                if fresh {
                    let _ = inner.events.send(DroneEvent::Signal {
                        drone: DroneId(drone),
                        signal: BuiltinSignal::ConnectionRestored,
                    });
                } else {
                    let reason = format!(
                        "{}: no HEARTBEAT from system {} for {:.1} s on {}",
                        c.name,
                        c.v.system,
                        limit.as_secs_f64(),
                        c.link.address
                    );
                    inner.fault(
                        DroneId(drone),
                        Failure::new(BuiltinException::ConnectionLost, reason),
                    );
                }
            }
        }
    }
}

impl Backend for MavlinkBackend {
    fn call(&self, drone: DroneId, call: &FunctionCall) -> PendingCall {
        let function = call.function();
        let id = CallId(self.inner.next.fetch_add(1, Ordering::SeqCst));
        let (tx, rx) = oneshot::channel();
        let Some(Some(craft)) = self.inner.crafts.get(drone.0).cloned() else {
            let _ = tx.send(CallEnd::Failed(failed(format!(
                "drone number {drone} is not a MAVLink drone"
            ))));
            return PendingCall { id, end: Ending::Later(rx) };
        };
        if function.resource() == aviary_api::Resource::Motion {
            // A motion call forgets where the last path call stopped, before anything can
            // refuse it: a refused call has not moved.
            craft.set_flying_to(None);
            self.inner.stops.lock()[drone.0] = None;
        }
        if self.inner.lost.lock()[drone.0] {
            // The drone stays lost to the mission until its link is back: what is asked
            // of it meanwhile raises the exception a handler of the loss already knows.
            let reason = format!(
                "{}: no link since its HEARTBEATs stopped; `{function}` was not sent",
                craft.name
            );
            let _ =
                tx.send(CallEnd::Failed(Failure::new(BuiltinException::ConnectionLost, reason)));
            return PendingCall { id, end: Ending::Later(rx) };
        }
        let (paused_tx, paused_rx) = watch::channel(false);
        let inner = Arc::clone(&self.inner);
        let call = call.clone();
        // Hold the table while spawning, so that a call that ends at once finds its slot.
        let mut calls = self.inner.calls.lock();
        let task = tokio::spawn(async move {
            let end = match functions::run(&craft, &call, paused_rx, &inner.sensors).await {
                Ok(()) => CallEnd::Done,
                Err(failure) => CallEnd::Failed(failure),
            };
            inner.finish(id, end);
        });
        calls.insert(
            id,
            Slot { drone, function, task: task.abort_handle(), paused: paused_tx, end: tx },
        );
        PendingCall { id, end: Ending::Later(rx) }
    }

    fn interrupt(&self, call: CallId, how: Interrupt) {
        match how {
            Interrupt::Abort => {
                let Some(slot) = self.inner.calls.lock().remove(&call) else {
                    return;
                };
                slot.task.abort();
                self.inner.note_stop(&slot);
                if let Some(Some(c)) = self.inner.crafts.get(slot.drone.0).cloned() {
                    c.set_doing(Doing::Other);
                    // The drone stops where it is and hovers (the task that flew it is gone).
                    if c.state().airborne() {
                        tokio::spawn(async move { c.hold().await });
                    }
                }
                let _ = slot.end.send(CallEnd::Interrupted);
            }
            Interrupt::Pause | Interrupt::Resume => {
                if let Some(slot) = self.inner.calls.lock().get(&call) {
                    let _ = slot.paused.send(how == Interrupt::Pause);
                }
            }
        }
    }

    /// What this run's `LoadPayload` loaded and no `ReleasePayload` has dropped since: a
    /// gripper reports no kind (MAVLink has no message for what it holds), so this is
    /// what Aviary asked for and the autopilot accepted, not what a sensor saw.
    fn payload(&self, drone: DroneId) -> Option<String> {
        let Some(Some(c)) = self.inner.crafts.get(drone.0) else { return None };
        c.carrying.lock().clone()
    }

    fn telemetry(&self, drone: DroneId) -> Telemetry {
        let Some(Some(c)) = self.inner.crafts.get(drone.0) else {
            return Telemetry::LOST;
        };
        let state = c.state();
        let seen = c.v.seen();
        let fix = seen.fix;
        let position = fix.map_or([c.home[0], c.home[1], 0.0], |f| f.pos);
        Telemetry {
            position,
            gps_position: position,
            wind: None,
            speed: fix.map_or(0.0, |f| f.speed),
            heading: fix.map_or(0.0, |f| f.heading),
            battery: seen.battery.unwrap_or(1.0),
            state,
            link: !self.inner.lost.lock()[drone.0],
        }
    }

    fn stopped(&self, drone: DroneId) -> Option<Progress> {
        self.inner.stops.lock().get(drone.0).copied().flatten()
    }

    fn events(&self) -> Option<mpsc::UnboundedReceiver<DroneEvent>> {
        self.inner.taken.lock().take()
    }
}
