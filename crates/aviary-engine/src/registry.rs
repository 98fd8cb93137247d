//! The running capability instances, indexed so that no event scans them all: by actor
//! (drone events and exceptions go to one drone's activities) and by (capability, tag)
//! (leashes). With ten thousand drones in the air, a per-event scan over every running
//! activity would make each event cost the fleet's size. Each list is in the order the
//! instances started (ids grow), the order a single list of them all would have. An
//! instance of several actors is listed under each.
//!
//! By actor it is a slot per drone, with room for one activity inline: starting and
//! ending the activity of a drone allocates nothing and hashes nothing.

use std::collections::BTreeMap;
use std::rc::Rc;

use aviary_api::DroneId;
use aviary_ir::{CapId, TagId, TiVec};
use smallvec::SmallVec;

use crate::engine::{Instance, Scope};

pub(crate) type Entry<'m> = (Rc<Instance>, Rc<Scope<'m>>);

#[derive(Default)]
pub(crate) struct Registry<'m> {
    by_actor: TiVec<DroneId, SmallVec<[Entry<'m>; 1]>>,
    by_tag: BTreeMap<(CapId, TagId, u64), Entry<'m>>,
    /// Instances without an actor (all of whose actor references were empty), so that
    /// `all` still sees them.
    loose: BTreeMap<u64, Entry<'m>>,
}

impl<'m> Registry<'m> {
    pub fn insert(&mut self, instance: Rc<Instance>, scope: Rc<Scope<'m>>) {
        let id = instance.id;
        if let Some(tag) = instance.tag {
            self.by_tag.insert((instance.capability, tag, id), (instance.clone(), scope.clone()));
        }
        if instance.actors.is_empty() {
            self.loose.insert(id, (instance.clone(), scope.clone()));
        }
        for d in &instance.actors {
            if self.by_actor.len() <= d.0 {
                self.by_actor.resize_with(d.0 + 1, SmallVec::new);
            }
            // Ids grow, so a push keeps the list in starting order. A drone named twice
            // in one instance is listed once.
            let list = &mut self.by_actor[*d];
            if list.last().is_none_or(|(i, _)| i.id != id) {
                list.push((instance.clone(), scope.clone()));
            }
        }
    }

    pub fn remove(&mut self, instance: &Instance) {
        let id = instance.id;
        if instance.actors.is_empty() {
            self.loose.remove(&id);
        }
        for d in &instance.actors {
            if let Some(list) = self.by_actor.get_mut(*d) {
                // Nearly always the last one: the innermost activity ends first.
                if let Some(at) = list.iter().rposition(|(i, _)| i.id == id) {
                    list.remove(at);
                }
            }
        }
        if let Some(tag) = instance.tag {
            self.by_tag.remove(&(instance.capability, tag, id));
        }
    }

    /// The scope an instance's events are raised in (once its own scope exists).
    pub fn set_scope(&mut self, instance: &Instance, scope: Rc<Scope<'m>>) {
        let id = instance.id;
        if let Some(entry) = self.loose.get_mut(&id) {
            entry.1 = scope.clone();
        }
        for d in &instance.actors {
            if let Some(entry) =
                self.by_actor.get_mut(*d).and_then(|l| l.iter_mut().rfind(|(i, _)| i.id == id))
            {
                entry.1 = scope.clone();
            }
        }
        if let Some(tag) = instance.tag {
            if let Some(entry) = self.by_tag.get_mut(&(instance.capability, tag, id)) {
                entry.1 = scope;
            }
        }
    }

    /// Every running instance once, in the order they started (for the operator's pause
    /// and resume of the whole mission, not for events).
    pub fn all(&self) -> Vec<Entry<'m>> {
        let mut all: Vec<&Entry<'m>> =
            self.by_actor.iter().flatten().chain(self.loose.values()).collect();
        all.sort_by_key(|(i, _)| i.id);
        all.dedup_by_key(|(i, _)| i.id);
        all.into_iter().cloned().collect()
    }

    /// The instances `drone` takes part in, in the order they started.
    pub fn of_actor(&self, drone: DroneId) -> impl Iterator<Item = &Entry<'m>> {
        self.by_actor.get(drone).into_iter().flatten()
    }

    /// Each (capability, tag) that a running instance has, once, in that order.
    pub fn tags(&self) -> Vec<(CapId, TagId)> {
        let mut tags: Vec<(CapId, TagId)> = self.by_tag.keys().map(|&(c, t, _)| (c, t)).collect();
        tags.dedup();
        tags
    }

    /// The instances of `capability` tagged `tag`, in the order they started.
    pub fn tagged(&self, capability: CapId, tag: TagId) -> impl Iterator<Item = &Entry<'m>> {
        self.by_tag.range((capability, tag, 0)..=(capability, tag, u64::MAX)).map(|(_, e)| e)
    }
}
