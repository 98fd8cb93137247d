//! Middle-layer calls: made, waited for (held while the activity is paused, interrupted
//! when it is dropped), traced, and what their ending raises.
//!
//! A call is split in two, [`Engine::api_begin`] (evaluate, trace `api_call`, call) and
//! [`Engine::api_end`] (wait, `CallGuard`, `api_done`, what a failure or interruption
//! raises), so that an instant activity can hand a call it made to the general path.

use std::cell::Cell;
use std::rc::Rc;

use aviary_api::trace::Shown;
use aviary_api::{
    BuiltinException, CallEnd, CallId, DroneId, Ending, Failure, Function, FunctionCall, Interrupt,
    Value,
};
use aviary_ir::{ApiCall, TiSlice};

use crate::engine::{Ctx, Engine, Instance};
use crate::place::Level;
use aviary_api::trace::{CallStatus, Event, EventKind};

/// A call made: what the rest of its statement needs.
pub(crate) struct Begun {
    pub call: Made,
    pub end: Ending,
}

/// Which call was made, with what.
pub(crate) struct Made {
    pub drone: DroneId,
    pub asked: Asked,
    pub id: CallId,
}

/// What a call asked for: its arguments read ([`FunctionCall::new`], the one place they
/// are), or, when they could not be, the values given (for the trace) and why (the call
/// is refused without reaching the backend).
pub(crate) enum Asked {
    Read(FunctionCall),
    /// Boxed: rare, and no larger a call than a read one to keep.
    Unread(Box<Unread>),
}

pub(crate) struct Unread {
    function: Function,
    args: Vec<Value>,
    reason: String,
}

impl Asked {
    pub fn function(&self) -> Function {
        match self {
            Asked::Read(call) => call.function(),
            Asked::Unread(u) => u.function,
        }
    }

    /// The arguments as the trace shows them.
    pub fn shown<'a>(&'a self, engine: &'a Engine<'_>) -> Vec<Shown<'a>> {
        match self {
            Asked::Read(call) => call.shown(),
            Asked::Unread(u) => engine.values(&u.args),
        }
    }
}

/// Whether a call's ending is remembered with the scope that made it (detection: finds
/// are raised in the activity that started it, docs/LANGUAGE.md, section 16).
pub(crate) fn remembers_scope(function: Function) -> bool {
    matches!(function, Function::StartDetection | Function::StopDetection)
}

impl<'m> Engine<'m> {
    pub(crate) async fn api(&self, a: &'m ApiCall, ctx: &Ctx<'m>) {
        let Some(drone) = self.api_drone(a, &ctx.frame) else { return };
        if let Some(root) = ctx.instance.as_ref().map(|i| i.root()) {
            // Paused or held; in the body, also while a leash section runs (`section.rs`).
            let in_section = ctx.scope.section.get();
            loop {
                let resumed = root.resumed.notified();
                if !root.holds(in_section) {
                    break;
                }
                resumed.await;
            }
        }
        // Made in a block of its own, so the call made is not kept twice while it runs.
        let rest = {
            let begun = self.api_begin(a, drone, &ctx.frame);
            self.api_end(begun, ctx)
        };
        rest.await;
    }

    /// The drone a call is made to, if its actor reference stands for one here.
    pub(crate) fn api_drone(&self, a: &ApiCall, frame: &[Value]) -> Option<DroneId> {
        self.env(frame, TiSlice::from_ref(&[])).actor(&a.actor)
    }

    /// Evaluates the arguments, records `api_call` and makes the call.
    pub(crate) fn api_begin(&self, a: &'m ApiCall, drone: DroneId, frame: &[Value]) -> Begun {
        let function = a.function;
        let asked = match &a.read {
            Some(call) => Asked::Read(call.clone()),
            None => {
                let args = {
                    let received = self.received.borrow();
                    let env = self.env(frame, &received);
                    a.args.iter().map(|e| env.eval(e)).collect::<Vec<_>>()
                };
                match FunctionCall::new(function, &args) {
                    Ok(call) => Asked::Read(call),
                    Err(reason) => Asked::Unread(Box::new(Unread { function, args, reason })),
                }
            }
        };
        self.calling(drone, a.origin);
        self.trace(EventKind::ApiCall, || Event::ApiCall {
            actor: self.name(drone).into(),
            function,
            args: asked.shown(self),
        });
        let pending = match &asked {
            Asked::Read(call) => {
                let pending = self.backend.call(drone, call);
                self.path_begun(drone, call);
                pending
            }
            // Refused as a backend refuses what it cannot do (`CommandFailed`), before
            // any backend sees it: no call id of the backend's.
            Asked::Unread(u) => {
                let reason = u.reason.clone();
                let failure = Failure::new(BuiltinException::CommandFailed, reason);
                aviary_api::PendingCall {
                    id: CallId(u64::MAX),
                    end: Ending::Now(CallEnd::Failed(failure)),
                }
            }
        };
        Begun { call: Made { drone, asked, id: pending.id }, end: pending.end }
    }

