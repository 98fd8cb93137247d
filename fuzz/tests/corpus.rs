//! Every seed, and every crash AFL has found and that was fixed (`regressions/`), runs
//! through the targets without AFL: `cargo test` in `fuzz/`.

use std::path::Path;

fn each_file(dir: &str, run: fn(&[u8])) -> usize {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(dir);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return 0;
    };
    let mut n = 0;
    for entry in entries {
        let path = entry.expect("a directory entry").path();
        if path.is_file() {
            run(&std::fs::read(&path).expect("a readable file"));
            n += 1;
        }
    }
    n
}

#[test]
fn seeds_and_regressions_of_fuzz_mission() {
    assert!(each_file("in/mission", aviary_fuzz::mission) > 0);
    each_file("regressions/mission", aviary_fuzz::mission);
}

#[test]
fn seeds_and_regressions_of_fuzz_world() {
    assert!(each_file("in/world", aviary_fuzz::world) > 0);
    each_file("regressions/world", aviary_fuzz::world);
}

#[test]
fn seeds_and_regressions_of_fuzz_operator() {
    assert!(each_file("in/operator", aviary_fuzz::operator) > 0);
    each_file("regressions/operator", aviary_fuzz::operator);
}
