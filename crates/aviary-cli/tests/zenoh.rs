//! `aviary run --zenoh` seen from another Zenoh peer: a session of the test's own (the
//! `zenoh` crate, as any Rust client would use it) connects to the run's endpoint,
//! subscribes to its keys, reads the state and steers the mission through the
//! queryables. What it receives is the trace file's own lines; a call without the token,
//! or with a body that is not JSON, changes nothing and is logged; a pause is seen on
//! the events key within a second. Without `--zenoh`, a run opens no socket.

mod common;

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, ChildStderr, Command, Stdio};
use std::time::{Duration, Instant};

use common::{free_port, scratch, wait_at_most};
use zenoh::Wait;

const WORLD: &str =
    "[places]\nFar = [0, 400]\n[drones.a]\nhome = [0, 0]\n[drones.b]\nhome = [10, 0]\n";
const MISSION: &str =
    "MISSION M:\n    PARALLEL:\n        a FlyTo-F1 WITH Far\n        b Hover WITH 40s\n";

/// A peer that finds no one by scouting: it listens or connects where it is told, and no
/// other test's Zenoh session on this machine can join it.
fn peer(endpoints: &str, port: u16) -> String {
    common::zenoh_peer(endpoints, &format!("tcp/127.0.0.1:{port}"))
}

/// `aviary run --zenoh` of the test's mission in `dir`, at 10 times real time, with the
/// Zenoh configuration `config` and the key prefix `prefix`, its trace in `t.jsonl`: the
/// process, its standard error after the first line, and the token that line gives.
fn on_zenoh(
    dir: &std::path::Path,
    config: &str,
    prefix: &str,
) -> (Child, BufReader<ChildStderr>, String) {
    std::fs::write(dir.join("m.mission"), MISSION).unwrap();
    std::fs::write(dir.join("m.world.toml"), WORLD).unwrap();
    std::fs::write(dir.join("zenoh.json5"), config).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", "m.mission", "--zenoh", "zenoh.json5", "--zenoh-prefix", prefix])
        .args(["--speed", "10", "--quiet", "--trace", "t.jsonl"])
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    let mut stderr = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    stderr.read_line(&mut line).unwrap();
    // aviary: on Zenoh under PREFIX/: events, ...; operator API PREFIX/api/CALL  token TOKEN
    assert!(line.contains(&format!("on Zenoh under {prefix}/")), "{line}");
    let token = line.split_whitespace().last().expect("token").to_string();
    (child, stderr, token)
}

fn get(
    session: &zenoh::Session,
    key: &str,
    body: Option<&str>,
    token: Option<&str>,
) -> Result<serde_json::Value, serde_json::Value> {
    let mut get = session.get(key).timeout(Duration::from_secs(5));
    if let Some(body) = body {
        get = get.payload(body.to_string());
    }
    if let Some(token) = token {
        get = get.attachment(token.to_string());
    }
    let replies = get.wait().expect("a query is sent");
    let reply = replies.recv().expect("the run answers");
    let json = |bytes: &zenoh::bytes::ZBytes| {
        serde_json::from_slice(&bytes.to_bytes()).expect("the answer is JSON")
    };
    match reply.result() {
        Ok(sample) => Ok(json(sample.payload())),
        Err(error) => Err(json(error.payload())),
    }
}

