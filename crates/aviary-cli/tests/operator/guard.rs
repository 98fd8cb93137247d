//! Who may call the operator API: Host and Origin on every request and upgrade (no DNS
//! rebinding, no other site's page), the token for everything beyond loopback, and the
//! HTTP details (scheme case, token before body, every error JSON).

use std::io::BufRead;

use super::serve::{bearer, http, serve, upgrade};
use super::{MISSION, WORLD};
use crate::common::{aviary, scratch};

#[test]
fn host_and_origin_must_be_this_server() {
    let dir = scratch("operator_host_origin");
    let run = serve(&dir, MISSION, WORLD, "0", &["--allow-host", "ops.example.org"]);
    let port = run.port;
    // DNS rebinding: a page of evil.example whose name now resolves to 127.0.0.1.
    let a = http(&run, "GET", "/api/state", &[("Host", "evil.example")], "");
    assert_eq!(a.status, 403, "{}", a.body);
    assert!(a.error().contains("Host `evil.example` is not this server"), "{}", a.body);
    let a = http(&run, "GET", "/api/state", &[("Host", &format!("localhost:{}", port + 1))], "");
    assert_eq!(a.status, 403, "another port is another server");
    for host in [
        format!("localhost:{port}"),
        format!("127.0.0.1:{port}"),
        format!("[::1]:{port}"),
        "ops.example.org".into(),
        "OPS.example.org:443".into(),
    ] {
        assert_eq!(
            http(&run, "GET", "/api/state", &[("Host", &host)], "").status,
            200,
            "Host {host}"
        );
    }
    // Any page the operator opens may try the event stream: WebSockets ignore the same-origin rule.
    let a = upgrade(&run, &[("Origin", "http://evil.example")]);
    assert_eq!(a.status, 403, "{}", a.head);
    assert!(
        a.error().contains("Origin `http://evil.example` may not call this server"),
        "{}",
        a.body
    );
    for origin in [
        "null",
        "https://127.0.0.1",
        &format!("https://localhost:{port}"),
        &format!("http://localhost:{port}.evil.example"),
    ] {
        assert_eq!(upgrade(&run, &[("Origin", origin)]).status, 403, "Origin {origin}");
    }
    let a = http(
        &run,
        "POST",
        "/api/pause",
        &[("Origin", "http://evil.example"), ("Authorization", &bearer(&run))],
        "",
    );
    assert_eq!(a.status, 403, "a control call from another site is refused even with the token");
    assert_eq!(
        upgrade(&run, &[("Origin", &format!("http://localhost:{port}"))]).status,
        101,
        "the same origin may stream"
    );
    assert_eq!(
        upgrade(&run, &[("Origin", "https://ops.example.org")]).status,
        101,
        "an allowed host, through its proxy"
    );
    assert_eq!(upgrade(&run, &[]).status, 101, "a client that is no browser sends no Origin");
    let (code, out, _) = aviary(&["ctl", "--url", &run.url, "state", "--json"], &dir);
    assert_eq!(code, 0, "aviary ctl sends the server's own Host");
    assert!(out.contains("\"drones\""));
}

