//! What the CLI runs on a second core. The library crates stay single-threaded and
//! leave that choice to their caller:
//! - [`join`]: the world file read in two parts ([`aviary_world::parse_world_joined`]);
//! - [`beside`]: the simulator's fleet, built while the main thread checks and compiles
//!   the mission ([`aviary_sim::Fleet::new`] is pure and needs only the world).
//!
//! On a machine with two cores each saves about the shorter of the two pieces of work.

use std::time::{Duration, Instant};

use aviary_sim::Fleet;
use aviary_world::World;

/// Runs `a` on this thread and `b` on another, and returns once both have run (`b` on
/// this thread too, when no thread can be started). A panic in either goes on here.
pub fn join(a: &mut (dyn FnMut() + Send), b: &mut (dyn FnMut() + Send)) {
    let beside = std::thread::scope(|s| {
        let other = std::thread::Builder::new().name("world".into()).spawn_scoped(s, &mut *b);
        a();
        other.map(|handle| handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic))).is_ok()
    });
    if !beside {
        b();
    }
}

/// Runs `work` on this thread while the fleet of `world` is built on another; returns
/// what `work` gave, the fleet, and how long this thread then waited for the fleet.
/// The fleet is the one [`Fleet::new`] builds on this thread (it is built there when no
/// thread can be started). Whatever `work` gave, the fleet is built: a caller that does
/// not fly (a mission with errors) just drops it. A panic in the fleet's thread goes on
/// in this one.
pub fn beside<R>(world: &World, work: impl FnOnce() -> R) -> (R, Fleet, Duration) {
    std::thread::scope(|s| {
        let builder = std::thread::Builder::new().name("fleet".into()).spawn_scoped(s, || Fleet::new(world));
        let r = work();
        let waiting = Instant::now();
        let fleet = match builder {
            Ok(handle) => handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)),
            Err(_) => Fleet::new(world),
        };
        (r, fleet, waiting.elapsed())
    })
}

#[cfg(test)]
mod tests {
    use aviary_diagnostics::SourceMap;
    use aviary_engine::RunOptions;
    use aviary_sim::{SimBackend, SimOptions};

    use super::*;
    use crate::bench::NoFiles;

    /// The trace of W(n, 2) flown on `start`'s backend.
    fn trace(n: usize, start: impl FnOnce(&World) -> std::sync::Arc<SimBackend>) -> Vec<serde_json::Value> {
        let mut sources = SourceMap::new();
        let wid = sources.add("w.world.toml", aviary_check::generate::w_world(n));
        let world = aviary_world::parse_world(wid, sources.text(wid)).0.expect("W's world reads");
        let root = sources.add("w.mission", aviary_check::generate::w_mission(2));
        let api = aviary_sim::descriptor();
        let (program, _) = aviary_check::check(&mut sources, root, Some(&world), &NoFiles, &api);
        let mission = aviary_ir::compile(&program, &world, &api).expect("W has a MISSION");
        let runtime = tokio::runtime::Builder::new_current_thread().enable_time().start_paused(true).build().expect("a runtime");
        let mut events = Vec::new();
        runtime.block_on(async {
            let sim = start(&world);
            let mut sink = |e: serde_json::Value| events.push(e);
            aviary_engine::run(&mission, &*sim, &mut sink, &RunOptions::default()).await;
            sim.stop();
        });
        events
    }

    #[test]
    fn a_fleet_built_beside_flies_as_one_built_in_place() {
        let before = trace(30, |w| SimBackend::start(w, SimOptions::default()));
        let after = trace(30, |w| {
            let (answer, fleet, _) = beside(w, || 42);
            assert_eq!(answer, 42);
            SimBackend::start_with(fleet, SimOptions::default())
        });
        assert!(before.len() > 30 * 2);
        assert_eq!(before, after);
    }

    #[test]
    fn a_world_read_in_two_parts_on_two_threads_is_the_world_read_whole() {
        let text = aviary_check::generate::w_world(5000);
        let two = aviary_world::parse_world_joined(Default::default(), &text, &join);
        assert_eq!(two, aviary_world::parse_world(Default::default(), &text));
        assert_eq!(two.0.map(|w| w.drones.len()), Some(5000));
    }

    #[test]
    #[should_panic(expected = "from the work")]
    fn a_panic_in_the_work_still_ends_the_fleet_thread() {
        let world = aviary_world::parse_world(Default::default(), &aviary_check::generate::w_world(3)).0.expect("W's world reads");
        beside(&world, || panic!("from the work"));
    }
}
