//! Leash sections hold the activity's body, and what holds an activity at all.
//!
//! A leash section (`Patrol-P1 Widen`, `PERFORM Widen:`) runs on a running activity,
//! beside its body. While one runs, the body is **held as `PAUSE` holds it**: its calls
//! in flight are paused (the drone stops where it is) and its next calls wait; the
//! section's own calls are not held, so a section may fly the drone (the simulator sets
//! the paused motion aside for the section's and brings it back after). When the last
//! section has ended the body goes on from where it was. Sections of one activity run one
//! at a time, in the order they were asked; the body stays held from the first one's
//! start to the last one's end (docs/LANGUAGE.md, section 14).
//!
//! A `PAUSE` (a leash, the operator's pause of the mission, a drone held) holds the
//! sections too, and the body with them; a `RESUME` lets a section go on, and the body
//! once no section is left. An `ABORT` stops the activity whole, sections included.
//!
//! Every hold is one of the root activity's flags (`paused`, `held`, `sections`); calls
//! are told to pause or resume only where one of them changes what holds them
//! ([`Engine::rehold`]), so no two holds can undo each other.

use std::rc::Rc;

use aviary_api::Interrupt;
use aviary_ir::Block;

use crate::engine::{Ctx, Engine, Holds, Instance};

/// Holds a root activity's body while a section is asked of it; lets it go when dropped
/// (the section ended, or was dropped with its activity).
pub(crate) struct BodyHeld<'e, 'm> {
    engine: &'e Engine<'m>,
    root: Rc<Instance>,
}

impl Drop for BodyHeld<'_, '_> {
    fn drop(&mut self) {
        let before = self.root.holding();
        self.root.sections.set(self.root.sections.get().saturating_sub(1));
        self.engine.rehold(&self.root, before);
    }
}

impl<'m> Engine<'m> {
    /// After a change to what holds `instance` (its flags, from `before`): pauses the calls
    /// a hold now takes, resumes those it let go, and wakes the calls waiting to be made.
    pub(crate) fn rehold(&self, instance: &Instance, before: Holds) {
        let now = instance.holding();
        let mut released = false;
        for (was, is, in_section) in
            [(before.body, now.body, false), (before.sections, now.sections, true)]
        {
            if was == is {
                continue;
            }
            let how = if is { Interrupt::Pause } else { Interrupt::Resume };
            for call in instance.calls_of(in_section).borrow().iter() {
                self.backend.interrupt(*call, how);
            }
            released |= !is;
        }
        if released {
            instance.resumed.notify_waiters();
        }
    }

    /// A leash section on the activity whose scope `ctx` is in: the body held from now
    /// until it ends, then its turn, then its block, in a scope marked as a section's.
    pub(crate) async fn section(&self, block: &'m Block, ctx: &Ctx<'m>) {
        let root = ctx.instance.as_ref().map(|i| i.root().clone());
        let _held = root.as_ref().map(|root| {
            let before = root.holding();
            root.sections.set(root.sections.get() + 1);
            self.rehold(root, before);
            BodyHeld { engine: self, root: root.clone() }
        });
        // The semaphore is never closed: `acquire` fails only then.
        let _turn = match &root {
            Some(root) => root.turn.acquire().await.ok(),
            None => None,
        };
        Box::pin(self.block_with(block, ctx, |scope| scope.section.set(true))).await;
    }
}
