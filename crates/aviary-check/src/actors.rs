//! The drones each actor name of the world stands for: a drone's name, that drone; a
//! group's, its members. One table for the walks that follow which drones do a piece of
//! work (the no-fly zones' in `no_fly.rs`, `endurance.rs`, `unheard.rs`), made once per
//! check where each walk used to make or scan its own: a world may have millions of
//! drones, which no walk looks through name by name. Made on first use, since a mission
//! that names no drone (or a world without zones) needs none.
//!
//! A name means one thing in a world the reader accepted (drones, groups, places, areas
//! and lines share one set of names), so a drone and a group never compete for a name.

use std::cell::OnceCell;

use aviary_world::World;

/// What an actor's name stands for: by index into the world's drones.
#[derive(Clone, Copy)]
enum Named<'w> {
    Drone(usize),
    Group(&'w [usize]),
}

/// The world's actor names, for the walks of one check (on one thread: the table is made
/// by whichever walk asks first).
pub(crate) struct Actors<'w> {
    world: &'w World,
    table: OnceCell<foldhash::HashMap<&'w str, Named<'w>>>,
}

impl<'w> Actors<'w> {
    pub(crate) fn new(world: &'w World) -> Actors<'w> {
        Actors { world, table: OnceCell::new() }
    }

    /// The drones (indices into the world's) that a drone's or a group's name stands for;
    /// `None` for any other name.
    pub(crate) fn drones(&self, name: &str) -> Option<&[usize]> {
        let table = self.table.get_or_init(|| {
            let w = self.world;
            let drones =
                w.drones.iter().enumerate().map(|(i, d)| (d.name.as_str(), Named::Drone(i)));
            let groups = w.groups.iter().map(|g| (g.name.as_str(), Named::Group(&g.members)));
            drones.chain(groups).collect()
        });
        Some(match table.get(name)? {
            Named::Drone(i) => std::slice::from_ref(i),
            Named::Group(members) => members,
        })
    }
}
