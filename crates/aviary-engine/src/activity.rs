//! Capability instances (activities) on the general path: claims, start, requirements,
//! the PERFORM body in the instance's scope, leash abort sections, the end.

use std::cell::{Cell, RefCell};
use std::pin::pin;
use std::rc::Rc;

use std::borrow::Cow;

use aviary_api::trace::{Event, EventKind, Params, Shown, Status};
use aviary_api::{BuiltinException, DroneId, Value};
use aviary_ir::{BlockKind, Call, Capability};
use smallvec::SmallVec;
use tokio::sync::Notify;

use crate::api::Begun;
use crate::arbiter::{acquire, try_acquire, Claims, Held, Needs};
use crate::cancel::Token as CancellationToken;
use crate::engine::{Actors, Ctx, Engine, Frame, Instance, Scope};
use crate::jobs::Jobs;
use crate::place::Level;

/// Where an instance's PERFORM body starts: at its beginning, or (an instant activity
/// that has to wait, `instant.rs`) at a statement of its sequence, that statement's
/// call perhaps already made.
pub(crate) enum Resume {
    Start,
    /// The call is boxed: the future of every instance has room for its `Resume`.
    At(usize, Option<Box<Begun>>),
}

/// An instance that has started, for `perform`.
struct Started {
    instance: Rc<Instance>,
    held: Held,
    frame: Frame,
    claims: Claims,
    listed: bool,
    args: Vec<Value>,
}

/// An instance's frame: actors, then arguments, then the body's own slots.
pub(crate) fn frame_values<'a>(
    cap: &'a Capability,
    actors: &'a [DroneId],
    args: &'a [Value],
) -> impl ExactSizeIterator<Item = Value> + 'a {
    let size = cap.frame_size.max(cap.actors + cap.params.len());
    (0..size).map(move |i| match i.checked_sub(cap.actors) {
        None => actors.get(i).map_or(Value::Absent, |d| Value::Actor(*d)),
        Some(j) => args.get(j).cloned().unwrap_or(Value::Absent),
    })
}

impl<'m> Engine<'m> {
    pub(crate) async fn instance(
        &self,
        call: &'m Call,
        actors: Actors,
        args: Vec<Value>,
        ctx: &Ctx<'m>,
    ) {
        // What `start` made is handed to `perform` and not kept beside its future.
        let rest = match self.start(call, actors, args, ctx).await {
            Some(Started { instance, held, frame, claims, listed, args }) => {
                self.perform(call, instance, held, frame, claims, listed, args, ctx, Resume::Start)
            }
            None => return,
        };
        rest.await;
    }

    /// An instance up to its start: its claims held (waited for if need be), `capability_start`
    /// recorded, its requirements met. `None` if it ends there.
    async fn start(
        &self,
        call: &'m Call,
        actors: Actors,
        args: Vec<Value>,
        ctx: &Ctx<'m>,
    ) -> Option<Started> {
        let cap = &self.m.capabilities[call.capability];
        if self.any_withdrawn(&actors) {
            // A drone of it is out of the mission (the operator took it, `steer.rs`): it
            // ends at once, without flying, and its block goes on.
            self.trace(EventKind::CapabilityStart, || {
                self.capability_event(call, &actors, &args, None)
            });
            self.capability_end(call, &actors, &args, Status::Aborted);
            return None;
        }
        if self.too_deep(call, &actors, ctx) {
            return None;
        }
        let frame: Frame = frame_values(cap, &actors, &args).collect();
        let instance = self.new_instance(self.new_id(), call, actors, ctx);
        let actor = instance.actors.first().copied();
        // Claims first (a second instance on a busy resource waits), then the start.
        let needs = self.needs(cap, &instance.actors, ctx);
        let claims = ctx.claims.with(&needs);
        // An instance that waits is known while it waits (a leash can abort it), by where
        // it was called; one granted at once is listed once its own scope exists.
        let mut listed = false;
        let held = if instance.token.is_cancelled() {
            None
        } else {
            match try_acquire(&self.arbiter, needs) {
                Ok(held) => Some(held),
                Err(needs) => {
                    self.instances.borrow_mut().insert(instance.clone(), ctx.scope.clone());
                    listed = true;
                    instance.token.run(acquire(&self.arbiter, needs)).await
                }
            }
        };
        if self.stopped() {
            self.instances.borrow_mut().remove(&instance);
            return None;
        }
        self.trace(EventKind::CapabilityStart, || {
            self.capability_event(call, &instance.actors, &args, None)
        });
        let Some(held) = held else {
            self.instances.borrow_mut().remove(&instance);
            self.capability_end(call, &instance.actors, &args, Status::Aborted);
            return None;
        };
        let requirements_met = {
            let received = self.received.borrow();
            let env = self.env(&frame, &received);
            cap.requirements.iter().all(|r| env.truth(r))
        };
        if !requirements_met {
            self.instances.borrow_mut().remove(&instance);
            self.capability_end(call, &instance.actors, &args, Status::Failed);
            drop(held);
            let id = self.m.builtins.exception(BuiltinException::RequirementNotMet);
            let why = format!("a requirement of {} does not hold", cap.name);
            self.throw(id, vec![Value::Text(why)], actor, &ctx.scope, Some(call.origin), None);
            return None;
        }
        Some(Started { instance, held, frame, claims, listed, args })
    }

