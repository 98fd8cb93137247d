//! `aviary replay TRACE [--world W]`: the ground station on a recorded trace, played back
//! on the page (play, pause, speed, a scrubber over the mission's time), with the world's
//! map when the world is given.

use std::path::Path;

use aviary_diagnostics::{render_text, SourceMap};
use aviary_station::Mode;

use crate::files::color_wanted;
use crate::serve::Serve;

pub fn run(trace: &Path, world: Option<&Path>, serve: &Serve) -> u8 {
    let name = trace.display().to_string();
    let bytes = match std::fs::read(trace) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("aviary: cannot read {name}: {e}");
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
    let map = match world {
        None => serde_json::Value::Null,
        Some(path) => {
            let bytes = match std::fs::read(path) {
                Ok(b) => b,
                Err(e) => {
                    eprintln!("aviary: cannot read the world file {}: {e}", path.display());
                    return 2;
                }
            };
            let mut sources = SourceMap::new();
            let read = aviary_check::read_world(
                &mut sources,
                &path.display().to_string(),
                std::borrow::Cow::Owned(bytes),
            );
            match read.world {
                Some(w) => aviary_station::checking::map_of(&w),
                None => {
                    for d in read.diagnostics.iter().filter(|d| d.is_error()) {
                        eprint!("{}", render_text(&sources, d, color_wanted()));
                    }
                    eprintln!("aviary: the world file {} has errors", path.display());
                    return 2;
                }
            }
        }
    };
    match crate::serve::station(serve, Mode::Replay { name: name.clone(), trace: text }, map) {
        Ok(_serving) => {
            eprintln!("aviary: replaying {name}; Ctrl-C stops");
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
