//! What each drone's last `Sweep` or `FollowPath` left (`drone.remaining`,
//! docs/LANGUAGE.md, section 18): nothing once one finishes; when one ends early, what it
//! had not flown, from where the backend says it stopped (`Backend::stopped`), computed
//! by the contract (`aviary_api::coverage::left`).
//!
//! It is noted as soon as the engine learns that such a call ended early, whichever way
//! it learns it first: a drone's fault (before the exception is raised, so a handler that
//! reads it at once sees it), the call's own end (`Failed`, `Interrupted`), or its
//! activity stopped (an abort: `CallGuard`). A drone has one motion call at a time, so
//! the path call in progress is the drone's.

use std::cell::RefCell;
use std::sync::Arc;

use aviary_api::{CallEnd, DroneId, Function, FunctionCall, Remainder, Value};
use aviary_ir::TiVec;

use crate::engine::Engine;

/// A `Sweep` or `FollowPath` in progress, with its arguments: boxed, so that a drone
/// without one (most of a large fleet) keeps a pointer's width, not a call's.
type PathCall = Box<FunctionCall>;

pub(crate) struct Coverage {
    /// Per drone: its path call in progress.
    flying: RefCell<TiVec<DroneId, Option<PathCall>>>,
    /// Per drone: what its last one left; `None` for nothing.
    left: RefCell<TiVec<DroneId, Option<Arc<Remainder>>>>,
    nothing: Arc<Remainder>,
}

/// Whether `function` flies a path whose remainder is kept.
pub(crate) fn flies_path(function: Function) -> bool {
    matches!(function, Function::Sweep | Function::FollowPath)
}

impl Coverage {
    pub fn new(drones: usize) -> Coverage {
        Coverage {
            flying: RefCell::new(vec![None; drones].into()),
            left: RefCell::new(vec![None; drones].into()),
            nothing: Arc::new(Remainder::Nothing),
        }
    }

    /// `drone.remaining`.
    pub fn remaining(&self, drone: DroneId) -> Value {
        let left = self.left.borrow().get(drone).cloned().flatten();
        Value::Remainder(left.unwrap_or_else(|| self.nothing.clone()))
    }

    fn set_left(&self, drone: DroneId, left: Remainder) {
        if let Some(slot) = self.left.borrow_mut().get_mut(drone) {
            *slot = (!left.is_empty()).then(|| Arc::new(left));
        }
    }

    fn length_left(&self, drone: DroneId) -> f64 {
        self.left.borrow().get(drone).cloned().flatten().map_or(0.0, |l| l.length())
    }
}

impl Engine<'_> {
    /// A call was made: a path call is remembered until it ends.
    pub(crate) fn path_begun(&self, drone: DroneId, call: &FunctionCall) {
        if flies_path(call.function()) {
            if let Some(slot) = self.coverage.flying.borrow_mut().get_mut(drone) {
                *slot = Some(Box::new(call.clone()));
            }
        }
    }

    /// The drone's path call in progress, if it has one, ended early: what it left.
    pub(crate) fn path_stopped(&self, drone: DroneId) {
        let flying = self.coverage.flying.borrow_mut().get_mut(drone).and_then(Option::take);
        let Some(call) = flying else { return };
        let left = aviary_api::coverage::left(&call, self.backend.stopped(drone));
        self.coverage.set_left(drone, left.unwrap_or_default());
    }

    /// A call of `function` on `drone` ended: for a path call, what it left (nothing when
    /// done). Returns, for one that ended early, the metres it left (the trace's `left`).
    pub(crate) fn path_ended(
        &self,
        drone: DroneId,
        function: Function,
        end: &CallEnd,
    ) -> Option<f64> {
        if !flies_path(function) {
            return None;
        }
        if *end == CallEnd::Done {
            if let Some(slot) = self.coverage.flying.borrow_mut().get_mut(drone) {
                *slot = None;
            }
            self.coverage.set_left(drone, Remainder::Nothing);
            return None;
        }
        self.path_stopped(drone);
        Some(self.coverage.length_left(drone))
    }
}
