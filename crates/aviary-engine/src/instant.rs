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

use futures_util::future::LocalBoxFuture;

use smallvec::SmallVec;

use aviary_api::{CallEnd, DroneId, Ending, Value};
use aviary_ir::{ActorRef, BlockKind, Call, Capability, Mission, Node};

use crate::activity::{frame_values, Resume};
use crate::api::{remembers_scope, Begun};
use crate::arbiter::{free, take, Needs};
use crate::engine::{Actors, Ctx, Engine};
use crate::trace::Kind;

/// Which capabilities may run as instant activities, by index.
pub(crate) fn instant_capabilities(m: &Mission) -> Vec<bool> {
    m.capabilities.iter().map(|c| may_be_instant(m, c)).collect()
}

fn may_be_instant(m: &Mission, cap: &Capability) -> bool {
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
        && body.items.iter().all(|n| matches!(n, Node::Api(a) if !remembers_scope(&m.functions[a.function].0)))
}

/// An instant activity that has to wait, and where it stands.
enum Stopped<'m> {
    /// Before anything of it happened.
    Start(Vec<Value>),
    /// Started, at statement `at` of its body.
    At { id: u64, needs: Needs, frame: LocalFrame, args: Vec<Value>, at: usize, begun: Option<Begun<'m>> },
}

/// An instant activity's frame: on the stack when it is small, as nearly all are.
type LocalFrame = SmallVec<[Value; 4]>;

impl<'m> Engine<'m> {
    /// A statement calling a capability that may be instant.
    pub(crate) async fn instant_call(&self, call: &'m Call, ctx: &Ctx<'m>) {
        let drone = match call.actors.as_slice() {
            [ActorRef::Drone(d)] => *d,
            // Not an actor here: `call` does nothing either.
            [ActorRef::Slot(s)] => match ctx.frame.get(*s) {
                Some(Value::Actor(d)) => *d,
                _ => return,
            },
            // A group or several actors: an instance per actor, each perhaps instant.
            _ => {
                let general: LocalBoxFuture<'_, ()> = Box::pin(self.call(call, ctx));
                return general.await;
            }
        };
        let args = {
            let received = self.received.borrow();
            let env = self.env(&ctx.frame, &received);
            call.args.iter().map(|e| env.eval(e)).collect()
        };
        self.instant_instance(call, drone, args, ctx).await;
    }

    /// One instance of a capability that may be instant, on `drone`.
    pub(crate) async fn instant_instance(&self, call: &'m Call, drone: DroneId, args: Vec<Value>, ctx: &Ctx<'m>) {
        if let Some(stopped) = self.run_instant(call, drone, args, ctx) {
            self.go_on(call, drone, stopped, ctx).await;
        }
    }

    /// Runs the activity as far as it goes at once; `None` when it ended.
    fn run_instant(&self, call: &'m Call, drone: DroneId, args: Vec<Value>, ctx: &Ctx<'m>) -> Option<Stopped<'m>> {
        let cap = &self.m.capabilities[call.capability];
        let parent = ctx.instance.as_ref().map_or(&self.stop, |p| &p.token);
        if parent.is_cancelled() {
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
        self.trace(Kind::CapabilityStart, || self.capability_fields(call, &actors, &args));
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
            // operator holds the mission.
            let paused = ctx.instance.as_ref().map_or_else(|| self.mission_paused.get(), |p| p.root().paused.get());
            if paused {
                return Some(Stopped::At { id, needs, frame, args, at, begun: None });
            }
            let begun = self.api_begin(a, to, &frame);
            if !matches!(begun.end, Ending::Now(CallEnd::Done)) {
                return Some(Stopped::At { id, needs, frame, args, at, begun: Some(begun) });
            }
            self.trace_done(begun.drone, begun.function, &begun.args, &CallEnd::Done);
        }
        self.capability_end(call, &actors, &args, "ok");
        None
    }

    /// The rest of an activity that had to wait, on the general path. Boxed: its future
    /// is an instance's, far larger than the statement's that holds it.
    fn go_on<'a>(&'a self, call: &'m Call, drone: DroneId, stopped: Stopped<'m>, ctx: &'a Ctx<'m>) -> LocalBoxFuture<'a, ()> {
        Box::pin(async move {
            match stopped {
                Stopped::Start(args) => self.instance(call, Actors::from_elem(drone, 1), args, ctx).await,
                Stopped::At { id, needs, frame, args, at, begun } => {
                    // Free when the activity started, and nothing has run since.
                    let held = take(&self.arbiter, needs.clone());
                    let instance = self.new_instance(id, call, Actors::from_elem(drone, 1), ctx);
                    let claims = ctx.claims.with(&needs);
                    let frame = frame.into_iter().collect();
                    self.perform(call, instance, held, frame, claims, false, args, ctx, Resume::At(at, begun)).await;
                }
            }
        })
    }
}
