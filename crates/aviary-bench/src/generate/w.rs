//! The engine benchmark W(N, K) of docs/BENCHMARKS.md, written in the
//! language: N actors start in parallel; each runs K instant steps, each step a
//! capability instance of its own that the actor waits for; each actor then raises
//! `Done` carrying its index, and one mission-level `ON EVERY Done` handler takes every
//! one. A step's PERFORM is one middle-layer call that ends at once (`Arm` on a landed
//! drone), so the benchmark measures the language and its runtime, not the physics.

use std::fmt::Write;

/// The group every drone of the W world belongs to.
pub const GROUP: &str = "fleet";

/// The mission W(·, K): it does not depend on N (the world says how many actors).
pub fn w_mission(k: usize) -> String {
    let mut m = String::with_capacity(512 + 16 * k);
    let _ = writeln!(m, "// W(N, {k}): the engine benchmark, N = the drones of group `{GROUP}`.");
    m.push_str(
        "// One step: a capability whose PERFORM is one middle-layer call that ends at once.\n\
         CAPABILITY Step BY d:\n\
         \x20   PERFORM:\n\
         \x20       d.Arm()\n\n\
         MISSION W:\n\
         \x20   // The one handler that takes every Done; `i` is the actor's index.\n\
         \x20   ON EVERY Done WITH i:\n\
         \x20       WAITFOR i >= 0\n",
    );
    let _ = writeln!(m, "    PARALLEL FOR {GROUP} AS d:");
    for _ in 0..k {
        m.push_str("        d Step\n");
    }
    m.push_str("        SIGNAL Done WITH d.index\n");
    m
}

/// The world of W(N, ·): one fleet of N drones `a0` to `a{N-1}` in one group, on a
/// square grid 5 m apart, each with its number (0 to N - 1) as its `index` attribute.
/// A few lines whatever N: the world file describes the fleet, not each drone.
pub fn w_world(n: usize) -> String {
    let side = (n as f64).sqrt().ceil().max(1.0) as usize;
    format!(
        "[site]\nname = \"W\"\norigin = {{ lat = 46.6, lon = 14.2, alt = 440.0 }}\n\n\
         [fleets.a]\ncount = {n}\nnames = \"a{{i}}\"\ngroup = \"{GROUP}\"\n\
         homes = {{ grid = [0, 0], spacing = 5, columns = {side} }}\n"
    )
}

#[cfg(test)]
mod tests {
    use aviary_diagnostics::FileId;

    use super::*;

    /// W's world as a table per drone: what the fleet stands for, drone for drone.
    fn as_tables(n: usize) -> String {
        let mut w = String::from(
            "[site]\nname = \"W\"\norigin = { lat = 46.6, lon = 14.2, alt = 440.0 }\n",
        );
        let side = (n as f64).sqrt().ceil().max(1.0) as usize;
        for i in 0..n {
            let _ = write!(
                w,
                "\n[drones.a{i}]\nhome = [{}, {}]\ngroup = \"{GROUP}\"\nindex = {i}\n",
                (i % side) * 5,
                (i / side) * 5
            );
        }
        w
    }

    #[test]
    fn the_fleet_is_the_drones_of_a_table_each() {
        for n in [1, 2, 40, 1000, 1001] {
            let read = |text: &str| {
                let (world, diags) = aviary_world::parse_world(FileId(0), text);
                assert!(diags.is_empty(), "{diags:#?}");
                let mut world = world.unwrap();
                world.drones.iter_mut().for_each(|d| d.span = Default::default());
                world.groups.iter_mut().for_each(|g| g.spans.clear());
                world
            };
            assert_eq!(read(&w_world(n)), read(&as_tables(n)), "{n} drones");
        }
    }
}
