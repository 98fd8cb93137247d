//! Where a drone's own events are raised: its built-in signals other than `Detected`
//! (`BatteryLow`, `ConnectionRestored`) and its faults (docs/LANGUAGE.md, sections 16
//! and 17). One rule: **where the drone's work is at that moment**, the innermost of
//!
//! - its middle-layer call in progress (the scope of the statement that made it, as a
//!   `THROW` written there would be), a call of a deeper activity before one of a
//!   shallower, the latest made first among equals;
//! - the PERFORM body of its innermost running activity (for the moments between two
//!   calls, or while the body waits);
//! - its innermost running activity itself (the registry's scope: the caller's while the
//!   activity waits for its claims);
//!
//! or, when it runs nothing, the mission's own body. So a handler hears a drone's signal
//! exactly when the drone's work is inside the handler's block, as for a `SIGNAL` or a
//! `THROW` of that work; `Detected` is raised where `StartDetection` was called
//! (`api.rs`), which is the same place for a detection switched on by the work itself.
//!
//! The activity's own scope is not enough: it lies above its PERFORM body's handlers, so
//! an `ON BatteryLow BY drone:` written in a PERFORM would hear nothing while that
//! PERFORM flies a middle-layer call.
//!
//! The places are kept per drone, a few each (an activity's body, and a call or two in
//! flight), added and removed by guards: no event scans anything but its own drone's.

use std::cell::RefCell;
use std::rc::Rc;

use aviary_api::DroneId;
use aviary_ir::TiVec;
use smallvec::SmallVec;

use crate::engine::{Engine, Scope};

/// How deep a place is inside its activity: a call is inside the body it runs in, and
/// a body inside the activity. The order is that of the rule above.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Level {
    Activity,
    Body,
    Call,
}

/// Which place is innermost: the activity's depth, then the level, then the latest.
pub(crate) type Rank = (usize, Level, u64);

struct Place<'m> {
    rank: Rank,
    scope: Rc<Scope<'m>>,
}

#[derive(Default)]
pub(crate) struct Places<'m> {
    by_drone: RefCell<TiVec<DroneId, SmallVec<[Place<'m>; 2]>>>,
    next: std::cell::Cell<u64>,
}

impl<'m> Places<'m> {
    /// The innermost place of `drone`, if it has one, with its rank.
    pub fn innermost(&self, drone: DroneId) -> Option<(Rank, Rc<Scope<'m>>)> {
        let places = self.by_drone.borrow();
        let place = places.get(drone)?.iter().max_by_key(|p| p.rank)?;
        Some((place.rank, place.scope.clone()))
    }
}

/// Forgets its places when dropped: the call ended, the body ended or was dropped.
pub(crate) struct Placed<'e, 'm> {
    places: &'e Places<'m>,
    drones: SmallVec<[DroneId; 2]>,
    seq: u64,
}

impl Drop for Placed<'_, '_> {
    fn drop(&mut self) {
        let mut places = self.places.by_drone.borrow_mut();
        for d in &self.drones {
            if let Some(list) = places.get_mut(*d) {
                list.retain(|p| p.rank.2 != self.seq);
            }
        }
    }
}

impl<'m> Engine<'m> {
    /// Keeps `scope` as a place of `drones`, at `depth` and `level`, while the guard lives.
    pub(crate) fn place<'e>(
        &'e self,
        drones: &[DroneId],
        depth: usize,
        level: Level,
        scope: &Rc<Scope<'m>>,
    ) -> Placed<'e, 'm> {
        let seq = self.places.next.get() + 1;
        self.places.next.set(seq);
        let mut places = self.places.by_drone.borrow_mut();
        for d in drones {
            if places.len() <= d.0 {
                places.resize_with(d.0 + 1, SmallVec::new);
            }
            places[*d].push(Place { rank: (depth, level, seq), scope: scope.clone() });
        }
        Placed { places: &self.places, drones: drones.iter().copied().collect(), seq }
    }

    /// Where `drone`'s own events are raised: where its work is (the module's rule), or
    /// the mission's own body when it runs nothing.
    pub(crate) fn actor_scope(&self, drone: DroneId) -> Rc<Scope<'m>> {
        let activity = {
            let instances = self.instances.borrow();
            instances
                .of_actor(drone)
                .max_by_key(|(i, _)| (i.depth, i.id))
                .map(|(i, scope)| ((i.depth, Level::Activity, i.id), scope.clone()))
        };
        let place = self.places.innermost(drone);
        let innermost = match (activity, place) {
            (Some(a), Some(p)) => Some(if p.0 > a.0 { p } else { a }),
            (a, p) => a.or(p),
        };
        match innermost {
            Some((_, scope)) => scope,
            None => self.mission_scope.borrow().clone().unwrap_or_else(|| self.root_scope()),
        }
    }
}
