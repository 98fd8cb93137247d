//! The operator steers one drone (issue 16): holds it, lets it go on, or takes it out of
//! the mission, home or down where it is (`Control::Drone`).
//!
//! - **Hold** pauses every activity the drone takes part in, as a `PAUSE` leash pauses one:
//!   the activity as the mission's statement started it (its root), so an activity of
//!   several drones is held whole, and so is one whose inner capability works the drone.
//!   Its calls in flight are paused and its next calls wait; an activity that starts
//!   while the drone is held starts held. A hold and a pause (of the whole mission, or a
//!   leash) are apart: an activity goes on only when neither holds it.
//! - **Return home** and **land** abort every activity the drone takes part in, as an
//!   `ABORT` leash aborts one (its statement ends `aborted` and its block goes on), but
//!   without the capability's `PERFORM ABORT:` section: that is the mission's idea of
//!   what the drone does next, and the drone is the operator's now. It is then brought
//!   down as at the mission's end (`homing.rs`), home or where it is, beside the rest of
//!   the mission, and is out of the mission for the rest of the run: an activity that
//!   names it ends `aborted` at once, without flying; its faults are recorded as
//!   exceptions on the way down (`during`: `return home`) that no handler takes and that
//!   do not fail the mission; its signals and finds are recorded and not raised. A drone
//!   on its way home can still be landed where it is; nothing else is taken from it.
//!
//! Every action is written to the trace as an `operator` event, before what it does.

use std::cell::RefCell;
use std::rc::Rc;
use std::task::Waker;

use aviary_api::{CallId, DroneId, Interrupt};
use aviary_ir::TiVec;

use crate::control::DroneAction;
use crate::engine::{Engine, Instance};

/// How a drone taken out of the mission comes down.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Down {
    Home,
    Land,
}

/// What the operator did to one drone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
enum Steer {
    #[default]
    Free,
    Held,
    Withdrawn(Down),
}

/// The operator's steering of single drones.
#[derive(Default)]
pub(crate) struct Steering {
    /// By drone; empty until the operator steers one, so a run without that looks at
    /// an empty list.
    drones: RefCell<TiVec<DroneId, Steer>>,
    /// Drones taken out of the mission, to bring down, with the root activities aborted
    /// for them (`Engine::withdrawals` takes them).
    pub queued: RefCell<Vec<(DroneId, Vec<Rc<Instance>>)>>,
    /// Wakes `Engine::withdrawals` when a drone is queued.
    pub waker: RefCell<Option<Waker>>,
    /// The call bringing a drone taken out down, while it is in flight (so that a land
    /// can cut a return home).
    pub calls: RefCell<Vec<(DroneId, CallId)>>,
    /// Drones whose return home a land cut: their call ends `Interrupted` by the
    /// operator, not by a fault.
    pub cut: RefCell<Vec<DroneId>>,
    /// Drones taken out that did not come down safely, and why.
    pub stranded: RefCell<Vec<(DroneId, String)>>,
}

impl Steering {
    fn get(&self, d: DroneId) -> Steer {
        self.drones.borrow().get(d).copied().unwrap_or_default()
    }

    fn set(&self, d: DroneId, steer: Steer) {
        let mut drones = self.drones.borrow_mut();
        if drones.len() <= d.0 {
            drones.resize(d.0 + 1, Steer::Free);
        }
        drones[d] = steer;
    }

    /// Whether the operator holds `d`.
    pub fn held(&self, d: DroneId) -> bool {
        self.get(d) == Steer::Held
    }

    /// How `d` comes down, if the operator took it out of the mission.
    pub fn withdrawn(&self, d: DroneId) -> Option<Down> {
        match self.get(d) {
            Steer::Withdrawn(down) => Some(down),
            _ => None,
        }
    }

    /// Whether a land cut `d`'s return home (once).
    pub fn take_cut(&self, d: DroneId) -> bool {
        let mut cut = self.cut.borrow_mut();
        let before = cut.len();
        cut.retain(|x| *x != d);
        cut.len() != before
    }

    pub fn any_withdrawn(&self) -> bool {
        self.drones.borrow().iter().any(|s| matches!(s, Steer::Withdrawn(_)))
    }

    /// The drones the operator holds.
    fn held_drones(&self) -> Vec<DroneId> {
        let drones = self.drones.borrow();
        (0..drones.len()).map(DroneId).filter(|d| drones[*d] == Steer::Held).collect()
    }
}