    /// The rest of an instance, once it holds its claims and has started: its body in its
    /// own scope until it ends or is aborted, then its end.
    #[allow(clippy::too_many_arguments)]
    pub(crate) async fn perform(
        &self,
        call: &'m Call,
        instance: Rc<Instance>,
        held: Held,
        frame: Frame,
        claims: Claims,
        listed: bool,
        args: Vec<Value>,
        ctx: &Ctx<'m>,
        resume: Resume,
    ) {
        let cap = &self.m.capabilities[call.capability];
        *instance.claims.borrow_mut() = claims.clone();
        let scope = Rc::new(Scope {
            parent: Some(ctx.scope.clone()),
            path: &cap.name,
            mission_block: false,
            handlers: &[],
            fired: RefCell::new(Vec::new()),
            exception_handlers: &cap.exception_handlers,
            frame: RefCell::new(frame.clone()),
            jobs: Jobs::default(),
            unwinding: Cell::new(false),
            deferred: RefCell::new(Vec::new()),
            serial: RefCell::new(Vec::new()),
            catching: Cell::new(0),
            caught: Notify::new(),
            instance: Some(instance.clone()),
            section: Cell::new(ctx.scope.section.get()),
            stop: ctx.scope.stop.clone(),
        });
        if listed {
            self.instances.borrow_mut().set_scope(&instance, scope.clone());
        } else {
            self.instances.borrow_mut().insert(instance.clone(), scope.clone());
        }
        let actor = instance.actors.first().copied();
        let inner =
            Ctx { scope: scope.clone(), frame, actor, instance: Some(instance.clone()), claims };
        // A PERFORM body that declares no handlers, in a capability without exception
        // handlers, runs its statements in the instance's own scope: a scope of its own
        // would hear nothing and catch nothing, and an exception unwinds both alike.
        let own_scope = !cap.perform.handlers.is_empty()
            || !cap.perform.exception_handlers.is_empty()
            || cap.perform.traced;
        // A body in a scope of its own is where its drones' own events are raised between
        // two calls (`place.rs`); one run in the instance's scope needs no place.
        let body_block = || {
            Box::pin(self.block_with(&cap.perform, &inner, |body| {
                self.place(&instance.actors, instance.depth, Level::Body, body)
            }))
        };
        let body = pin!(async {
            match resume {
                Resume::Start => match &instance.perform {
                    Some(perform) => _ = perform.run(body_block()).await,
                    None if own_scope => body_block().await,
                    None => self.items(&cap.perform, &inner).await,
                },
                // Only for a sequence run in the instance's scope (`instant.rs`).
                Resume::At(at, begun) => {
                    debug_assert!(
                        cap.perform.kind == BlockKind::Sequential
                            && !own_scope
                            && instance.perform.is_none()
                    );
                    let next = at + usize::from(begun.is_some());
                    if let Some(begun) = begun {
                        self.api_end(*begun, &inner).await;
                        self.caught(&inner).await;
                    }
                    self.sequence(&cap.perform.items[next..], &inner).await;
                }
            }
        });
        let drive = pin!(self.drive(&scope, body));
        let finished = instance.token.run(drive).await.is_some();
        self.instances.borrow_mut().remove(&instance);
        // Not for a drone the operator took out of the mission (`steer.rs`): the way down
        // is the operator's, not the section's.
        if !finished && instance.by_leash.get() && !self.any_withdrawn(&instance.actors) {
            // `PERFORM ABORT:` says what aborting this activity also does.
            if let Some((_, section)) = cap.abort_section.map(|k| &cap.sections[k]) {
                let after = Ctx { instance: None, ..inner.clone() };
                self.block(section, &after).await;
            }
        }
        drop(held);
        let status = if finished && !instance.failed.get() {
            Status::Ok
        } else if instance.failed.get() {
            Status::Failed
        } else {
            Status::Aborted
        };
        self.capability_end(call, &instance.actors, &args, status);
    }

