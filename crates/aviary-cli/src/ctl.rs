//! `aviary ctl`: the command-line client of the operator API that `aviary run --serve`
//! starts (docs/OPERATOR_API.md), or that `aviary run --zenoh` answers on Zenoh
//! (docs/DISTRIBUTED.md): the same calls, the same answers.

use aviary_api::operator::OperatorState;
use aviary_server::requests::{Argument, DroneRequest, DroneVerb, LeashRequest, SignalRequest};
use aviary_syntax::ast::{Expr, ExprKind};
use clap::{Subcommand, ValueEnum};
use serde_json::Value;

#[derive(Subcommand)]
pub enum CtlCommand {
    /// Print the mission's state: blocks, activities with their leashes, drones
    State {
        /// Print the operator API's JSON document instead of the table
        #[arg(long)]
        json: bool,
    },
    /// Print every event as it happens, one JSON object per line
    Events,
    /// A leash on a running activity: `leash FlyCircle-C1 PAUSE`, `leash FlyCircle-C1 Widen radius=200m`
    /// (values as the language writes them: 200m, 2min, (100, 50), Body, "text")
    Leash { activity: String, action: String, args: Vec<String> },
    /// Raise a signal the mission declares with OPERATOR SIGNAL: `signal Go`, `signal Found
    /// (120, 40) Body` (the state lists them as `operator_signals`)
    Signal { name: String, values: Vec<String> },
    /// Steer one drone: `drone scout1 hold` (its activities wait where they are), `resume`,
    /// `home` or `land` (its activities are aborted and it leaves the mission, flying home
    /// or landing where it is)
    Drone { name: String, action: DroneCtl },
    /// Hold every drone where it is
    Pause,
    /// Go on after `pause`
    Resume,
    /// End the mission; the fleet returns home
    Abort,
}

/// What `aviary ctl drone NAME ACTION` tells a drone.
#[derive(Clone, Copy, ValueEnum)]
pub enum DroneCtl {
    /// Hold its activities where they are
    Hold,
    /// Let them go on after `hold`
    Resume,
    /// Abort its activities and send it home, out of the mission
    Home,
    /// Abort its activities and land it where it is, out of the mission
    Land,
}

impl DroneCtl {
    /// As the operator API takes it.
    fn verb(self) -> DroneVerb {
        match self {
            DroneCtl::Hold => DroneVerb::Hold,
            DroneCtl::Resume => DroneVerb::Resume,
            DroneCtl::Home => DroneVerb::Home,
            DroneCtl::Land => DroneVerb::Land,
        }
    }
}

/// Where the operator API is.
pub enum Reach {
    /// `--url`: the HTTP server's address.
    Http(String),
    /// `--zenoh`: a run on Zenoh.
    Zenoh(aviary_zenoh::Client),
}

impl Reach {
    /// The operator API's `call` with its JSON body (none for `state`): the HTTP status
    /// and the answer.
    fn call(
        &self,
        call: &str,
        token: Option<&str>,
        body: Option<String>,
    ) -> Result<(u16, String), String> {
        match self {
            Reach::Http(base) => match body {
                None => get(&format!("{base}/api/{call}"), token),
                Some(body) => post(base, call, token, body),
            },
            Reach::Zenoh(client) => client.call(call, body, token),
        }
    }

    /// Where, for messages.
    fn place(&self) -> String {
        match self {
            Reach::Http(base) => base.clone(),
            Reach::Zenoh(client) => format!("{} on Zenoh", client.keys().api()),
        }
    }
}

/// A control call's body, as JSON.
fn control(
    reach: &Reach,
    call: &str,
    token: Option<&str>,
    body: &impl serde::Serialize,
) -> Result<(u16, String), String> {
    let body = serde_json::to_string(body).map_err(|e| e.to_string())?;
    reach.call(call, token, Some(body))
}

