//! Instant activities. An instance of a capability whose PERFORM body is only
//! middle-layer calls (no handlers, exception handlers, sections or requirements) runs
//! from start to end in one go when each call ends as it is made (`Ending::Now`), as
//! W's steps do: no instance, scope, token or registry entry is made, and its frame is
//! on the stack. Nothing can look at an activity between two of its calls that end at
//! once: the engine is one thread, and nothing else runs until the mission waits. So
//! the trace and every effect are those of the general path (`activity.rs`).
//!
//! When the activity cannot go on at once (its claims are busy, its token is cancelled,
//! its root is paused, a call must wait, fails or is interrupted), it becomes a general
//! instance where it stands: with the id, claims and frame it has, at the statement it
//! reached, that statement's call perhaps made ([`Resume::At`]).
//!
//! A specialisation of the general path, not a second definition of it: each step here
//! is a call of the general path's own functions (`needs`, `capability_event`,
//! `api_begin`, `trace_done`, `capability_end`), in the general path's order. What holds
//! it there is `tests/instant.rs`: the examples and generated missions (claims held by
//! others, calls that take time or fail, signals, handlers, leashes, the operator's pause,
//! resume and abort, drone faults) run both ways must give the same trace, event for
//! event. The general path alone is reachable only through `aviary_engine::testing`,
//! behind a feature that only the tests' support crate turns on.

use futures_util::future::LocalBoxFuture;

use smallvec::SmallVec;

use aviary_api::{CallEnd, DroneId, Ending, Value};
use aviary_ir::{ActorRef, BlockKind, Call, CapId, Capability, Mission, Node, Slots, TiVec};

use crate::activity::{frame_values, Resume};
use crate::api::{remembers_scope, Begun};
use crate::arbiter::{free, take, Needs};
use crate::engine::{Actors, Ctx, Engine};
use aviary_api::trace::{EventKind, Status};

/// Which capabilities may run as instant activities, by index.
pub(crate) fn instant_capabilities(m: &Mission) -> TiVec<CapId, bool> {
    m.capabilities.iter().map(may_be_instant).collect()
}

fn may_be_instant(cap: &Capability) -> bool {
    let body = &cap.perform;
    cap.actors == 1
        && cap.requirements.is_empty()
        && cap.sections.is_empty()
        && cap.exception_handlers.is_empty()
        && body.kind == BlockKind::Sequential
        && body.handlers.is_empty()
        && body.exception_handlers.is_empty()
        && !body.traced
        // A detection call remembers the activity's scope: that needs the scope.
        && body.items.iter().all(|n| matches!(n, Node::Api(a) if !remembers_scope(a.function)))
}

/// An instant activity that has to wait, and where it stands. Made and taken apart at
/// once, never kept: its size does not matter.
#[allow(clippy::large_enum_variant)]
enum Stopped {
    /// Before anything of it happened.
    Start(Vec<Value>),
    /// Started, at statement `at` of its body.
    At {
        id: u64,
        needs: Needs,
        frame: LocalFrame,
        args: Vec<Value>,
        at: usize,
        begun: Option<Begun>,
    },
}

/// An instant activity's frame: on the stack when it is small, as nearly all are.
type LocalFrame = SmallVec<[Value; 4]>;

impl<'m> Engine<'m> {
    /// A statement calling a capability that may be instant, unless the mission has
    /// stopped: what `instant_call` leaves, awaited.
    pub(crate) async fn instant_statement(&self, call: &'m Call, ctx: &Ctx<'m>) {
        self.heed_interrupt();
        let rest = if self.stopped() { None } else { self.instant_call(call, ctx) };
        if let Some(rest) = rest {
            rest.await;
        }
    }

