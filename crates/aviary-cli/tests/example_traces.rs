//! The traces of the examples, byte for byte: every mission in `examples/` (the paper's
//! mission and the newcomers' scenarios, the bridge inspection as it flies with no
//! operator) and each fault drill in `examples/faults/`, run as a user runs them
//! (`aviary run FILE --trace OUT`), against a snapshot. A change that should not change
//! behaviour must leave every one of them as it is; one that does shows, event by event,
//! in review.

mod common;

use common::{aviary, repo, scratch};

#[test]
fn every_example_writes_the_trace_it_always_wrote() {
    let dir = scratch("example_traces");
    // Every mission of `examples/` and of `examples/faults/`, as the folders hold them.
    let missions_in = |folder: &str| -> Vec<String> {
        let mut found: Vec<String> = std::fs::read_dir(repo().join(folder))
            .expect(folder)
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|x| x == "mission"))
            .map(|p| format!("{folder}/{}", p.file_name().unwrap_or_default().to_string_lossy()))
            .collect();
        found.sort();
        found
    };
    let mut missions = missions_in("examples");
    let drills = missions_in("examples/faults");
    missions.extend(drills);
    for mission in missions {
        let name = std::path::Path::new(&mission)
            .file_stem()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        let trace = dir.join(format!("{name}.jsonl"));
        let (code, out, err) =
            aviary(&["run", &mission, "--quiet", "--trace", &trace.to_string_lossy()], &repo());
        assert_eq!(code, 0, "{mission}: {out}{err}");
        let text = std::fs::read_to_string(&trace).expect("the trace");
        insta::assert_snapshot!(name, text);
    }
}
