//! `aviary report TRACE [--world W] -o OUT.html`: one self-contained HTML file for the
//! record after a mission (`aviary_station::report`).

use std::path::Path;

pub fn run(trace: &Path, world: Option<&Path>, out: &Path) -> u8 {
    let (name, bytes, world) = match crate::files::recorded_trace_and_world(trace, world) {
        Ok(read) => read,
        Err(shown) => {
            eprint!("{shown}");
            return 2;
        }
    };
    let html = match aviary_station::report::render(&name, bytes, world.as_ref()) {
        Ok(h) => h,
        Err(why) => {
            eprintln!("aviary: {why}");
            return 2;
        }
    };
    // Written beside and renamed over: a report is whole or not there.
    let temporary = out.with_extension("html.writing");
    if let Err(e) = std::fs::write(&temporary, html).and_then(|()| std::fs::rename(&temporary, out))
    {
        let _ = std::fs::remove_file(&temporary);
        eprintln!("aviary: cannot write {}: {e}", out.display());
        return 2;
    }
    eprintln!("aviary: wrote {}", out.display());
    0
}