    /// The rest of a call's statement: waits for its ending, records `api_done`, and
    /// raises what a failure or an interruption means.
    pub(crate) async fn api_end(&self, begun: Begun, ctx: &Ctx<'m>) {
        let Begun { call, end } = begun;
        // While the call is in flight, its drone's own events are raised here, where the
        // call was made (`place.rs`); kept until what its ending raises has been raised.
        let mut _placed = None;
        let end = match end {
            // Over as it was made: nothing in flight to pause, resume or abort.
            Ending::Now(end) => end,
            Ending::Later(answer) => {
                let root = ctx.instance.as_ref().map(|i| i.root());
                let in_section = ctx.scope.section.get();
                let guard = CallGuard {
                    engine: self,
                    call: &call,
                    root,
                    in_section,
                    done: Cell::new(false),
                };
                if let Some(instance) = &ctx.instance {
                    _placed =
                        Some(self.place(&[call.drone], instance.depth, Level::Call, &ctx.scope));
                }
                if let Some(root) = root {
                    root.calls_of(in_section).borrow_mut().push(call.id);
                    if root.holds(in_section) {
                        self.backend.interrupt(call.id, Interrupt::Pause);
                    }
                }
                let end = answer.await.unwrap_or(CallEnd::Interrupted);
                guard.done.set(true);
                end
            }
        };
        let Made { drone, ref asked, .. } = call;
        self.trace_done(drone, asked.function(), || asked.shown(self), &end);
        match end {
            CallEnd::Done => {
                if let Asked::Read(call) = asked {
                    self.after_call(call, drone, ctx)
                }
            }
            CallEnd::Failed(f) => self.fail(f, drone, &ctx.scope),
            CallEnd::Interrupted => {
                // A fault interrupted it: raise that first, while this activity still runs.
                self.drain_events();
                ctx.scope.unwinding.set(true);
            }
        }
    }

    fn after_call(&self, call: &FunctionCall, drone: DroneId, ctx: &Ctx<'m>) {
        if let FunctionCall::StartDetection { kind } = call {
            self.detections.borrow_mut().insert((drone, kind.clone()), ctx.scope.clone());
        } else if let FunctionCall::StopDetection { kind } = call {
            self.detections.borrow_mut().remove(&(drone, kind.clone()));
        }
    }
}

/// Interrupts a call whose activity is dropped before the call ended, and says so in
/// the trace: every `api_call` has its `api_done`.
struct CallGuard<'e, 'm> {
    engine: &'e Engine<'m>,
    call: &'e Made,
    root: Option<&'e Rc<Instance>>,
    /// Made in a leash section: listed with the root's `section_calls`.
    in_section: bool,
    done: Cell<bool>,
}

impl Drop for CallGuard<'_, '_> {
    fn drop(&mut self) {
        let call = self.call;
        if !self.done.get() {
            self.engine.backend.interrupt(call.id, Interrupt::Abort);
            let engine = self.engine;
            // Ended early: any way but done.
            let function = call.asked.function();
            let left = engine.path_ended(call.drone, function, &CallEnd::Interrupted);
            engine.trace(EventKind::ApiDone, || Event::ApiDone {
                actor: engine.name(call.drone).into(),
                function,
                args: call.asked.shown(engine),
                status: CallStatus::Aborted,
                position: engine.backend.telemetry(call.drone).position,
                left,
            });
        }
        if let Some(root) = &self.root {
            root.calls_of(self.in_section).borrow_mut().retain(|c| *c != call.id);
        }
    }
}