#[test]
fn a_peer_watches_and_steers_a_run_on_zenoh() {
    let dir = scratch("zenoh_run");
    let port = free_port();
    let (mut child, mut stderr, token) = on_zenoh(&dir, &peer("listen", port), "test/ops");

    let config = zenoh::Config::from_json5(&peer("connect", port)).unwrap();
    let session = zenoh::open(config).wait().expect("the test's peer opens");
    let heard = session.declare_subscriber("test/ops/**").wait().unwrap();
    // A second station, on a session of its own, that only watches.
    let config = zenoh::Config::from_json5(&peer("connect", port)).unwrap();
    let other = zenoh::open(config).wait().expect("the second peer opens");
    // When each event reached it.
    let (arrived, other_heard) = std::sync::mpsc::channel::<(Instant, String)>();
    let _other_subscriber = other
        .declare_subscriber("test/ops/events")
        .callback(move |sample| {
            let text = sample.payload().try_to_string().unwrap_or_default().into_owned();
            let _ = arrived.send((Instant::now(), text));
        })
        .wait()
        .unwrap();
    get(&other, "test/ops/api/state", None, None).expect("the second peer reads the state");
    // The subscription reaches the run before the calls below are made.
    let state = get(&session, "test/ops/api/state", None, None).expect("reading needs no token");
    assert!(state["drones"].is_array(), "{state}");

    let refused = get(&session, "test/ops/api/pause", None, None).unwrap_err();
    assert!(refused["error"].as_str().unwrap().contains("token"), "{refused}");
    let refused = get(&session, "test/ops/api/pause", None, Some("not-the-token")).unwrap_err();
    assert!(refused["error"].is_string(), "{refused}");
    let garbage = get(&session, "test/ops/api/leash", Some("{not json"), Some(&token)).unwrap_err();
    assert!(garbage["error"].is_string(), "{garbage}");
    let unknown = get(&session, "test/ops/api/launch", Some("{}"), Some(&token)).unwrap_err();
    assert!(unknown["error"].as_str().unwrap().contains("the calls are"), "{unknown}");

    let asked = Instant::now();
    assert!(get(&session, "test/ops/api/pause", None, Some(&token)).is_ok());
    let mut samples: Vec<(String, String, Duration)> = Vec::new();
    let mut resumed = false;
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let Ok(Some(sample)) = heard.recv_timeout(Duration::from_millis(100)) else {
            assert!(Instant::now() < deadline, "no mission_end on test/ops/events");
            continue;
        };
        let key = sample.key_expr().as_str().to_string();
        let text = sample.payload().try_to_string().unwrap().into_owned();
        let end = key == "test/ops/events" && text.contains(r#""event":"mission_end""#);
        samples.push((key, text, asked.elapsed()));
        if !resumed
            && samples.iter().any(|(_, t, _)| t.contains(r#""event":"operator","action":"pause""#))
        {
            std::thread::sleep(Duration::from_millis(500));
            assert!(get(&session, "test/ops/api/resume", None, Some(&token)).is_ok());
            resumed = true;
        }
        if end {
            break;
        }
    }
    // The state once more, after the end: the publisher sends it last.
    while let Ok(Some(sample)) = heard.recv_timeout(Duration::from_secs(2)) {
        let key = sample.key_expr().as_str().to_string();
        let text = sample.payload().try_to_string().unwrap().into_owned();
        let last = key == "test/ops/state";
        samples.push((key, text, asked.elapsed()));
        if last {
            break;
        }
    }
    assert_eq!(wait_at_most(&mut child, Duration::from_secs(20), "the run"), 0);
    let mut log = String::new();
    stderr.read_to_string(&mut log).unwrap();
    session.close().wait().unwrap();

    // What was published is what the trace file holds, line for line.
    let trace = std::fs::read_to_string(dir.join("t.jsonl")).unwrap();
    let lines: std::collections::HashSet<&str> = trace.lines().collect();
    for (key, text, _) in samples.iter().filter(|(k, _, _)| !k.ends_with("/state")) {
        assert!(lines.contains(text.as_str()), "{key}: {text} is not a line of the trace");
    }
    let on = |key: &str| samples.iter().filter(|(k, _, _)| k == key).count();
    assert!(on("test/ops/telemetry/a") >= 5 && on("test/ops/telemetry/b") >= 5);
    let last_state = samples.iter().rev().find(|(k, _, _)| k == "test/ops/state").expect("a state");
    let last_state: serde_json::Value = serde_json::from_str(&last_state.1).unwrap();
    assert_eq!(last_state["status"], "ok", "{last_state}");
    // The pause, asked of the run, is heard on the events key within a second.
    let (_, _, heard_after) = samples
        .iter()
        .find(|(_, t, _)| t.contains(r#""event":"operator","action":"pause""#))
        .expect("the pause");
    assert!(*heard_after < Duration::from_secs(1), "the pause was heard after {heard_after:?}");
    // The other station heard the same pause, within a second of the asking too.
    let pause = |text: &str| text.contains(r#""event":"operator","action":"pause""#);
    let (at, text) = other_heard
        .try_iter()
        .find(|(_, text)| pause(text))
        .expect("the other station heard the pause");
    assert!(at.duration_since(asked) < Duration::from_secs(1), "{:?}", at.duration_since(asked));
    assert!(samples.iter().any(|(_, t, _)| *t == text), "both heard the one pause: {text}");
    other.close().wait().unwrap();
    assert!(samples.iter().any(|(_, t, _)| t.contains(r#""event":"operator","action":"resume""#)));
    // Each refusal was logged for the operator.
    assert!(log.matches("test/ops/api/pause refused (401)").count() == 2, "{log}");
    assert!(log.contains("test/ops/api/leash refused (400)"), "{log}");
}

#[test]
fn without_zenoh_a_run_opens_no_socket() {
    let dir = scratch("zenoh_off");
    std::fs::write(dir.join("m.mission"), MISSION).unwrap();
    std::fs::write(dir.join("m.world.toml"), WORLD).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", "m.mission", "--speed", "10", "--quiet"])
        .current_dir(&dir)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("spawn");
    // Mid-flight: the sockets the process holds (the signal handler's pair of its own),
    // none of them TCP or UDP.
    std::thread::sleep(Duration::from_millis(1500));
    let pid = child.id();
    let fds = std::fs::read_dir(format!("/proc/{pid}/fd")).expect("/proc");
    let sockets: Vec<String> = fds
        .filter_map(|fd| std::fs::read_link(fd.ok()?.path()).ok())
        .filter_map(|target| {
            let inode = target.to_str()?.strip_prefix("socket:[")?.strip_suffix(']')?;
            Some(inode.to_string())
        })
        .collect();
    let network: Vec<String> = ["tcp", "tcp6", "udp", "udp6"]
        .iter()
        .filter_map(|table| std::fs::read_to_string(format!("/proc/{pid}/net/{table}")).ok())
        .flat_map(|table| {
            // The inode is the tenth column of each line after the header.
            table
                .lines()
                .skip(1)
                .filter_map(|l| l.split_whitespace().nth(9).map(String::from))
                .collect::<Vec<_>>()
        })
        .collect();
    assert!(child.try_wait().unwrap().is_none(), "the run was still flying");
    let open: Vec<&String> = sockets.iter().filter(|s| network.contains(s)).collect();
    assert!(open.is_empty(), "network sockets {open:?} among {sockets:?}");
    assert_eq!(wait_at_most(&mut child, Duration::from_secs(30), "the run"), 0);
}

/// A certificate authority of the test's own, and a certificate for `localhost` it signed:
/// `(ca.pem, server.pem, server.key)`, written into `dir`.
fn certificates(dir: &std::path::Path) -> (String, String, String) {
    use rcgen::{BasicConstraints, CertificateParams, IsCa, Issuer, KeyPair};
    let ca_key = KeyPair::generate().unwrap();
    let mut ca_params = CertificateParams::new(Vec::<String>::new()).unwrap();
    ca_params.is_ca = IsCa::Ca(BasicConstraints::Unconstrained);
    let ca = ca_params.self_signed(&ca_key).unwrap();
    let issuer = Issuer::new(ca_params, ca_key);
    let key = KeyPair::generate().unwrap();
    let server = CertificateParams::new(vec!["localhost".to_string()])
        .unwrap()
        .signed_by(&key, &issuer)
        .unwrap();
    let write = |name: &str, text: String| {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path.display().to_string()
    };
    (
        write("ca.pem", ca.pem()),
        write("server.pem", server.pem()),
        write("server.key", key.serialize_pem()),
    )
}

/// With TLS on (docs/SECURITY.md): the run listens on a `tls/` endpoint with its
/// certificate; a peer that trusts the authority that signed it watches the run, and one
/// that does not cannot join.
#[test]
fn over_tls_only_a_peer_that_trusts_the_certificate_joins() {
    let dir = scratch("zenoh_tls");
    let (ca, cert, key) = certificates(&dir);
    let port = free_port();
    let no_scouting = "scouting: { multicast: { enabled: false }, gossip: { enabled: false } }";
    let listen = format!(
        r#"{{ mode: "peer", listen: {{ endpoints: ["tls/localhost:{port}"] }}, {no_scouting},
            transport: {{ link: {{ tls: {{ listen_certificate: "{cert}", listen_private_key: "{key}" }} }} }} }}"#
    );
    let (mut child, _stderr, _) = on_zenoh(&dir, &listen, "tls/ops");

    let client = |ca: Option<&str>| {
        let tls = ca.map_or(String::new(), |ca| {
            format!(r#", transport: {{ link: {{ tls: {{ root_ca_certificate: "{ca}" }} }} }}"#)
        });
        let config = format!(
            r#"{{ mode: "peer", connect: {{ endpoints: ["tls/localhost:{port}"], timeout_ms: 3000, exit_on_failure: true }},
                {no_scouting}{tls} }}"#
        );
        zenoh::open(zenoh::Config::from_json5(&config).unwrap()).wait()
    };
    // The authority's certificate is not one the system trusts: no TLS session.
    match client(None) {
        Ok(_) => panic!("a peer that does not trust the certificate joined"),
        Err(e) => eprintln!("refused, as it should be: {e}"),
    }
    let session = client(Some(&ca)).expect("a peer that trusts the certificate joins");
    let state = get(&session, "tls/ops/api/state", None, None).expect("the state over TLS");
    assert!(state["drones"].is_array(), "{state}");
    let heard = session.declare_subscriber("tls/ops/telemetry/*").wait().unwrap();
    let sample = heard.recv_timeout(Duration::from_secs(10)).unwrap().expect("telemetry over TLS");
    assert!(sample.payload().try_to_string().unwrap().contains(r#""event":"telemetry""#));
    session.close().wait().unwrap();
    assert_eq!(wait_at_most(&mut child, Duration::from_secs(30), "the run"), 0);
}

/// `aviary ctl --zenoh` reads and steers a run on Zenoh as `--url` does over HTTP: the
/// state's table, a refusal without the token (exit 1, with the status), a pause and a
/// resume, and the events until the mission ends.
#[test]
fn ctl_steers_a_run_on_zenoh_as_it_does_over_http() {
    let dir = scratch("zenoh_ctl");
    let port = free_port();
    let (mut child, _stderr, token) = on_zenoh(&dir, &peer("listen", port), "ctl/ops");
    std::fs::write(dir.join("client.json5"), peer("connect", port)).unwrap();
    // An AVIARY_URL in the environment does not stand in the way of --zenoh.
    let ctl = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_aviary"))
            .args(["ctl", "--zenoh", "client.json5", "--zenoh-prefix", "ctl/ops"])
            .args(args)
            .env("AVIARY_URL", "http://127.0.0.1:9")
            .current_dir(&dir)
            .output()
            .expect("run aviary ctl");
        let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
        (out.status.code().unwrap_or(-1), text(&out.stdout), text(&out.stderr))
    };
    let events = {
        let dir = dir.clone();
        std::thread::spawn(move || {
            common::aviary(
                &["ctl", "--zenoh", "client.json5", "--zenoh-prefix", "ctl/ops", "events"],
                &dir,
            )
        })
    };
    // The stream's session joins before the pause is asked.
    std::thread::sleep(Duration::from_secs(1));
    let (code, table, err) = ctl(&["state"]);
    assert_eq!(code, 0, "{err}");
    assert!(table.starts_with("mission "), "{table}");
    let (code, _, err) = ctl(&["pause"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("refused (401)"), "{err}");
    assert_eq!(ctl(&["--token", &token, "pause"]).0, 0);
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(ctl(&["--token", &token, "resume"]).0, 0);
    assert_eq!(wait_at_most(&mut child, Duration::from_secs(60), "the run"), 0);
    let (code, streamed, err) = events.join().unwrap();
    assert_eq!(code, 0, "{err}");
    assert!(streamed.lines().any(|l| l.contains(r#""event":"operator","action":"pause""#)));
    assert!(streamed.lines().last().is_some_and(|l| l.contains(r#""event":"mission_end""#)));
    // Without a prefix, or with one that is no key, ctl says what to write.
    let (code, _, err) =
        common::aviary(&["ctl", "--zenoh", "--zenoh-prefix", "a/*", "state"], &dir);
    assert_eq!(code, 2);
    assert!(err.contains("cannot be a Zenoh key prefix"), "{err}");
    // A configuration that is not there: said with its name, before anything flies.
    let (code, _, err) = common::aviary(&["run", "m.mission", "--zenoh", "nope.json5"], &dir);
    assert_eq!(code, 2);
    assert!(err.contains("cannot read the Zenoh configuration nope.json5: No such file"), "{err}");
    assert!(!err.contains(".rs:"), "no source location of Zenoh's: {err}");
}
