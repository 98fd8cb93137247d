//! `aviary ctl`: the command-line client of the operator API that `aviary run --serve`
//! starts (docs/OPERATOR_API.md).

use aviary_syntax::ast::Unit;
use clap::Subcommand;
use serde_json::{json, Value};

#[derive(Subcommand)]
pub enum CtlCommand {
    /// Print the mission's state: blocks, activities with tags, drones
    State,
    /// Print every event as it happens, one JSON object per line
    Events,
    /// A leash on a running activity: `leash FlyCircle-C1 PAUSE`, `leash FlyCircle-C1 Widen radius=200m`
    Leash { activity: String, action: String, args: Vec<String> },
    /// Raise a signal the mission hears: `signal Go`
    Signal { name: String, values: Vec<String> },
    /// Hold every drone where it is
    Pause,
    /// Go on after `pause`
    Resume,
    /// End the mission; the fleet returns home
    Abort,
}

pub fn run(url: &str, token: Option<&str>, command: CtlCommand) -> u8 {
    let base = url.trim_end_matches('/');
    let result = match command {
        CtlCommand::State => get(&format!("{base}/api/state")),
        CtlCommand::Events => return events(base),
        CtlCommand::Leash { activity, action, args } => {
            let mut named = serde_json::Map::new();
            for a in &args {
                let Some((k, v)) = a.split_once('=') else {
                    eprintln!("aviary: `{a}` is not `name=value`");
                    return 2;
                };
                named.insert(k.to_string(), value(v));
            }
            post(base, "leash", token, json!({ "activity": activity, "action": action, "args": named }))
        }
        CtlCommand::Signal { name, values } => post(base, "signal", token, json!({ "name": name, "args": values.iter().map(|v| value(v)).collect::<Vec<_>>() })),
        CtlCommand::Pause => post(base, "pause", token, json!({})),
        CtlCommand::Resume => post(base, "resume", token, json!({})),
        CtlCommand::Abort => post(base, "abort", token, json!({})),
    };
    match result {
        Ok((200, body)) => {
            outln!("{body}");
            0
        }
        Ok((status, body)) => {
            let why = serde_json::from_str::<Value>(&body).ok().and_then(|v| v["error"].as_str().map(str::to_string)).unwrap_or(body);
            eprintln!("aviary: refused ({status}): {why}");
            1
        }
        Err(e) => {
            eprintln!("aviary: cannot reach the operator API at {base}: {e}");
            2
        }
    }
}

fn agent() -> ureq::Agent {
    ureq::Agent::config_builder().http_status_as_error(false).build().into()
}

fn get(url: &str) -> Result<(u16, String), String> {
    let mut response = agent().get(url).call().map_err(|e| e.to_string())?;
    let status = response.status().as_u16();
    let body = response.body_mut().read_to_string().map_err(|e| e.to_string())?;
    Ok((status, body))
}

fn post(base: &str, call: &str, token: Option<&str>, body: Value) -> Result<(u16, String), String> {
    let mut request = agent().post(format!("{base}/api/{call}")).header("Content-Type", "application/json");
    if let Some(token) = token {
        request = request.header("Authorization", format!("Bearer {token}"));
    }
    let mut response = request.send(body.to_string()).map_err(|e| e.to_string())?;
    let status = response.status().as_u16();
    let text = response.body_mut().read_to_string().map_err(|e| e.to_string())?;
    Ok((status, text))
}

/// Prints each event as a JSON line until the mission ends.
fn events(base: &str) -> u8 {
    let ws = format!("{}/api/events", base.replacen("http://", "ws://", 1));
    let (mut socket, _) = match tungstenite::connect(ws.as_str()) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("aviary: cannot open the event stream at {ws}: {e}");
            return 2;
        }
    };
    loop {
        match socket.read() {
            Ok(tungstenite::Message::Text(text)) => {
                outln!("{text}");
                if crate::out::closed() {
                    return 0;
                }
            }
            Ok(tungstenite::Message::Close(_)) | Err(_) => return 0,
            Ok(_) => {}
        }
    }
}

/// `40m` is 40 (SI), `2min` is 120, `(1, 2)`-free forms only: a number, a quantity, or a symbol.
fn value(text: &str) -> Value {
    if let Ok(n) = text.parse::<f64>() {
        return json!(n);
    }
    let split = text.find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-')).unwrap_or(text.len());
    if let (Ok(n), Some(unit)) = (text[..split].parse::<f64>(), Unit::parse(&text[split..])) {
        return json!(n * unit.to_si());
    }
    json!(text)
}
