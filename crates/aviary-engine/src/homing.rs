//! After the mission's body, and as the failsafe after an unhandled exception or an
//! abort: every drone still in the air is brought down, and watched until it is. A drone
//! the operator takes out of the mission (`steer.rs`) is brought down the same way,
//! at once, beside the rest of the mission: home, or where it is.
//!
//! A fault that hits a drone on its way home is still an exception: it is recorded
//! (unhandled: the mission's handlers have ended) and the drone is sent again, home or,
//! when its fault requires it, straight down (no position to fly home by, a failed
//! motor). A return that fails while the drone's link is down is tried again once the
//! link is back. It ends for each drone when the drone is down or lost, or when it
//! cannot be reached for [`LINK_WAIT`] or keeps refusing for [`REFUSED_FOR`]: then it is
//! left to its autopilot's own failsafe, and the outcome says so.

use std::cell::Cell;
use std::future::{poll_fn, Future};
use std::pin::Pin;
use std::rc::Rc;
use std::task::Poll;
use std::time::Duration;

use aviary_api::{
    BuiltinException, CallEnd, DroneEvent, DroneId, FlightState, Function, FunctionCall,
};
use aviary_clock::Instant;
use futures_util::stream::{FuturesUnordered, StreamExt};

use crate::engine::{Engine, Instance};
use crate::steer::Down;
use aviary_api::trace::{CallStatus, Event, EventKind, Shown};

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
/// How many polls of the run a drone the operator took out waits for its aborted
/// activities to end before it is sent down (one is enough, a few when they nest).
const ABORTED_POLLS: usize = 16;

/// What the way down did to the fleet.
#[derive(Default)]
pub(crate) struct Homecoming {
    /// Drones not brought down safely, and why.
    pub stranded: Vec<String>,
    /// Faults of drones that came down all the same.
    pub notes: Vec<String>,
}

