//! The `fuzz_mission` target. Built by `cargo afl build` (which sets `--cfg fuzzing`), it
//! is the AFL harness: `cargo afl fuzz -i in/mission -o out/mission target/release/fuzz_mission`.
//! Built by plain cargo, it runs the target once on each file named on the command line
//! (or on stdin), to reproduce a crash: `cargo run --bin fuzz_mission -- out/mission/default/crashes/id*`.

#[cfg(fuzzing)]
fn main() {
    afl::fuzz!(|data: &[u8]| {
        aviary_fuzz::mission(data);
    });
}

#[cfg(not(fuzzing))]
fn main() {
    aviary_fuzz::run_files(aviary_fuzz::mission);
}
