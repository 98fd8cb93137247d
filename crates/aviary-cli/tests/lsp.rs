//! The real `aviary lsp` binary over stdio, as an editor starts it: initialize, open a
//! mission whose world and USEd library are on disk, receive the diagnostics of both
//! files, shut down and exit.

mod common;

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

use serde_json::{json, Value};

fn send(stdin: &mut impl Write, message: &Value) {
    let body = message.to_string();
    write!(stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).unwrap();
    stdin.flush().unwrap();
}

/// `aviary lsp` started as an editor starts it, through `initialize` and `initialized`:
/// the process, its input, its output and the answer to `initialize`.
fn start() -> (Child, ChildStdin, BufReader<ChildStdout>, Value) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .arg("lsp")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start aviary lsp");
    let mut stdin = child.stdin.take().unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    send(
        &mut stdin,
        &json!({ "jsonrpc": "2.0", "id": 1, "method": "initialize", "params": { "processId": null, "rootUri": null, "capabilities": {} } }),
    );
    let init = receive(&mut stdout);
    assert_eq!(init["id"], 1);
    send(&mut stdin, &json!({ "jsonrpc": "2.0", "method": "initialized", "params": {} }));
    (child, stdin, stdout, init)
}

fn receive(stdout: &mut impl BufRead) -> Value {
    let mut length = None;
    loop {
        let mut line = String::new();
        assert!(stdout.read_line(&mut line).unwrap() > 0, "the server closed its output");
        let line = line.trim_end();
        if line.is_empty() {
            break;
        }
        if let Some(n) = line.strip_prefix("Content-Length: ") {
            length = Some(n.parse::<usize>().unwrap());
        }
    }
    let mut body = vec![0; length.expect("a Content-Length header")];
    stdout.read_exact(&mut body).unwrap();
    serde_json::from_slice(&body).unwrap()
}

#[test]
fn initialize_open_diagnostics_shutdown_over_stdio() {
    let dir = common::scratch("lsp_stdio");
    std::fs::write(
        dir.join("site.world.toml"),
        "[places]\nHome = [0, 0]\n\n[drones.scout]\nhome = [0, 0]\n",
    )
    .unwrap();
    std::fs::create_dir_all(dir.join("lib")).unwrap();
    std::fs::write(
        dir.join("lib/moves.mission"),
        "CAPABILITY GoHome BY drone:\n    PERFORM:\n        drone FlyTo WITH Hmoe\n",
    )
    .unwrap();
    let mission = "USE \"lib/moves.mission\"\n\nMISSION Site:\n    scout TakeOff\n    scout FlyTo WITH Hom\n    scout GoHome\n";
    std::fs::write(dir.join("site.mission"), mission).unwrap();
    let dir = std::fs::canonicalize(&dir).unwrap();
    let uri = format!("file://{}/site.mission", dir.display());
    let lib_uri = format!("file://{}/lib/moves.mission", dir.display());

    let (mut child, mut stdin, mut stdout, init) = start();
    assert_eq!(init["result"]["capabilities"]["textDocumentSync"], 2, "{init}");
    send(
        &mut stdin,
        &json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {
        "textDocument": { "uri": uri, "languageId": "aviary", "version": 1, "text": mission } } }),
    );

    let mut published = std::collections::BTreeMap::new();
    while published.len() < 2 {
        let m = receive(&mut stdout);
        assert_eq!(m["method"], "textDocument/publishDiagnostics", "{m}");
        let codes: Vec<String> = m["params"]["diagnostics"]
            .as_array()
            .unwrap()
            .iter()
            .map(|d| format!("{} {}", d["code"].as_str().unwrap(), d["message"].as_str().unwrap()))
            .collect();
        published.insert(m["params"]["uri"].as_str().unwrap().to_string(), codes);
    }
    assert_eq!(
        published[&uri],
        ["E103 unknown place `Hom`\nhelp: did you mean `Home`?"],
        "{published:?}"
    );
    assert_eq!(
        published[&lib_uri],
        ["E103 unknown place `Hmoe`\nhelp: did you mean `Home`?"],
        "{published:?}"
    );

    send(&mut stdin, &json!({ "jsonrpc": "2.0", "id": 2, "method": "shutdown", "params": null }));
    let bye = receive(&mut stdout);
    assert_eq!(bye["id"], 2);
    assert_eq!(bye["result"], Value::Null, "{bye}");
    send(&mut stdin, &json!({ "jsonrpc": "2.0", "method": "exit", "params": null }));
    drop(stdin);
    let code = common::wait_at_most(&mut child, std::time::Duration::from_secs(30), "aviary lsp");
    assert_eq!(code, 0);
}

/// A world's `[imports]` as the editor sees them: the places of a GeoJSON file beside the
/// world are known (a typo is told the imported name), and a rename of one is refused,
/// since its definition is the file's name in the world, not a key.
#[test]
fn the_places_a_world_imports_are_known_and_not_renamed_over_the_files_name() {
    let dir = common::scratch("lsp_imports");
    std::fs::copy(
        common::repo().join("crates/aviary-world/tests/fixtures/imports/farm.geojson"),
        dir.join("farm.geojson"),
    )
    .unwrap();
    std::fs::write(
        dir.join("farm.world.toml"),
        "[site]\norigin = { lat = 46.6167, lon = 14.2650 }\n\n[imports]\nfeatures = \"farm.geojson\"\n\n[drones.scout]\nhome = [0, 0]\n",
    )
    .unwrap();
    let mission =
        "MISSION Farm:\n    scout TakeOff\n    scout FlyTo WITH Barn\n    scout FlyTo WITH Bran\n";
    std::fs::write(dir.join("farm.mission"), mission).unwrap();
    let dir = std::fs::canonicalize(&dir).unwrap();
    let uri = format!("file://{}/farm.mission", dir.display());

    let (mut child, mut stdin, mut stdout, _) = start();
    send(
        &mut stdin,
        &json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {
        "textDocument": { "uri": uri, "languageId": "aviary", "version": 1, "text": mission } } }),
    );
    let codes = loop {
        let m = receive(&mut stdout);
        if m["params"]["uri"] == uri.as_str() {
            let all = m["params"]["diagnostics"].as_array().unwrap().clone();
            break all
                .iter()
                .map(|d| {
                    format!("{} {}", d["code"].as_str().unwrap(), d["message"].as_str().unwrap())
                })
                .collect::<Vec<_>>();
        }
    };
    assert_eq!(codes, ["E103 unknown place `Bran`\nhelp: did you mean `Barn`?"], "{codes:?}");
    send(
        &mut stdin,
        &json!({ "jsonrpc": "2.0", "id": 2, "method": "textDocument/rename", "params": {
        "textDocument": { "uri": uri }, "position": { "line": 2, "character": 24 }, "newName": "Shed" } }),
    );
    let answer = loop {
        let m = receive(&mut stdout);
        if m["id"] == 2 {
            break m;
        }
    };
    let why = answer["error"]["message"].as_str().unwrap_or_default();
    assert!(why.contains("a file the world imports (\"farm.geojson\")"), "{answer}");
    send(&mut stdin, &json!({ "jsonrpc": "2.0", "id": 3, "method": "shutdown", "params": null }));
    while receive(&mut stdout)["id"] != 3 {}
    send(&mut stdin, &json!({ "jsonrpc": "2.0", "method": "exit", "params": null }));
    drop(stdin);
    let code = common::wait_at_most(&mut child, std::time::Duration::from_secs(30), "aviary lsp");
    assert_eq!(code, 0);
}
