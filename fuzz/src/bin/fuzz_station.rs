//! The `fuzz_station` target. Built by `cargo afl build` (which sets `--cfg fuzzing`), it
//! is the AFL harness: `cargo afl fuzz -i in/station -o out/station target/release/fuzz_station`.
//! Built by plain cargo, it runs the target once on each file named on the command line
//! (or on stdin), to reproduce a crash: `cargo run --bin fuzz_station -- out/station/default/crashes/id*`.

#[cfg(fuzzing)]
fn main() {
    afl::fuzz!(|data: &[u8]| {
        aviary_fuzz::station(data);
    });
}

#[cfg(not(fuzzing))]
fn main() {
    aviary_fuzz::run_files(aviary_fuzz::station);
}
