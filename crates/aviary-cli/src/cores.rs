//! What the CLI runs on a second core: the world file read in two parts
//! ([`aviary_world::parse_world_joined`]). The library crates stay single-threaded and
//! leave that choice to their caller. On a machine with two cores it saves about the
//! shorter of the two parts.
//!
//! The simulator's fleet was also built on a second thread while the mission was checked
//! and compiled (15 ms at 100,000 drones); it is now built after, from the world it
//! takes ([`aviary_sim::Fleet::from_world`]), so that the world and the fleet are never
//! held whole at once: 17 MB less at that size, for those 15 ms.

/// Runs `a` on this thread and `b` on another, and returns once both have run (`b` on
/// this thread too, when no thread can be started). A panic in either goes on here.
pub fn join(a: &mut (dyn FnMut() + Send), b: &mut (dyn FnMut() + Send)) {
    let beside = std::thread::scope(|s| {
        let other = std::thread::Builder::new().name("world".into()).spawn_scoped(s, &mut *b);
        a();
        other
            .map(|handle| handle.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
            .is_ok()
    });
    if !beside {
        b();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_world_read_in_two_parts_on_two_threads_is_the_world_read_whole() {
        let text = aviary_check::generate::w_world(5000);
        let two = aviary_world::parse_world_joined(Default::default(), &text, &join);
        assert_eq!(two, aviary_world::parse_world(Default::default(), &text));
        assert_eq!(two.0.map(|w| w.drones.len()), Some(5000));
    }
}
