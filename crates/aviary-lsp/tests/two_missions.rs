//! Two open missions that `USE` one library: renaming a capability of the library, or
//! finding its references, from one of them covers the other too; a mission that does not
//! read the library is left alone.

mod support;

use std::path::Path;

use serde_json::json;
use support::{uri, Client};

#[test]
fn a_rename_in_a_shared_library_edits_every_open_mission_that_uses_it() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let first = std::fs::read_to_string(dir.join("uses.mission")).unwrap();
    // A second mission beside it (not on disk) with the same library and world names.
    let second = "USE \"lib/beacons.mission\"\n\nMISSION Other:\n    beacon_drone2 MarkPlace WITH Facility\n";
    // A third with a capability of its own of the same name, and no USE.
    let third = "MISSION Alone:\n    beacon_drone1 MarkPlace\n\nCAPABILITY MarkPlace BY drone:\n    PERFORM:\n        drone Hover\n";
    let lib = std::fs::read_to_string(dir.join("uses_lib.txt")).unwrap();
    let mut client = Client::start();
    client.open(&uri(&dir.join("lib/beacons.mission")), &lib);
    client.open(&uri(&dir.join("uses.mission")), &first);
    client.open(&uri(&dir.join("uses_second.mission")), second);
    client.open(&uri(&dir.join("uses_third.mission")), third);
    client.sync();
    let at = json!({ "textDocument": { "uri": uri(&dir.join("uses.mission")) }, "position": { "line": 5, "character": 20 } });
    let found = client.request(
        "textDocument/references",
        json!({ "textDocument": at["textDocument"], "position": at["position"], "context": { "includeDeclaration": true } }),
    );
    let mut files: Vec<String> = found["result"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| {
            let u = l["uri"].as_str().unwrap();
            u.rsplit('/').next().unwrap().to_string()
                + ":"
                + &l["range"]["start"]["line"].to_string()
        })
        .collect();
    files.sort();
    assert_eq!(
        files,
        ["beacons.mission:1", "uses.mission:5", "uses.mission:8", "uses_second.mission:3"],
        "{found}"
    );
    let renamed = client.request(
        "textDocument/rename",
        json!({ "textDocument": at["textDocument"], "position": at["position"], "newName": "Mark" }),
    );
    let changes = renamed["result"]["documentChanges"].as_array().unwrap();
    let mut edited: Vec<(String, usize)> = changes
        .iter()
        .map(|c| {
            let u = c["textDocument"]["uri"].as_str().unwrap();
            (u.rsplit('/').next().unwrap().to_string(), c["edits"].as_array().unwrap().len())
        })
        .collect();
    edited.sort();
    assert_eq!(
        edited,
        [
            ("beacons.mission".to_string(), 1),
            ("uses.mission".to_string(), 2),
            ("uses_second.mission".to_string(), 1)
        ],
        "{renamed}"
    );
    client.shutdown();
}
