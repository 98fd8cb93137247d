//! One ground station's share of the server: its own queue of messages to send, its own
//! stream rates, and its own sequence numbers.
//!
//! The queue has two lanes; the first is sent before the second:
//! - heartbeats, answers and events (COMMAND_ACK, STATUSTEXT, PARAM_VALUE,
//!   AUTOPILOT_VERSION, HOME_POSITION), in the order they happened (a failsafe's words
//!   come before the HEARTBEAT that shows its mode). Heartbeats are never dropped (a
//!   client that reads nothing for [`BEAT_BACKLOG`] heartbeats of a vehicle, two minutes,
//!   loses only the oldest of them); past [`EVENTS_MAX`] waiting, a client that sends
//!   faster than it reads loses its newest answers, as ArduPilot drops what finds no room
//!   in a link's buffer;
//! - telemetry streams, coalesced: a lagging client gets the newest message of each kind
//!   for each vehicle, not a backlog.
//!
//! Messages are numbered when written, per vehicle and per client (MAVLink's sequence is
//! per sending system and per link), so a client sees each vehicle's numbers rise by one
//! per message: what a lagging client never got was never numbered.

use std::collections::{HashMap, VecDeque};
use std::sync::atomic::{AtomicU64, Ordering};

use parking_lot::Mutex;

use aviary_mavlink::mavlink::{MavHeader, Message};
use tokio::sync::Notify;
use tokio::task::AbortHandle;

use crate::autopilot::Out;

/// Heartbeats kept per vehicle for a client that does not read.
pub const BEAT_BACKLOG: usize = 120;
/// Answers and events kept for a client that does not read.
pub const EVENTS_MAX: usize = 4096;

#[derive(Default)]
struct Lanes {
    /// Heartbeats and events, in order.
    events: VecDeque<Out>,
    telemetry: VecDeque<Out>,
}

fn is_heartbeat(o: &Out) -> bool {
    o.msg.message_id() == 0
}

/// Per (system, message id): the rate a client asked for (Hz; 0 is off) and when the
/// next one is due (seconds of the vehicles' time since the server started).
#[derive(Default)]
pub struct Schedule {
    rates: HashMap<(u8, u32), f64>,
    due: HashMap<(u8, u32), f64>,
}

impl Schedule {
    /// Sets a stream's rate (None: back to the default); the next one goes out at once.
    pub fn set(&mut self, system: u8, id: u32, hz: Option<f64>) {
        match hz {
            Some(hz) => self.rates.insert((system, id), hz),
            None => self.rates.remove(&(system, id)),
        };
        self.due.remove(&(system, id));
    }

    /// Whether a stream of `default_hz` is due at `now`; if so, schedules the next one.
    pub fn due(&mut self, system: u8, id: u32, default_hz: f64, now: f64) -> bool {
        let hz = self.rates.get(&(system, id)).copied().unwrap_or(default_hz);
        if hz <= 0.0 {
            return false;
        }
        let next = self.due.entry((system, id)).or_insert(now);
        if now + 1e-9 < *next {
            return false;
        }
        // From now, not from when it was due: a late tick does not cause a burst.
        *next = now + 1.0 / hz;
        true
    }
}

pub struct Client {
    pub id: u64,
    lanes: Mutex<Lanes>,
    ready: Notify,
    pub schedule: Mutex<Schedule>,
    /// Its reader and writer, ended when the server stops.
    pub tasks: Mutex<Vec<AbortHandle>>,
}

static NEXT_ID: AtomicU64 = AtomicU64::new(1);

impl Client {
    pub fn new() -> Client {
        Client {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            lanes: Mutex::default(),
            ready: Notify::new(),
            schedule: Mutex::default(),
            tasks: Mutex::default(),
        }
    }

    pub fn heartbeat(&self, o: Out) {
        let mut l = self.lanes.lock();
        let mine = |b: &Out| is_heartbeat(b) && b.system == o.system;
        if l.events.iter().filter(|b| mine(b)).count() >= BEAT_BACKLOG {
            if let Some(k) = l.events.iter().position(mine) {
                l.events.remove(k);
            }
        }
        l.events.push_back(o);
        drop(l);
        self.ready.notify_one();
    }

    pub fn event(&self, o: Out) {
        let mut l = self.lanes.lock();
        if l.events.len() >= EVENTS_MAX {
            return;
        }
        l.events.push_back(o);
        drop(l);
        self.ready.notify_one();
    }

    /// A stream message: replaces one of the same kind from the same vehicle still waiting.
    pub fn telemetry(&self, o: Out) {
        let mut l = self.lanes.lock();
        let id = o.msg.message_id();
        match l.telemetry.iter_mut().find(|t| t.system == o.system && t.msg.message_id() == id) {
            Some(waiting) => *waiting = o,
            None => l.telemetry.push_back(o),
        }
        drop(l);
        self.ready.notify_one();
    }

    pub(crate) fn pop(&self) -> Option<Out> {
        let mut l = self.lanes.lock();
        l.events.pop_front().or_else(|| l.telemetry.pop_front())
    }

