//! The `fuzz_lsp` target. Built by `cargo afl build` (which sets `--cfg fuzzing`), it
//! is the AFL harness: `cargo afl fuzz -i in/lsp -o out/lsp target/release/fuzz_lsp`.
//! Built by plain cargo, it runs the target once on each file named on the command line
//! (or on stdin), to reproduce a crash: `cargo run --bin fuzz_lsp -- out/lsp/default/crashes/id*`.

#[cfg(fuzzing)]
fn main() {
    afl::fuzz!(|data: &[u8]| {
        aviary_fuzz::lsp(data);
    });
}

#[cfg(not(fuzzing))]
fn main() {
    aviary_fuzz::run_files(aviary_fuzz::lsp);
}
