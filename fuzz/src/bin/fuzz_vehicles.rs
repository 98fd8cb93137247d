//! The `fuzz_vehicles` target. Built by `cargo afl build` (which sets `--cfg fuzzing`), it
//! is the AFL harness: `cargo afl fuzz -i in/vehicles -o out/vehicles target/release/fuzz_vehicles`.
//! Built by plain cargo, it runs the target once on each file named on the command line
//! (or on stdin), to reproduce a crash: `cargo run --bin fuzz_vehicles -- out/vehicles/default/crashes/id*`.

#[cfg(fuzzing)]
fn main() {
    afl::fuzz!(|data: &[u8]| {
        aviary_fuzz::vehicles(data);
    });
}

#[cfg(not(fuzzing))]
fn main() {
    aviary_fuzz::run_files(aviary_fuzz::vehicles);
}
