//! The running capability instances, indexed so that no event scans them all: by id
//! (start order, for iteration), by actor (drone events and exceptions go to one
//! drone's activities) and by (capability, tag) (leashes). With ten thousand drones in
//! the air, a per-event scan over every running activity would make each event cost
//! the fleet's size.

use std::collections::{BTreeMap, BTreeSet};
use std::rc::Rc;

use aviary_api::DroneId;

use crate::engine::{Instance, Scope};

pub(crate) type Entry<'m> = (Rc<Instance>, Rc<Scope<'m>>);

#[derive(Default)]
pub(crate) struct Registry<'m> {
    by_id: BTreeMap<u64, Entry<'m>>,
    by_actor: BTreeSet<(DroneId, u64)>,
    by_tag: BTreeSet<(usize, usize, u64)>,
}

impl<'m> Registry<'m> {
    pub fn insert(&mut self, instance: Rc<Instance>, scope: Rc<Scope<'m>>) {
        let id = instance.id;
        for d in &instance.actors {
            self.by_actor.insert((*d, id));
        }
        if let Some(tag) = instance.tag {
            self.by_tag.insert((instance.capability, tag, id));
        }
        self.by_id.insert(id, (instance, scope));
    }

    pub fn remove(&mut self, id: u64) {
        if let Some((instance, _)) = self.by_id.remove(&id) {
            for d in &instance.actors {
                self.by_actor.remove(&(*d, id));
            }
            if let Some(tag) = instance.tag {
                self.by_tag.remove(&(instance.capability, tag, id));
            }
        }
    }

    /// The scope an instance's events are raised in (once its own scope exists).
    pub fn set_scope(&mut self, id: u64, scope: Rc<Scope<'m>>) {
        if let Some(entry) = self.by_id.get_mut(&id) {
            entry.1 = scope;
        }
    }

    /// Every running instance, in the order they started.
    pub fn iter(&self) -> impl Iterator<Item = &Entry<'m>> {
        self.by_id.values()
    }

    /// The instances `drone` takes part in, in the order they started.
    pub fn of_actor(&self, drone: DroneId) -> impl Iterator<Item = &Entry<'m>> {
        self.by_actor.range((drone, 0)..=(drone, u64::MAX)).filter_map(|(_, id)| self.by_id.get(id))
    }

    /// The instances of `capability` tagged `tag`, in the order they started.
    pub fn tagged(&self, capability: usize, tag: usize) -> impl Iterator<Item = &Entry<'m>> {
        self.by_tag.range((capability, tag, 0)..=(capability, tag, u64::MAX)).filter_map(|(_, _, id)| self.by_id.get(id))
    }
}
