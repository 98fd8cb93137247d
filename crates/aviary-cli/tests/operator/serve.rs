//! A served run and raw HTTP to it: the tests write the very bytes a browser, a proxy
//! or an attacker would send (Host, Origin, Authorization, bodies), with no client in
//! between to fix them up.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::Path;
use std::process::{Child, ChildStderr, Command, Stdio};
use std::time::Duration;

pub struct Run {
    pub child: Child,
    /// `127.0.0.1:PORT`
    pub addr: String,
    pub port: u16,
    pub url: String,
    pub token: String,
    pub stderr: BufReader<ChildStderr>,
}

impl Drop for Run {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `aviary run m.mission --serve ... EXTRA` on the files given, in real time.
pub fn serve(dir: &Path, mission: &str, world: &str, serve: &str, extra: &[&str]) -> Run {
    std::fs::write(dir.join("m.mission"), mission).unwrap();
    std::fs::write(dir.join("m.world.toml"), world).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", "m.mission", "--serve", serve, "--quiet", "--trace", "t.jsonl"])
        .args(extra)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    stderr.read_line(&mut line).unwrap();
    // aviary: operator API on http://127.0.0.1:PORT  token TOKEN
    let url = line
        .split_whitespace()
        .find(|w| w.starts_with("http://"))
        .unwrap_or_else(|| panic!("no URL in {line:?}"))
        .to_string();
    let token = line.split_whitespace().last().expect("token").to_string();
    let addr = url.trim_start_matches("http://").to_string();
    let port = addr.rsplit(':').next().unwrap().parse().unwrap();
    Run { child, addr, port, url, token, stderr }
}

pub struct Answer {
    pub status: u16,
    pub head: String,
    pub body: String,
}

impl Answer {
    /// The body as JSON: every answer of the API is JSON, errors included.
    pub fn json(&self) -> serde_json::Value {
        serde_json::from_str(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {} {}", self.status, self.body))
    }
    /// The `error` of a JSON error answer.
    pub fn error(&self) -> String {
        self.json()["error"]
            .as_str()
            .unwrap_or_else(|| panic!("no error in {}", self.body))
            .to_string()
    }
}

/// One request: `headers` go as written, and a `Host` of this server is added unless
/// one is given. The answer's head is read, then its body by `content-length` (a
/// WebSocket's 101 has none).
pub fn http(run: &Run, method: &str, path: &str, headers: &[(&str, &str)], body: &str) -> Answer {
    let mut text = format!("{method} {path} HTTP/1.1\r\n");
    if !headers.iter().any(|(k, _)| k.eq_ignore_ascii_case("host")) {
        text.push_str(&format!("Host: {}\r\n", run.addr));
    }
    for (k, v) in headers {
        text.push_str(&format!("{k}: {v}\r\n"));
    }
    text.push_str(&format!("Content-Length: {}\r\nConnection: close\r\n\r\n{body}", body.len()));
    let mut stream = TcpStream::connect(&run.addr).expect("connect");
    stream.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    // A large body may be refused before it is all sent: the answer still comes.
    let _ = stream.write_all(text.as_bytes());
    let mut got = Vec::new();
    let mut byte = [0u8; 1];
    while !got.ends_with(b"\r\n\r\n") {
        match stream.read(&mut byte) {
            Ok(1) => got.push(byte[0]),
            _ => panic!("the answer ended in its head: {}", String::from_utf8_lossy(&got)),
        }
    }
    let head = String::from_utf8_lossy(&got).into_owned();
    let status = head.split_whitespace().nth(1).and_then(|s| s.parse().ok()).expect("a status");
    let length = head
        .lines()
        .find_map(|l| {
            l.to_ascii_lowercase()
                .strip_prefix("content-length:")
                .map(|n| n.trim().parse::<usize>().unwrap())
        })
        .unwrap_or(0);
    let mut body = vec![0u8; length];
    stream.read_exact(&mut body).expect("the body");
    Answer { status, head, body: String::from_utf8_lossy(&body).into_owned() }
}

/// A WebSocket handshake on `/api/events`, with `headers` besides the handshake's own.
pub fn upgrade(run: &Run, headers: &[(&str, &str)]) -> Answer {
    let mut all = vec![
        ("Connection", "Upgrade"),
        ("Upgrade", "websocket"),
        ("Sec-WebSocket-Version", "13"),
        ("Sec-WebSocket-Key", "dGhlIHNhbXBsZSBub25jZQ=="),
    ];
    all.extend_from_slice(headers);
    http(run, "GET", "/api/events", &all, "")
}

pub fn bearer(run: &Run) -> String {
    format!("Bearer {}", run.token)
}

/// A control call: `body` POSTed to `path` with the token; the status, and the body
/// (200) or the error's message.
pub fn post(run: &Run, path: &str, body: &str) -> (u16, String) {
    let headers = [("Authorization", bearer(run)), ("Content-Type", "application/json".into())];
    let headers: Vec<(&str, &str)> = headers.iter().map(|(k, v)| (*k, v.as_str())).collect();
    let a = http(run, "POST", path, &headers, body);
    (a.status, if a.status == 200 { a.body } else { a.error() })
}

/// The operator raises `name` with the JSON `args`.
pub fn raise(run: &Run, name: &str, args: &str) -> (u16, String) {
    post(run, "/api/signal", &format!("{{\"name\": \"{name}\", \"args\": {args}}}"))
}
