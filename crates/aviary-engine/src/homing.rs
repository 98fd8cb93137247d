//! After the mission's body, and as the failsafe after an unhandled exception or an
//! abort: every drone still in the air is brought down, and watched until it is.
//!
//! A fault that hits a drone on its way home is still an exception: it is recorded
//! (unhandled: the mission's handlers have ended) and the drone is sent again, home or,
//! when its fault requires it, straight down (no position to fly home by, a failed
//! motor). A return that fails while the drone's link is down is tried again once the
//! link is back. It ends for each drone when the drone is down or lost, or when it
//! cannot be reached for [`LINK_WAIT`] or keeps refusing for [`REFUSED_FOR`]: then it is
//! left to its autopilot's own failsafe, and the outcome says so.

use std::time::Duration;

use aviary_api::{BuiltinException, CallEnd, DroneEvent, DroneId, FlightState, Function};
use tokio::time::Instant;

use crate::engine::Engine;
use aviary_api::trace::{Event, EventKind, Shown};

/// How long a drone in the air may stay out of reach before it is left to its
/// autopilot. Longer than any autopilot's own link-loss failsafe takes to act
/// (ArduCopter's FS_GCS_TIMEOUT is 5 s), so the vehicle is on its way by then.
const LINK_WAIT: Duration = Duration::from_secs(120);
/// How long a drone in the air may keep refusing to come down before it is left to its
/// autopilot.
const REFUSED_FOR: Duration = Duration::from_secs(300);
/// Between two tries of a refused or interrupted return.
const RETRY: Duration = Duration::from_secs(2);
/// How often an unreachable drone's link is looked at.
const LINK_POLL: Duration = Duration::from_millis(500);

/// What the way down did to the fleet.
#[derive(Default)]
pub(crate) struct Homecoming {
    /// Drones not brought down safely, and why.
    pub stranded: Vec<String>,
    /// Faults of drones that came down all the same.
    pub notes: Vec<String>,
}

/// The faults seen after the mission's handlers ended, in order.
#[derive(Default)]
struct Faults {
    seen: std::cell::RefCell<Vec<(DroneId, BuiltinException)>>,
}

impl Faults {
    fn last(&self, d: DroneId) -> Option<BuiltinException> {
        self.seen.borrow().iter().rev().find(|(x, _)| *x == d).map(|(_, e)| *e)
    }
}

/// Faults that leave a drone unable to fly home: it comes straight down instead.
fn lands_where_it_is(exception: BuiltinException) -> bool {
    matches!(exception, BuiltinException::PositionLost | BuiltinException::MotorFailure)
}

impl<'m> Engine<'m> {
    /// Brings every drone in the air down, recording what happens to them on the way.
    /// Returns what the outcome must say: the drones that did not come down safely
    /// (which fail the mission), and the faults of those that did.
    pub(crate) async fn all_home(&self) -> Homecoming {
        let flying: Vec<DroneId> = (0..self.m.drones.len())
            .filter(|&d| self.backend.telemetry(d).state.airborne())
            .collect();
        if flying.is_empty() {
            return Homecoming::default();
        }
        let faults = Faults::default();
        let homes =
            futures_util::future::join_all(flying.into_iter().map(|d| self.bring_down(d, &faults)));
        let stranded: Vec<(DroneId, String)> = tokio::select! {
            biased;
            stranded = homes => stranded.into_iter().flatten().collect(),
            _ = self.watch_after_end(&faults) => unreachable!("drone events never end"),
        };
        let mut notes = Vec::new();
        for (d, exception) in faults.seen.borrow().iter() {
            if !stranded.iter().any(|(s, _)| s == d) {
                notes.push(format!(
                    "{exception} on {} on its way down, which it survived",
                    self.name(*d)
                ));
            }
        }
        Homecoming { stranded: stranded.into_iter().map(|(_, why)| why).collect(), notes }
    }

    /// One drone: sent home (or down) until it is on the ground or lost.
    async fn bring_down(&self, d: DroneId, faults: &Faults) -> Option<(DroneId, String)> {
        let name = self.name(d);
        let mut refused_since: Option<Instant> = None;
        loop {
            let t = self.backend.telemetry(d);
            if t.state == FlightState::Lost {
                return Some((d, format!("{name} was lost on its way down")));
            }
            if !t.state.airborne() {
                return None;
            }
            if !t.link {
                if !self.link_back(d).await {
                    return Some((d, format!("{name} was out of reach for {} s on its way down: left to its autopilot's failsafe", LINK_WAIT.as_secs())));
                }
                continue;
            }
            let function = if faults.last(d).is_some_and(lands_where_it_is) {
                Function::Land
            } else {
                Function::ReturnToLaunch
            };
            self.trace(EventKind::ApiCall, || Event::ApiCall {
                actor: name.into(),
                function,
                args: Vec::new(),
            });
            let pending = self.backend.call(d, function, &[]);
            let end = pending.end.wait().await.unwrap_or(CallEnd::Interrupted);
            self.trace_done(d, function, &[], &end);
            if end == CallEnd::Done {
                refused_since = None;
                continue;
            }
            let since = *refused_since.get_or_insert_with(Instant::now);
            if since.elapsed() >= REFUSED_FOR && self.backend.telemetry(d).state.airborne() {
                return Some((
                    d,
                    format!(
                        "{name} refused to come down for {} s: left to its autopilot's failsafe",
                        REFUSED_FOR.as_secs()
                    ),
                ));
            }
            tokio::time::sleep(RETRY).await;
        }
    }

    /// Waits until the drone can be reached again (or is no longer in the air); false
    /// after [`LINK_WAIT`].
    async fn link_back(&self, d: DroneId) -> bool {
        let until = Instant::now() + LINK_WAIT;
        while Instant::now() < until {
            let t = self.backend.telemetry(d);
            if t.link || !t.state.airborne() {
                return true;
            }
            tokio::time::sleep(LINK_POLL).await;
        }
        false
    }

    /// Drone events after the mission's handlers have ended: a fault is still an
    /// exception of its drone (recorded, unhandled), the rest is recorded as it comes.
    async fn watch_after_end(&self, faults: &Faults) {
        loop {
            match self.next_event().await {
                Some(DroneEvent::Fault { drone, failure }) => {
                    faults.seen.borrow_mut().push((drone, failure.exception));
                    self.trace(EventKind::Exception, || Event::Exception {
                        name: failure.exception.name().into(),
                        actor: Some(self.name(drone).into()),
                        args: vec![Shown::Text(failure.reason.as_str().into())],
                        handled: false,
                        handler: None,
                        during: Some("return home".into()),
                        skipped: None,
                    });
                }
                Some(DroneEvent::Signal { drone, signal }) => {
                    self.trace(EventKind::Signal, || Event::Signal {
                        name: signal.name().into(),
                        actor: Some(self.name(drone).into()),
                        args: Vec::new(),
                    });
                }
                Some(DroneEvent::Detected { drone, kind, location }) => {
                    self.trace(EventKind::Detection, || Event::Detection {
                        actor: self.name(drone).into(),
                        kind: kind.as_str().into(),
                        location,
                    });
                }
                None => std::future::pending().await,
            }
        }
    }
}
