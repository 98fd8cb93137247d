//! `aviary replay TRACE [--world W]`: the ground station on a recorded trace, played back
//! on the page (play, pause, speed, a scrubber over the mission's time), with the world's
//! map when the world is given.

use std::io::Write;
use std::path::Path;

use aviary_station::Mode;

use crate::serve::Serve;

pub fn run(trace: &Path, world: Option<&Path>, serve: &Serve) -> u8 {
    let (name, bytes, world) = match crate::files::recorded_trace_and_world(trace, world) {
        Ok(read) => read,
        Err(shown) => {
            eprint!("{shown}");
            return 2;
        }
    };
    let text = match aviary_station::replay::read(&name, bytes) {
        Ok(t) => t,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    let map = world.as_ref().map(aviary_station::checking::map_of).unwrap_or_default();
    match crate::serve::station(serve, Mode::Replay { name: name.clone(), trace: text }, map, None)
    {
        Ok(_serving) => {
            // Not `eprintln!`: a script that closed standard error must not stop the replay.
            let _ = writeln!(std::io::stderr(), "aviary: replaying {name}; Ctrl-C stops");
            loop {
                std::thread::park();
            }
        }
        Err(why) => {
            eprintln!("aviary: {why}");
            2
        }
    }
}
