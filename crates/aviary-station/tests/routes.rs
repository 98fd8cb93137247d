//! The station's calls that name files, through the real router (no socket): names the
//! server decodes from the query string, and the trace of a flight from the page, which
//! the station writes itself. Every one is checked by `Folder::place` (`tests/paths.rs`).

#![cfg(unix)]

use std::path::{Path, PathBuf};

use aviary_check::{NoFiles, SourceProvider};
use aviary_station::{FilesFor, Folder, Mode};
use axum::body::Body;
use axum::http::Request;
use tower::ServiceExt;

const TOKEN: &str = "00112233445566778899aabbccddeeff";

fn folders(name: &str) -> (PathBuf, PathBuf) {
    let base = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("station_routes_{name}"));
    let _ = std::fs::remove_dir_all(&base);
    let (root, outside) = (base.join("root"), base.join("outside"));
    std::fs::create_dir_all(&root).unwrap();
    std::fs::create_dir_all(&outside).unwrap();
    std::fs::write(root.join("m.mission"), "MISSION M:\n    a TakeOff\n").unwrap();
    std::fs::write(root.join("m.world.toml"), "[drones.a]\nhome = [0, 0]\n").unwrap();
    std::fs::write(outside.join("secret.mission"), "MISSION Secret:\n").unwrap();
    (root, outside)
}

fn station(root: &Path) -> axum::Router {
    let files: FilesFor =
        Box::new(|_: &Path| Ok(Box::new(NoFiles) as Box<dyn SourceProvider + Send>));
    let mode = Mode::Folder { folder: Folder::new(root).unwrap(), files };
    let bound = "127.0.0.1:7878".parse().unwrap();
    aviary_station::router(mode, bound, TOKEN.into(), &[], serde_json::Value::Null, None)
}

/// A call with the token, as the page makes it: status and JSON answer.
fn call(app: &axum::Router, method: &str, uri: &str, body: &str) -> (u16, serde_json::Value) {
    let request = Request::builder()
        .method(method)
        .uri(uri)
        .header("host", "127.0.0.1:7878")
        .header("authorization", format!("Bearer {TOKEN}"))
        .header("content-type", "application/json")
        .body(Body::from(body.to_string()))
        .unwrap();
    let runtime = tokio::runtime::Builder::new_multi_thread().enable_all().build().unwrap();
    runtime.block_on(async {
        let response = app.clone().oneshot(request).await.unwrap();
        let status = response.status().as_u16();
        let bytes = axum::body::to_bytes(response.into_body(), usize::MAX).await.unwrap();
        (status, serde_json::from_slice(&bytes).unwrap_or(serde_json::Value::Null))
    })
}

#[test]
fn names_the_server_decodes_are_checked_as_any_other() {
    let (root, _) = folders("decoded");
    std::os::unix::fs::symlink(root.parent().unwrap().join("outside"), root.join("out")).unwrap();
    let app = station(&root);
    let (status, answer) = call(&app, "GET", "/api/station/file?path=m.mission", "");
    assert_eq!((status, answer["text"].as_str()), (200, Some("MISSION M:\n    a TakeOff\n")));
    for query in [
        "..%2Foutside%2Fsecret.mission",
        "%2e%2e%2foutside%2fsecret.mission",
        "%252e%252e%252foutside%252fsecret.mission",
        "%2Fetc%2Fpasswd.toml",
        "out%2Fsecret.mission",
        "m.mission%00.txt",
    ] {
        let (status, answer) = call(&app, "GET", &format!("/api/station/file?path={query}"), "");
        assert_eq!(status, 404, "{query}: {answer}");
        assert!(answer["error"].is_string(), "{query}: {answer}");
        assert!(answer.get("text").is_none(), "{query}: {answer}");
    }
    for query in ["..%2Foutside%2Fx.toml", "out%2Fx.toml"] {
        let (status, _) = call(&app, "GET", &format!("/api/station/world?path={query}"), "");
        assert_ne!(status, 200, "{query}");
        let (status, _) = call(&app, "GET", &format!("/api/station/trace?path={query}.jsonl"), "");
        assert_ne!(status, 200, "{query}");
        let report = format!("/api/station/report?path=%2e%2e%2foutside%2ft.jsonl&world={query}");
        assert_ne!(call(&app, "GET", &report, "").0, 200, "{query}");
    }
}

