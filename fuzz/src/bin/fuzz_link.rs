//! The `fuzz_link` target. Built by `cargo afl build` (which sets `--cfg fuzzing`), it
//! is the AFL harness: `cargo afl fuzz -i in/link -o out/link target/release/fuzz_link`.
//! Built by plain cargo, it runs the target once on each file named on the command line
//! (or on stdin), to reproduce a crash: `cargo run --bin fuzz_link -- out/link/default/crashes/id*`.

#[cfg(fuzzing)]
fn main() {
    afl::fuzz!(|data: &[u8]| {
        aviary_fuzz::link(data);
    });
}

#[cfg(not(fuzzing))]
fn main() {
    aviary_fuzz::run_files(aviary_fuzz::link);
}