#[test]
fn beyond_loopback_everything_needs_the_token_and_the_run_warns() {
    let dir = scratch("operator_beyond_loopback");
    let mut run = serve(&dir, MISSION, WORLD, "0.0.0.0:0", &[]);
    assert!(
        run.url.starts_with("http://127.0.0.1:"),
        "the printed URL is one to connect to: {}",
        run.url
    );
    let mut warning = String::new();
    run.stderr.read_line(&mut warning).unwrap();
    assert!(
        warning.starts_with("aviary: warning: the operator API listens on 0.0.0.0:"),
        "{warning}"
    );
    assert!(
        warning.contains("TLS reverse proxy") && warning.contains("needs the token"),
        "{warning}"
    );
    assert!(!warning.contains(&run.token), "the warning does not repeat the token");

    let a = http(&run, "GET", "/api/state", &[], "");
    assert_eq!(a.status, 401, "{}", a.body);
    assert!(a.head.to_ascii_lowercase().contains("www-authenticate: bearer"));
    assert!(a.error().contains("reading needs the token too"), "{}", a.body);
    assert_eq!(
        http(&run, "GET", "/api/state", &[("Authorization", &bearer(&run))], "").status,
        200
    );
    assert_eq!(upgrade(&run, &[]).status, 401, "the event stream needs it too");
    assert_eq!(upgrade(&run, &[("Authorization", &bearer(&run))]).status, 101);
    // A browser cannot set Authorization on a WebSocket: it offers the token as a subprotocol.
    let offered = format!("aviary, aviary.bearer.{}", run.token);
    let a = upgrade(&run, &[("Sec-WebSocket-Protocol", &offered)]);
    assert_eq!(a.status, 101, "{}", a.head);
    assert!(
        a.head.to_ascii_lowercase().contains("sec-websocket-protocol: aviary\r\n"),
        "the server picks `aviary`, never echoes the token: {}",
        a.head
    );
    assert_eq!(
        upgrade(&run, &[("Sec-WebSocket-Protocol", "aviary, aviary.bearer.0000")]).status,
        401
    );
    // The machine's other addresses answer too (an IP cannot be rebound); names need --allow-host.
    let ip_host = format!("192.0.2.7:{}", run.port);
    assert_eq!(
        http(
            &run,
            "GET",
            "/api/state",
            &[("Host", &ip_host), ("Authorization", &bearer(&run))],
            ""
        )
        .status,
        200
    );
    assert_eq!(
        http(
            &run,
            "GET",
            "/api/state",
            &[("Host", "drone-ops.lan"), ("Authorization", &bearer(&run))],
            ""
        )
        .status,
        403
    );

    let (code, _, err) = aviary(&["ctl", "--url", &run.url, "state"], &dir);
    assert_eq!((code, err.contains("refused (401)")), (1, true), "{err}");
    let (code, out, err) =
        aviary(&["ctl", "--url", &run.url, "--token", &run.token, "state"], &dir);
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("mission ") && out.contains("blocks running:"), "{out}");
    let (code, _, err) = aviary(&["ctl", "--url", &run.url, "events"], &dir);
    assert_eq!((code, err.contains("refused (401)")), (1, true), "{err}");
}

#[test]
fn the_token_comes_before_the_body_and_every_error_is_json() {
    let dir = scratch("operator_http_details");
    let run = serve(&dir, MISSION, WORLD, "0", &[]);
    let json = ("Content-Type", "application/json");
    // Without the token, a broken body says nothing about itself.
    let a = http(&run, "POST", "/api/leash", &[json], "{\"activity\": ");
    assert_eq!(a.status, 401, "{}", a.body);
    let a =
        http(&run, "POST", "/api/signal", &[("Authorization", "Basic dXNlcjpwYXNz"), json], "[]");
    assert_eq!(a.status, 401, "another scheme is no token");
    let lower = format!("bearer {}", run.token);
    let upper = format!("BEARER  {}", run.token);
    let a = http(&run, "POST", "/api/leash", &[("Authorization", &lower), json], "{\"activity\": ");
    assert_eq!(a.status, 400, "`bearer` is the same scheme: {}", a.body);
    assert!(a.error().starts_with("the body is not JSON"), "{}", a.body);
    let a = http(&run, "POST", "/api/signal", &[("Authorization", &upper), json], "[1]");
    assert_eq!(
        (a.status, a.error()),
        (400, "the body must be a JSON object, not an array".to_string())
    );
    let a = http(&run, "POST", "/api/signal", &[("Authorization", &lower)], "{\"name\": \"Go\"}");
    assert_eq!(a.status, 415, "{}", a.body);
    assert!(a.error().contains("Content-Type: application/json"));
    let big = format!("{{\"name\": \"{}\"}}", "x".repeat(100_000));
    let a = http(&run, "POST", "/api/signal", &[("Authorization", &lower), json], &big);
    assert_eq!((a.status, a.error()), (413, "the body is larger than 64 KiB".to_string()));
    let a = http(&run, "GET", "/api/nothing", &[], "");
    assert_eq!(a.status, 404);
    a.error();
    let a = http(&run, "DELETE", "/api/state", &[], "");
    assert_eq!(a.status, 405);
    a.error();
    let a = http(&run, "GET", "/api/events", &[], "");
    assert!(
        a.status >= 400 && a.error().contains("WebSocket"),
        "a plain GET of the stream: {} {}",
        a.status,
        a.body
    );
}