/// The station writes a flight's trace in `traces/` of its folder: a `traces` that is a
/// link out of the folder is refused, and nothing is written outside.
#[test]
fn a_flights_trace_is_never_written_through_a_link_out_of_the_folder() {
    let (root, outside) = folders("flight_trace");
    std::fs::create_dir_all(outside.join("elsewhere")).unwrap();
    std::os::unix::fs::symlink(outside.join("elsewhere"), root.join("traces")).unwrap();
    let app = station(&root);
    let body = serde_json::json!({
        "mission": { "path": "m.mission", "text": "MISSION M:\n    a TakeOff\n" },
        "world": { "path": "m.world.toml", "text": "[drones.a]\nhome = [0, 0]\n" },
    });
    let (status, answer) = call(&app, "POST", "/api/station/fly", &body.to_string());
    assert_eq!(status, 409, "{answer}");
    let why = answer["error"].as_str().unwrap_or_default();
    assert!(why.contains("leads outside the station's folder"), "{why}");
    let written: Vec<_> = std::fs::read_dir(outside.join("elsewhere")).unwrap().collect();
    assert!(written.is_empty(), "written outside: {written:?}");
}

/// Reads a `USE` beside the file that says it, as the command line's `DiskProvider` does.
struct Beside;

impl SourceProvider for Beside {
    fn load(&self, from: &str, path: &str) -> Result<(String, Vec<u8>), aviary_check::LoadError> {
        let full = Path::new(from).parent().unwrap_or(Path::new("")).join(path);
        match std::fs::read(&full) {
            Ok(bytes) => Ok((full.display().to_string(), bytes)),
            Err(e) => Err(format!("{}: {e}", full.display()).into()),
        }
    }
}

/// The page names its files relative to the folder: a mission's `USE` is read beside the
/// mission in the folder (not in the station's working directory), and a used file's
/// diagnostics name it as the page does.
#[test]
fn a_check_reads_what_the_mission_uses_beside_it_in_the_folder() {
    let (root, _) = folders("uses");
    std::fs::create_dir_all(root.join("lib")).unwrap();
    std::fs::write(
        root.join("lib/moves.mission"),
        "CAPABILITY GoHome BY drone:\n    PERFORM:\n        drone FlyTo WITH Hmoe\n",
    )
    .unwrap();
    let files: FilesFor =
        Box::new(|_: &Path| Ok(Box::new(Beside) as Box<dyn SourceProvider + Send>));
    let mode = Mode::Folder { folder: Folder::new(&root).unwrap(), files };
    let bound = "127.0.0.1:7878".parse().unwrap();
    let app = aviary_station::router(mode, bound, TOKEN.into(), &[], serde_json::Value::Null, None);
    let body = serde_json::json!({
        "mission": { "path": "m.mission", "text": "USE \"lib/moves.mission\"\n\nMISSION M:\n    a TakeOff\n    a GoHome\n" },
        "world": { "path": "m.world.toml", "text": "[places]\nHome = [0, 0]\n\n[drones.a]\nhome = [0, 0]\n" },
    });
    let (status, answer) = call(&app, "POST", "/api/station/check", &body.to_string());
    assert_eq!(status, 200, "{answer}");
    let diagnostics = answer["diagnostics"].as_array().unwrap();
    let errors: Vec<_> = diagnostics.iter().filter(|d| d["severity"] == "error").collect();
    assert_eq!(errors.len(), 1, "only the used file's typo: {answer}");
    assert_eq!(errors[0]["code"], "E103", "{answer}");
    assert_eq!(errors[0]["file"], "lib/moves.mission", "named as the page names it: {answer}");
}