impl<'m> Engine<'m> {
    /// Applies `action` to drone `d`, or says why not and what to do.
    pub(crate) fn steer(&self, d: DroneId, action: DroneAction) -> Result<(), String> {
        // An id from a directory of this mission is always in its fleet.
        let name = self.m.drones.get(d).ok_or("no such drone")?;
        let now = self.steering.get(d);
        match (action, now) {
            (DroneAction::Hold, Steer::Free) => {
                self.operator(action.traced(), Some(d));
                self.steering.set(d, Steer::Held);
                let roots: Vec<Rc<Instance>> =
                    self.instances.borrow().of_actor(d).map(|(i, _)| i.root().clone()).collect();
                for root in roots {
                    self.hold_root(&root);
                }
                Ok(())
            }
            (DroneAction::Hold, Steer::Held) => Err(format!(
                "{name} is already held: resume it to let its activities go on"
            )),
            (DroneAction::Resume, Steer::Held) => {
                self.operator(action.traced(), Some(d));
                self.steering.set(d, Steer::Free);
                self.release_roots();
                Ok(())
            }
            (DroneAction::Resume, Steer::Free) => {
                let mut why = format!("{name} is not held: there is nothing of it to resume");
                if self.mission_paused.get() {
                    why.push_str("; the whole mission is paused: resume the mission instead");
                }
                Err(why)
            }
            (DroneAction::ReturnHome | DroneAction::Land, Steer::Free | Steer::Held) => {
                let down = if action == DroneAction::Land { Down::Land } else { Down::Home };
                self.operator(action.traced(), Some(d));
                self.steering.set(d, Steer::Withdrawn(down));
                self.take_out(d);
                // What it held besides its own activities (now aborted) goes on.
                if now == Steer::Held {
                    self.release_roots();
                }
                Ok(())
            }
            (DroneAction::Land, Steer::Withdrawn(Down::Home)) => {
                self.operator(action.traced(), Some(d));
                self.steering.set(d, Steer::Withdrawn(Down::Land));
                // Its return home is cut where it is; `bring_down` then lands it (between
                // two calls, it lands at the next).
                let calls = self.steering.calls.borrow().clone();
                for (_, call) in calls.iter().filter(|(x, _)| *x == d) {
                    self.steering.cut.borrow_mut().push(d);
                    self.backend.interrupt(*call, Interrupt::Abort);
                }
                Ok(())
            }
            (_, Steer::Withdrawn(Down::Home)) => Err(format!(
                "{name} is on its way home, out of the mission (the operator sent it): it takes no more orders but land"
            )),
            (_, Steer::Withdrawn(Down::Land)) => Err(format!(
                "{name} is landing or has landed, out of the mission (the operator landed it): it takes no more orders"
            )),
        }
    }

    /// Holds a root activity for a drone the operator holds: its calls in flight are
    /// paused (unless they already are) and its next ones wait.
    pub(crate) fn hold_root(&self, root: &Rc<Instance>) {
        let before = root.holding();
        root.held.set(true);
        self.rehold(root, before);
    }

    /// After a drone is no longer held: every held root activity that no held drone
    /// takes part in any more goes on (unless a pause still holds it).
    fn release_roots(&self) {
        let held = self.steering.held_drones();
        let roots: Vec<Rc<Instance>> = self
            .instances
            .borrow()
            .all()
            .into_iter()
            .map(|(i, _)| i.root().clone())
            .filter(|r| r.held.get())
            .collect();
        for root in roots {
            let still = {
                let instances = self.instances.borrow();
                held.iter()
                    .any(|d| instances.of_actor(*d).any(|(i, _)| Rc::ptr_eq(i.root(), &root)))
            };
            if still || !root.held.get() {
                continue;
            }
            let before = root.holding();
            root.held.set(false);
            self.rehold(&root, before);
        }
    }

    /// Takes `d` out of the mission: aborts every root activity it takes part in (its
    /// calls in flight cut now, so that the drone is free for the way down) and queues
    /// it to be brought down. Its finds no longer reach the mission.
    fn take_out(&self, d: DroneId) {
        let mut roots: Vec<Rc<Instance>> = Vec::new();
        for (instance, _) in self.instances.borrow().of_actor(d) {
            let root = instance.root();
            if !roots.iter().any(|r| Rc::ptr_eq(r, root)) {
                roots.push(root.clone());
            }
        }
        for root in &roots {
            root.token.cancel();
            let calls = root.calls.borrow();
            let sections = root.section_calls.borrow();
            for call in calls.iter().chain(sections.iter()) {
                self.backend.interrupt(*call, Interrupt::Abort);
            }
        }
        self.detections.borrow_mut().retain(|(drone, _), _| *drone != d);
        self.steering.queued.borrow_mut().push((d, roots));
        if let Some(waker) = self.steering.waker.take() {
            waker.wake();
        }
    }

    /// Whether an activity of these drones may start: not when the operator took one of
    /// them out of the mission.
    pub(crate) fn any_withdrawn(&self, actors: &[DroneId]) -> bool {
        actors.iter().any(|d| self.steering.withdrawn(*d).is_some())
    }
}
