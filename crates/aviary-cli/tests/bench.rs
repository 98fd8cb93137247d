//! `aviary bench parse` runs end to end on a small generated mission and exits 0.

use std::process::Command;

#[test]
fn bench_parse_runs_and_reports_the_median() {
    let out = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["bench", "parse", "--mb", "0.2", "--runs", "1"])
        .output()
        .expect("the aviary binary runs");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "stdout:\n{stdout}\nstderr:\n{stderr}");
    assert!(stdout.contains("run 1: parse "), "{stdout}");
    assert!(stdout.contains("median of 1 run(s)"), "{stdout}");
    assert!(stdout.contains("MB/s"), "{stdout}");
    // The generated mission checks clean, so the bench has nothing to warn about.
    assert!(!stdout.contains("note: the check reports"), "{stdout}");
}

#[test]
fn bench_parse_refuses_a_size_of_zero() {
    let out = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["bench", "parse", "--mb", "0"])
        .output()
        .expect("the aviary binary runs");
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn bench_front_checks_both_shapes_clean_and_reports_the_median() {
    for shape in ["sequential", "chain"] {
        let out = Command::new(env!("CARGO_BIN_EXE_aviary"))
            .args(["bench", "front", "--shape", shape, "--n", "300", "--runs", "1"])
            .output()
            .expect("the aviary binary runs");
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{shape}: {stdout}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            stdout.contains("run 1: parse + check ") && stdout.contains(" 0 error(s)"),
            "{shape}: {stdout}"
        );
        assert!(stdout.contains("median of 1 run(s)"), "{shape}: {stdout}");
    }
}