    /// A statement calling a capability that may be instant: runs what it can at once,
    /// and gives the rest, if any, to be awaited. Not `async`: a future holding what this
    /// makes along the way would hold it as long as the activity waits, in every block
    /// that waits on it.
    pub(crate) fn instant_call<'a>(
        &'a self,
        call: &'m Call,
        ctx: &'a Ctx<'m>,
    ) -> Option<LocalBoxFuture<'a, ()>> {
        let drone = match call.actors.as_slice() {
            [ActorRef::Drone(d)] => *d,
            // Not an actor here: `call` does nothing either.
            [ActorRef::Slot(s)] => match ctx.frame.slot(*s) {
                Some(Value::Actor(d)) => *d,
                _ => return None,
            },
            // A group or several actors: an instance per actor, each perhaps instant.
            _ => return Some(Box::pin(self.call(call, ctx))),
        };
        let args = {
            let received = self.received.borrow();
            let env = self.env(&ctx.frame, &received);
            call.args.iter().map(|e| env.eval(e)).collect()
        };
        self.instant_instance(call, drone, args, ctx)
    }

    /// One instance of a capability that may be instant, on `drone`: as `instant_call`.
    pub(crate) fn instant_instance<'a>(
        &'a self,
        call: &'m Call,
        drone: DroneId,
        args: Vec<Value>,
        ctx: &'a Ctx<'m>,
    ) -> Option<LocalBoxFuture<'a, ()>> {
        let stopped = self.run_instant(call, drone, args, ctx)?;
        Some(self.go_on(call, drone, stopped, ctx))
    }

    /// Runs the activity as far as it goes at once; `None` when it ended.
    fn run_instant(
        &self,
        call: &'m Call,
        drone: DroneId,
        args: Vec<Value>,
        ctx: &Ctx<'m>,
    ) -> Option<Stopped> {
        let cap = &self.m.capabilities[call.capability];
        let parent = ctx.instance.as_ref().map_or(&self.stop, |p| &p.token);
        // A drone out of the mission: the general path ends it at once (`steer.rs`).
        if parent.is_cancelled() || self.steering.withdrawn(drone).is_some() {
            return Some(Stopped::Start(args));
        }
        let actors = [drone];
        let needs = self.needs(cap, &actors, ctx);
        // Free claims are not taken: nobody can ask for them before the activity ends or
        // stops, and then they are taken (`go_on`).
        if !free(&self.arbiter, &needs) {
            return Some(Stopped::Start(args));
        }
        let id = self.new_id();
        self.trace(EventKind::CapabilityStart, || {
            self.capability_event(call, &actors, &args, None)
        });
        let mut frame = LocalFrame::new();
        // Pushed one by one: `collect` (`extend`) costs several times as much here.
        for v in frame_values(cap, &actors, &args) {
            frame.push(v);
        }
        for (at, node) in cap.perform.items.iter().enumerate() {
            let Node::Api(a) = node else { unreachable!("only calls in an instant body") };
            if self.stopped() {
                continue;
            }
            let Some(to) = self.api_drone(a, &frame) else { continue };
            // The activity's root: the caller's, or this one, which starts held while the
            // operator holds the mission. Either is held while the operator holds its
            // drone (the general path's `new_instance` holds the caller's then).
            let paused = self.steering.held(drone)
                || ctx.instance.as_ref().map_or_else(
                    || self.mission_paused.get(),
                    |p| p.root().holds(ctx.scope.section.get()),
                );
            if paused {
                return Some(Stopped::At { id, needs, frame, args, at, begun: None });
            }
            let begun = self.api_begin(a, to, &frame);
            if !matches!(begun.end, Ending::Now(CallEnd::Done)) {
                return Some(Stopped::At { id, needs, frame, args, at, begun: Some(begun) });
            }
            let made = &begun.call;
            let shown = || made.asked.shown(self);
            self.trace_done(made.drone, made.asked.function(), shown, &CallEnd::Done);
        }
        self.capability_end(call, &actors, &args, Status::Ok);
        None
    }

    /// The rest of an activity that had to wait, on the general path. Boxed, each way at
    /// its own size: the future is an instance's, far larger than the statement's that
    /// holds it, and it lives as long as the activity.
    fn go_on<'a>(
        &'a self,
        call: &'m Call,
        drone: DroneId,
        stopped: Stopped,
        ctx: &'a Ctx<'m>,
    ) -> LocalBoxFuture<'a, ()> {
        match stopped {
            Stopped::Start(args) => {
                Box::pin(self.instance(call, Actors::from_elem(drone, 1), args, ctx))
            }
            Stopped::At { id, needs, frame, args, at, begun } => {
                // Free when the activity started, and nothing has run since.
                let claims = ctx.claims.with(&needs);
                let held = take(&self.arbiter, needs);
                let instance = self.new_instance(id, call, Actors::from_elem(drone, 1), ctx);
                let frame = frame.into_iter().collect();
                Box::pin(self.perform(
                    call,
                    instance,
                    held,
                    frame,
                    claims,
                    false,
                    args,
                    ctx,
                    Resume::At(at, begun.map(Box::new)),
                ))
            }
        }
    }
}