    /// Whether this call would nest deeper than the limit: then it does not start, and
    /// raises `CommandFailed` of its actor where it stands, as a refused command does.
    /// Only a capability that calls itself (behind a condition the checker cannot judge)
    /// gets here; without the limit it would overflow the stack.
    fn too_deep(&self, call: &'m Call, actors: &[DroneId], ctx: &Ctx<'m>) -> bool {
        let depth = ctx.instance.as_ref().map_or(0, |p| p.depth + 1);
        if depth < self.max_call_depth {
            return false;
        }
        let cap = &self.m.capabilities[call.capability];
        let id = self.m.builtins.exception(BuiltinException::CommandFailed);
        let why = format!(
            "calling `{}` would nest capability calls {} deep, past the limit of {}: a capability that keeps calling itself",
            cap.name,
            depth + 1,
            self.max_call_depth
        );
        self.throw(
            id,
            vec![Value::Text(why)],
            actors.first().copied(),
            &ctx.scope,
            Some(call.origin),
            None,
        );
        true
    }

    pub(crate) fn new_id(&self) -> u64 {
        let id = self.next_id.get() + 1;
        self.next_id.set(id);
        id
    }

    pub(crate) fn new_instance(
        &self,
        id: u64,
        call: &'m Call,
        actors: Actors,
        ctx: &Ctx<'m>,
    ) -> Rc<Instance> {
        let cap = &self.m.capabilities[call.capability];
        // A drone of it the operator holds holds the activity its statement started.
        let held = actors.iter().any(|d| self.steering.held(*d));
        if let (true, Some(parent)) = (held, &ctx.instance) {
            self.hold_root(parent.root());
        }
        Rc::new(Instance {
            id,
            capability: call.capability,
            tag: call.tag,
            actors,
            root: ctx.instance.as_ref().map(|p| p.root().clone()),
            token: ctx
                .instance
                .as_ref()
                .map_or_else(|| self.mission_level_token(ctx), |p| p.token.child_token()),
            // Only the capability's own exception handler cancels its PERFORM body.
            perform: (!cap.exception_handlers.is_empty()).then(CancellationToken::new),
            by_leash: Cell::new(false),
            failed: Cell::new(false),
            // An activity started while the operator holds the mission starts held.
            paused: Cell::new(ctx.instance.is_none() && self.mission_paused.get()),
            held: Cell::new(ctx.instance.is_none() && held),
            resumed: Notify::new(),
            calls: RefCell::new(SmallVec::new()),
            sections: Cell::new(0),
            section_calls: RefCell::new(SmallVec::new()),
            turn: tokio::sync::Semaphore::const_new(1),
            depth: ctx.instance.as_ref().map_or(0, |p| p.depth + 1),
            claims: RefCell::new(ctx.claims.clone()),
        })
    }

    /// What an instance claims beyond what its caller already holds.
    pub(crate) fn needs(&self, cap: &Capability, actors: &[DroneId], ctx: &Ctx<'m>) -> Needs {
        cap.claims
            .iter()
            .filter_map(|(i, r)| actors.get(*i).map(|d| (*d, *r)))
            .filter(|c| !ctx.claims.contains(c))
            .collect()
    }

    /// `capability_start`, or with the status it ended with, `capability_end` (made only
    /// when the trace wants them).
    pub(crate) fn capability_event<'a>(
        &'a self,
        call: &Call,
        actors: &[DroneId],
        args: &'a [Value],
        end: Option<Status>,
    ) -> Event<'a> {
        let cap = &self.m.capabilities[call.capability];
        let tag = call.tag.map(|t| Cow::Borrowed(self.m.tags[t].as_str()));
        let shown = cap.params.iter().zip(args);
        let params = Params(
            shown.map(|(p, v)| (Cow::Borrowed(p.as_str()), Shown::of(v, &self.m.drones))).collect(),
        );
        let actor = match actors {
            [one] => Cow::Borrowed(self.name(*one)),
            all => Cow::Owned(all.iter().map(|d| self.name(*d)).collect::<Vec<_>>().join(" ")),
        };
        let capability = Cow::Borrowed(cap.name.as_str());
        let line = self.m.line_of(&call.origin);
        match end {
            None => Event::CapabilityStart { actor, capability, tag, args: params, line },
            Some(status) => {
                Event::CapabilityEnd { actor, capability, tag, args: params, status, line }
            }
        }
    }

    pub(crate) fn capability_end(
        &self,
        call: &Call,
        actors: &[DroneId],
        args: &[Value],
        status: Status,
    ) {
        self.trace(EventKind::CapabilityEnd, || {
            self.capability_event(call, actors, args, Some(status))
        });
    }
}