/// The faults of drones on their way down, outside the mission, in order: seen after
/// the mission's handlers ended, or of a drone the operator took out of it.
#[derive(Default)]
pub(crate) struct Faults {
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
    /// Brings every drone in the air down, recording what happens to them on the way,
    /// and lets `withdrawals` (what `Engine::withdrawals` made) finish bringing down those
    /// the operator took out of the mission. Returns what the outcome must say: the drones
    /// that did not come down safely (which fail the mission), and the faults of those
    /// that did.
    pub(crate) async fn all_home(
        &self,
        withdrawals: Pin<&mut impl Future<Output = ()>>,
    ) -> Homecoming {
        // A drone the operator took out is brought down by its own withdrawal, which
        // goes on here, whether it is still on its way or was left to its autopilot.
        let flying: Vec<DroneId> = (0..self.m.drones.len())
            .map(DroneId)
            .filter(|&d| {
                self.steering.withdrawn(d).is_none() && self.backend.telemetry(d).state.airborne()
            })
            .collect();
        if flying.is_empty() && !self.steering.any_withdrawn() {
            return Homecoming::default();
        }
        let homes = futures_util::future::join_all(flying.into_iter().map(|d| self.bring_down(d)));
        let mut stranded: Vec<(DroneId, String)> = tokio::select! {
            biased;
            (stranded, ()) = futures_util::future::join(homes, withdrawals) => {
                stranded.into_iter().flatten().collect()
            }
            _ = self.watch_after_end() => unreachable!("drone events never end"),
        };
        stranded.extend(self.steering.stranded.take());
        stranded.sort_by_key(|(d, _)| *d);
        let mut notes = Vec::new();
        for (d, exception) in self.down_faults.seen.borrow().iter() {
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
    async fn bring_down(&self, d: DroneId) -> Option<(DroneId, String)> {
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
            let down = self.way_down(d);
            let function = down.function();
            self.trace(EventKind::ApiCall, || Event::ApiCall {
                actor: name.into(),
                function,
                args: Vec::new(),
            });
            let pending = self.backend.call(d, &down);
            let end = {
                let guard = DownGuard { engine: self, drone: d, function, done: Cell::new(false) };
                self.steering.calls.borrow_mut().push((d, pending.id));
                let end = pending.end.wait().await.unwrap_or(CallEnd::Interrupted);
                guard.done.set(true);
                self.steering.calls.borrow_mut().retain(|(x, _)| *x != d);
                end
            };
            if self.steering.take_cut(d) && end == CallEnd::Interrupted {
                // The operator landed a drone on its way home: the return was cut for it.
                self.trace_cut(d, function);
                continue;
            }
            self.trace_done(d, function, Vec::new, &end);
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
            aviary_clock::sleep(RETRY).await;
        }
    }

    /// How `d` comes down now: landed where it is when the operator said so or its fault
    /// requires it, else home.
    fn way_down(&self, d: DroneId) -> FunctionCall {
        if self.steering.withdrawn(d) == Some(Down::Land)
            || self.down_faults.last(d).is_some_and(lands_where_it_is)
        {
            FunctionCall::Land
        } else {
            FunctionCall::ReturnToLaunch
        }
    }

    /// `api_done` of a call on the way down that will not end as it was: `aborted`.
    fn trace_cut(&self, d: DroneId, function: Function) {
        self.trace(EventKind::ApiDone, || Event::ApiDone {
            actor: self.name(d).into(),
            function,
            args: Vec::new(),
            status: CallStatus::Aborted,
            position: self.backend.telemetry(d).position,
            left: None,
        });
    }

    /// Brings down, beside the mission, each drone the operator takes out of it, as
    /// `steer.rs` queues them. Ends once the mission is over (`over`) and every one of them
    /// is down or left to its autopilot; until then it never ends.
    pub(crate) async fn withdrawals(&self) {
        let mut running = FuturesUnordered::new();
        poll_fn(|cx| loop {
            for (d, aborted) in self.steering.queued.take() {
                running.push(self.withdraw(d, aborted));
            }
            while let Poll::Ready(Some(())) = running.poll_next_unpin(cx) {}
            // A drone queued by what just ran is taken at once.
            if !self.steering.queued.borrow().is_empty() {
                continue;
            }
            self.steering.waker.replace(Some(cx.waker().clone()));
            return if running.is_empty() && self.over.get() {
                Poll::Ready(())
            } else {
                Poll::Pending
            };
        })
        .await
    }

    /// One drone the operator took out: once the activities aborted for it have ended
    /// (their calls cut, their ends written), it is brought down as at the end.
    async fn withdraw(&self, d: DroneId, aborted: Vec<Rc<Instance>>) {
        // Each ends at its next poll, which comes first in the run's order; after the
        // mission's end, with its body dropped, none ever will, and none is in the way.
        // Their calls were cut as they were aborted, so the wait is only for the trace's
        // order, and it is bounded: an activity dropped inside another (a `PERFORM
        // ABORT:` section's) never leaves the registry, and time stands still while this
        // waits.
        let mut polls = 0;
        while !self.over.get()
            && polls < ABORTED_POLLS
            && aborted.iter().any(|r| self.registered(r))
        {
            polls += 1;
            yield_once().await;
        }
        if let Some(stranded) = self.bring_down(d).await {
            self.steering.stranded.borrow_mut().push(stranded);
        }
    }

    /// Whether a root activity still runs (is in the registry).
    fn registered(&self, root: &Rc<Instance>) -> bool {
        let instances = self.instances.borrow();
        root.actors.iter().any(|d| instances.of_actor(*d).any(|(i, _)| Rc::ptr_eq(i, root)))
    }

    /// A drone event of a drone on its way down, outside the mission: a fault is still an
    /// exception of its drone, recorded, unhandled, and remembered (it may decide how the
    /// drone comes down); the rest is recorded as it comes.
    pub(crate) fn on_the_way_down(&self, event: DroneEvent) {
        match event {
            DroneEvent::Fault { drone, failure } => {
                self.down_faults.seen.borrow_mut().push((drone, failure.exception));
                self.trace(EventKind::Exception, || Event::Exception {
                    name: failure.exception.name().into(),
                    actor: Some(self.name(drone).into()),
                    args: vec![Shown::Text(failure.reason.as_str().into())],
                    handled: false,
                    handler: None,
                    during: Some("return home".into()),
                    skipped: None,
                    line: None,
                    cause: failure.cause,
                });
            }
            DroneEvent::Signal { drone, signal } => {
                self.trace(EventKind::Signal, || Event::Signal {
                    name: signal.name().into(),
                    actor: Some(self.name(drone).into()),
                    args: Vec::new(),
                    by: None,
                    line: None,
                });
            }
            DroneEvent::Detected { drone, kind, location } => {
                self.trace(EventKind::Detection, || Event::Detection {
                    actor: self.name(drone).into(),
                    kind: kind.as_str().into(),
                    location,
                });
            }
            DroneEvent::Autopilot { drone, action, reason } => {
                self.autopilot(drone, action, &reason)
            }
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
            aviary_clock::sleep(LINK_POLL).await;
        }
        false
    }

    /// Drone events after the mission's handlers have ended, each as on the way down.
    async fn watch_after_end(&self) {
        loop {
            match self.next_event().await {
                Some(event) => self.on_the_way_down(event),
                None => std::future::pending().await,
            }
        }
    }
}

/// Lets every other branch of the run be polled once before going on.
async fn yield_once() {
    let mut yielded = false;
    poll_fn(|cx| {
        if yielded {
            return Poll::Ready(());
        }
        yielded = true;
        cx.waker().wake_by_ref();
        Poll::Pending
    })
    .await
}

/// Writes `api_done` (`aborted`) for a call on the way down whose wait is dropped before
/// it ended (the backend was lost): every `api_call` has its `api_done`.
struct DownGuard<'e, 'm> {
    engine: &'e Engine<'m>,
    drone: DroneId,
    function: Function,
    done: Cell<bool>,
}

impl Drop for DownGuard<'_, '_> {
    fn drop(&mut self) {
        if !self.done.get() {
            self.engine.steering.calls.borrow_mut().retain(|(x, _)| *x != self.drone);
            self.engine.trace_cut(self.drone, self.function);
        }
    }
}