pub fn run(reach: &Reach, token: Option<&str>, command: CtlCommand) -> u8 {
    let base = reach.place();
    let result = match command {
        CtlCommand::State { json } => {
            let got = reach.call("state", token, None);
            match (&got, json) {
                (Ok((200, body)), false) => match serde_json::from_str::<OperatorState>(body) {
                    Ok(state) => {
                        out!("{}", crate::ctl_table::state_table(&state));
                        return 0;
                    }
                    Err(e) => {
                        eprintln!("aviary: the state from {base} is not the state document ({e})");
                        return 2;
                    }
                },
                _ => got,
            }
        }
        CtlCommand::Events => {
            return match reach {
                Reach::Http(base) => events(base, token),
                Reach::Zenoh(client) => {
                    match client.events(|line| {
                        outln!("{line}");
                        !crate::out::closed()
                    }) {
                        Ok(()) => 0,
                        Err(why) => {
                            eprintln!("aviary: {why}");
                            2
                        }
                    }
                }
            }
        }
        CtlCommand::Leash { activity, action, args } => {
            let mut named = std::collections::BTreeMap::new();
            for a in &args {
                let Some((k, v)) = a.split_once('=') else {
                    eprintln!("aviary: `{a}` is not `name=value`");
                    return 2;
                };
                match value(v) {
                    Ok(v) => named.insert(k.to_string(), v),
                    Err(why) => return refuse_value(v, &why),
                };
            }
            let args = (!named.is_empty()).then_some(named);
            let request = LeashRequest {
                activity: Some(activity),
                capability: None,
                tag: None,
                action,
                args,
            };
            control(reach, "leash", token, &request)
        }
        CtlCommand::Signal { name, values } => {
            let mut args = Vec::new();
            for v in &values {
                match value(v) {
                    Ok(v) => args.push(v),
                    Err(why) => return refuse_value(v, &why),
                }
            }
            control(reach, "signal", token, &SignalRequest { name, args: Some(args) })
        }
        CtlCommand::Drone { name, action } => {
            control(reach, "drone", token, &DroneRequest { drone: name, action: action.verb() })
        }
        CtlCommand::Pause => control(reach, "pause", token, &NoBody {}),
        CtlCommand::Resume => control(reach, "resume", token, &NoBody {}),
        CtlCommand::Abort => control(reach, "abort", token, &NoBody {}),
    };
    match result {
        Ok((200, body)) => {
            outln!("{body}");
            0
        }
        Ok((status, body)) => {
            let why = serde_json::from_str::<Value>(&body)
                .ok()
                .and_then(|v| v["error"].as_str().map(str::to_string))
                .unwrap_or(body);
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

fn get(url: &str, token: Option<&str>) -> Result<(u16, String), String> {
    let mut request = agent().get(url);
    // Reading needs the token only when the server is reachable beyond its machine;
    // sending it whenever it is known costs nothing.
    if let Some(token) = token {
        request = request.header("Authorization", format!("Bearer {token}"));
    }
    let mut response = request.call().map_err(|e| e.to_string())?;
    let status = response.status().as_u16();
    let body = response.body_mut().read_to_string().map_err(|e| e.to_string())?;
    Ok((status, body))
}

/// The body of a control call that takes none: `{}`.
#[derive(serde::Serialize)]
struct NoBody {}

fn post(
    base: &str,
    call: &str,
    token: Option<&str>,
    body: String,
) -> Result<(u16, String), String> {
    let mut request =
        agent().post(format!("{base}/api/{call}")).header("Content-Type", "application/json");
    if let Some(token) = token {
        request = request.header("Authorization", format!("Bearer {token}"));
    }
    let mut response = request.send(body).map_err(|e| e.to_string())?;
    let status = response.status().as_u16();
    let text = response.body_mut().read_to_string().map_err(|e| e.to_string())?;
    Ok((status, text))
}

/// Prints each event as a JSON line until the mission ends.
fn events(base: &str, token: Option<&str>) -> u8 {
    use tungstenite::client::IntoClientRequest;
    let ws = format!("{}/api/events", base.replacen("http://", "ws://", 1));
    let mut request = match ws.as_str().into_client_request() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("aviary: `{ws}` is not an address for the event stream: {e}");
            return 2;
        }
    };
    if let Some(Ok(value)) = token.map(|t| format!("Bearer {t}").parse()) {
        request.headers_mut().insert("Authorization", value);
    }
    let (mut socket, _) = match tungstenite::connect(request) {
        Ok(s) => s,
        Err(tungstenite::Error::Http(response)) => {
            let body = response.body().as_deref().map(String::from_utf8_lossy).unwrap_or_default();
            let why = serde_json::from_str::<Value>(&body)
                .ok()
                .and_then(|v| v["error"].as_str().map(str::to_string))
                .unwrap_or(body.into_owned());
            eprintln!("aviary: refused ({}): {why}", response.status().as_u16());
            return 1;
        }
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

fn refuse_value(text: &str, why: &str) -> u8 {
    eprintln!("aviary: cannot read `{text}` as a value: {why}");
    eprintln!("  write a number with its unit (200m, 2min, 5m/s, 25%), a position (100, 50), (100, 50, 20m) or GEO(47.45, 13.1), a name (Body), or a string in quotes");
    2
}

/// A value read by the language's rules (`aviary_syntax::parse_value`), as the operator
/// API takes it: a number keeps its unit (`{"number": 10, "unit": "s"}`), so that the
/// server can refuse `10s` where a length is expected; a position is `[x, y(, z)]` in
/// metres, or `{"lat", "lon"(, "alt")}` for `GEO(...)`; a name or a string is a string.
fn value(text: &str) -> Result<Argument, String> {
    let expr = aviary_syntax::parse_value(text)
        .map_err(|d| d.first().map(|d| d.message.clone()).unwrap_or_default())?;
    argument(&expr)
}

fn argument(expr: &Expr) -> Result<Argument, String> {
    match &expr.kind {
        ExprKind::Number { value, unit, .. } => Ok(Argument::number(*value, *unit)),
        ExprKind::String(s) => Ok(Argument::word(s)),
        ExprKind::Name(id) => Ok(Argument::word(&id.name)),
        ExprKind::Bool(b) => Ok(Argument::truth(*b)),
        ExprKind::Paren(inner) => argument(inner),
        ExprKind::Coordinates(parts) => {
            let mut metres = Vec::new();
            for p in parts {
                match &p.kind {
                    // A coordinate is a number of metres, with or without its unit (as the checker reads it).
                    ExprKind::Number { value, unit: None, .. } => metres.push(*value),
                    ExprKind::Number { value, unit: Some(u), .. }
                        if matches!(
                            u,
                            aviary_syntax::ast::Unit::Metre | aviary_syntax::ast::Unit::Kilometre
                        ) =>
                    {
                        metres.push(value * u.to_si())
                    }
                    _ => return Err("a coordinate is a number of metres".into()),
                }
            }
            Ok(Argument::metres(&metres))
        }
        // GEO(lat, lon[, alt]): the server places it about the world's origin.
        ExprKind::Geo(parts) => {
            let mut n = Vec::new();
            for p in parts {
                match &p.kind {
                    ExprKind::Number { value, unit: None, .. } => n.push(*value),
                    ExprKind::Number { value, unit: Some(aviary_syntax::ast::Unit::Metre), .. }
                        if n.len() == 2 =>
                    {
                        n.push(*value)
                    }
                    _ => return Err("GEO takes degrees of latitude and longitude, and an altitude in metres above sea level: GEO(47.45, 13.1) or GEO(47.45, 13.1, 520)".into()),
                }
            }
            match n[..] {
                [lat, lon] => Ok(Argument::geo(lat, lon, None)),
                [lat, lon, alt] => Ok(Argument::geo(lat, lon, Some(alt))),
                _ => Err("GEO takes a latitude and a longitude, and an altitude if the height matters: GEO(47.45, 13.1)".into()),
            }
        }
        _ => Err(
            "only a number, a position ((x, y) or GEO(lat, lon)), a name or a string can be sent"
                .into(),
        ),
    }
}
