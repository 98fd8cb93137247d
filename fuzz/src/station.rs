//! The `fuzz_station` target: arbitrary bytes as a call to the ground station (`aviary gcs
//! DIR`): the route and its path or query, headers and body, through the real router (no
//! socket), on a folder of its own. Properties: no panic; every answer of an `/api/` route
//! is JSON, every error `{"error": "..."}`; a save succeeds only with the token, and
//! writes only inside the folder (nothing appears beside it).
//!
//! The input: byte 0 picks the route, byte 1 sets flags (bit 0: send the token; bit 1: the
//! station is bound beyond loopback; bit 2: `Content-Type: application/json`), then a line
//! appended to the route's path (a file's name, a query), then header lines `Name: value`
//! up to an empty line, then the body. Flying is left out: each call would start a flight;
//! its body is read as the check's is, and the flight's own limits are unit-tested.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use aviary_check::{NoFiles, SourceProvider};
use aviary_station::{FilesFor, Folder, Mode};
use tower::ServiceExt;

use crate::call::{call, Call, TOKEN};

/// Byte 0 modulo their number picks one; a route added goes last.
const ROUTES: [(&str, &str); 7] = [
    ("GET", "/api/station"),
    ("GET", "/api/station/files"),
    ("GET", "/api/station/file?path="),
    ("POST", "/api/station/check"),
    ("POST", "/api/station/save"),
    ("GET", "/assets/"),
    ("GET", "/api/state"),
];

/// The folder the station serves, inside a parent that nothing else writes to: made once.
fn folder() -> &'static (PathBuf, PathBuf) {
    static FOLDER: OnceLock<(PathBuf, PathBuf)> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let parent =
            std::env::temp_dir().join(format!("aviary-fuzz-station-{}", std::process::id()));
        let dir = parent.join("missions");
        std::fs::create_dir_all(&dir).expect("the fuzz folder");
        std::fs::write(dir.join("m.mission"), "MISSION M:\n    a FlyTo WITH Tower\n").unwrap();
        std::fs::write(
            dir.join("m.world.toml"),
            "[places]\nTower = [0, 100]\n[drones.a]\nhome = [0, 0]\n",
        )
        .unwrap();
        (parent, dir)
    })
}

fn beside(parent: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(parent)
        .map(|d| d.flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect())
        .unwrap_or_default();
    names.sort();
    names
}

pub fn station(data: &[u8]) {
    // A path that is no URI a client could send never reaches the router.
    let Some(Call { route, request, bound, carries_token }) = call(data, &ROUTES, true) else {
        return;
    };
    let (parent, dir) = folder();
    let before = beside(parent);
    let files: FilesFor =
        Box::new(|_: &Path| Ok(Box::new(NoFiles) as Box<dyn SourceProvider + Send>));
    let mode = Mode::Folder { folder: Folder::new(dir).expect("the folder"), files };
    let app = aviary_station::router(
        mode,
        bound,
        TOKEN.into(),
        &["ops.example.org".into()],
        serde_json::Value::Null,
        None,
    );
    let runtime =
        tokio::runtime::Builder::new_multi_thread().worker_threads(1).enable_all().build().unwrap();
    let (status, bytes) = runtime.block_on(async {
        let response = app.oneshot(request).await.expect("the router's errors are answers");
        let status = response.status();
        (status, axum::body::to_bytes(response.into_body(), usize::MAX).await.expect("the body"))
    });
    assert_eq!(beside(parent), before, "a call wrote beside the station's folder");
    if !route.1.starts_with("/api/") {
        return; // a file of the page, or a JSON error
    }
    let json: serde_json::Value = serde_json::from_slice(&bytes).unwrap_or_else(|e| {
        panic!("{status} is not JSON ({e}): {:?}", String::from_utf8_lossy(&bytes))
    });
    if status.is_client_error() || status.is_server_error() {
        assert!(json["error"].is_string(), "{status} without an error message: {json}");
    } else if route.1 == "/api/station/save" {
        assert!(carries_token, "a save without the token");
    }
}