    /// The next message to write, waiting for one.
    pub async fn next(&self) -> Out {
        loop {
            if let Some(o) = self.pop() {
                return o;
            }
            self.ready.notified().await;
        }
    }

    pub fn abort(&self) {
        for t in self.tasks.lock().iter() {
            t.abort();
        }
    }
}

/// Sequence numbers of one link, per sending system: the first message is 0.
pub struct Sequences([u8; 256]);

impl Sequences {
    pub fn new() -> Sequences {
        Sequences([0; 256])
    }

    pub fn header(&mut self, system: u8) -> MavHeader {
        let s = &mut self.0[usize::from(system)];
        let sequence = *s;
        *s = s.wrapping_add(1);
        MavHeader { system_id: u32::from(system), component_id: 1, sequence }
    }
}

/// Every connected client.
#[derive(Default)]
pub struct Registry(Mutex<Vec<std::sync::Arc<Client>>>);

impl Registry {
    pub fn add(&self, c: std::sync::Arc<Client>) {
        self.0.lock().push(c);
    }

    pub fn remove(&self, id: u64) {
        self.0.lock().retain(|c| c.id != id);
    }

    pub fn all(&self) -> Vec<std::sync::Arc<Client>> {
        self.0.lock().clone()
    }

    pub fn len(&self) -> usize {
        self.0.lock().len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::Wire;
    use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavMessage, HEARTBEAT_DATA};

    fn out(system: u8, msg: MavMessage) -> Out {
        Out { system, msg: msg.into() }
    }

    #[test]
    fn events_go_first_in_order_and_telemetry_is_coalesced() {
        let c = Client::new();
        let pos = |t| {
            MavMessage::GLOBAL_POSITION_INT(
                aviary_mavlink::mavlink::dialects::ardupilotmega::GLOBAL_POSITION_INT_DATA {
                    time_boot_ms: t,
                    ..Default::default()
                },
            )
        };
        c.telemetry(out(1, pos(1)));
        c.telemetry(out(2, pos(1)));
        c.telemetry(out(1, pos(2)));
        c.event(out(1, MavMessage::STATUSTEXT(Default::default())));
        c.heartbeat(out(1, MavMessage::HEARTBEAT(HEARTBEAT_DATA::default())));
        let order: Vec<_> = std::iter::from_fn(|| c.pop())
            .map(|o| (o.system, o.msg.message_name(), o.msg))
            .collect();
        assert_eq!(order.len(), 4);
        assert_eq!((order[0].0, order[0].1), (1, "STATUSTEXT"));
        assert_eq!((order[1].0, order[1].1), (1, "HEARTBEAT"));
        assert_eq!(order[2].2, pos(2).into(), "the newer position replaced the older");
        assert_eq!(order[3].0, 2);
    }

    #[test]
    fn heartbeats_are_kept_past_the_event_limit_and_only_the_oldest_go() {
        let c = Client::new();
        for _ in 0..EVENTS_MAX + 10 {
            c.event(out(1, MavMessage::STATUSTEXT(Default::default())));
        }
        for t in 0..BEAT_BACKLOG as u32 + 5 {
            let hb = HEARTBEAT_DATA { custom_mode: t, ..Default::default() };
            c.heartbeat(out(1, MavMessage::HEARTBEAT(hb)));
        }
        let all: Vec<_> = std::iter::from_fn(|| c.pop()).collect();
        let beats: Vec<u32> = all
            .iter()
            .filter_map(|o| match &o.msg {
                Wire::Mav(MavMessage::HEARTBEAT(h)) => Some(h.custom_mode),
                _ => None,
            })
            .collect();
        assert_eq!(all.len() - beats.len(), EVENTS_MAX, "events past the limit dropped");
        assert_eq!(beats.len(), BEAT_BACKLOG);
        assert_eq!(beats[0], 5, "the oldest heartbeats went first");
        assert_eq!(*beats.last().unwrap(), BEAT_BACKLOG as u32 + 4);
    }

    #[test]
    fn a_stream_is_due_at_its_rate_and_a_new_rate_applies_at_once() {
        let mut s = Schedule::default();
        assert!(s.due(1, 33, 4.0, 0.0));
        assert!(!s.due(1, 33, 4.0, 0.2));
        assert!(s.due(1, 33, 4.0, 0.25));
        s.set(1, 33, Some(0.0));
        assert!(!s.due(1, 33, 4.0, 10.0));
        s.set(1, 33, Some(10.0));
        assert!(s.due(1, 33, 4.0, 10.01));
        assert!(s.due(1, 33, 4.0, 10.11));
        s.set(1, 33, None);
        assert!(s.due(1, 33, 4.0, 10.12) && !s.due(1, 33, 4.0, 10.2));
    }

    #[test]
    fn sequences_are_per_system() {
        let mut s = Sequences::new();
        assert_eq!(s.header(1).sequence, 0);
        assert_eq!(s.header(2).sequence, 0);
        assert_eq!(s.header(1).sequence, 1);
    }
}
