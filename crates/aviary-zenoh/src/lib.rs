//! A run on Zenoh (`aviary run --zenoh`, docs/DISTRIBUTED.md): every trace event, each
//! drone's telemetry and the operator state are published under one key prefix, and the
//! operator API is answered as queryables, so that machines other than the one flying
//! the mission can watch and steer it.
//!
//! Invariants:
//! - The bridge adds no second operator API. A query is turned into the HTTP request it
//!   stands for and answered by the run's own router (`aviary_server`), with its checks
//!   of the token, the names and the values; a Zenoh reply is that response.
//! - What is published is the trace's own lines, byte for byte, and the state document
//!   of `GET /api/state`: a subscriber reads what a trace file or the HTTP API gives.
//! - It runs on threads of its own in real time, beside the engine: the engine only
//!   publishes to the run's `Feed`, which never waits for a slow peer.
//! - Without `--zenoh` nothing here runs and no socket is opened.
//! - An agent ([`agent`]) and a mission's [`Agents`] carry a vehicle's MAVLink frames
//!   unchanged, one frame a sample: neither reads what it carries, so signing holds end
//!   to end and the link's loss is seen as a MAVLink link's is, by its silence.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

pub mod agent;
mod carrier;
mod client;
mod frames;
mod keys;
mod publish;
mod queries;
pub mod remote;
pub mod ros;

pub use carrier::Agents;
pub use client::Client;
pub use keys::{AgentKeys, Keys};
pub use zenoh::Session;

use std::net::SocketAddr;
use std::path::Path;
use std::thread::JoinHandle;
use std::time::Duration;

use zenoh::Wait;

/// The session's configuration: Zenoh's JSON5 file (its own format,
/// <https://zenoh.io/docs/manual/configuration/>), or Zenoh's defaults (a peer that finds
/// others by multicast scouting and listens on a free TCP port).
pub fn config(file: Option<&Path>) -> Result<zenoh::Config, String> {
    match file {
        Some(path) => zenoh::Config::from_file(path)
            .map_err(|e| {
                format!(
                    "cannot read the Zenoh configuration {}: {} (Zenoh's JSON5 format: https://zenoh.io/docs/manual/configuration/)",
                    path.display(),
                    reason(&e)
                )
            }),
        None => Ok(zenoh::Config::default()),
    }
}

/// The run's operator API as the bridge reaches it: the router, the address the router
/// believes it is bound at (its `Host`), and the feed of events; and what a station shows
/// of the mission, `{"mission": NAME, "tree": ..., "map": ...}` (`PREFIX/api/mission`).
pub struct Api {
    pub router: axum::Router,
    pub bound: SocketAddr,
    pub feed: aviary_server::Feed,
    pub mission: serde_json::Value,
    /// Also for ROS 2 on rmw_zenoh (`--ros`).
    pub ros: Option<ros::Ros>,
}

/// Opens a session with `config`.
pub fn open(config: zenoh::Config) -> Result<zenoh::Session, String> {
    zenoh::open(config).wait().map_err(|e| format!("cannot open a Zenoh session: {}", reason(&e)))
}

/// A run on Zenoh, until [`Bridge::finish`].
pub struct Bridge {
    session: zenoh::Session,
    /// The publishers, each until it has sent `mission_end`.
    publishers: Vec<JoinHandle<()>>,
}

impl Bridge {
    /// Starts publishing, on `session`, what `api.feed` carries and answering queries
    /// under `keys`. Call before the run's first event.
    pub fn start(session: zenoh::Session, keys: Keys, api: Api) -> Result<Bridge, String> {
        let lines = api.feed.subscribe();
        let mut publishers =
            vec![publish::start(session.clone(), keys.clone(), lines, api.feed.clone())?];
        if let Some(ros) = api.ros {
            publishers.push(ros::start(session.clone(), api.feed.subscribe(), ros)?);
        }
        let mission = serde_json::to_vec(&api.mission).map_err(|e| e.to_string())?;
        queries::start(session.clone(), keys, api.router, api.bound, (mission, api.feed))?;
        Ok(Bridge { session, publishers })
    }

    /// After `mission_end`: waits (at most `limit`) until the publisher has sent it and
    /// the last state, then closes the session, so that no peer misses how the mission
    /// ended.
    pub fn finish(self, limit: Duration) {
        let start = std::time::Instant::now();
        while self.publishers.iter().any(|p| !p.is_finished()) && start.elapsed() < limit {
            std::thread::sleep(Duration::from_millis(10));
        }
        if let Err(e) = self.session.close().wait() {
            eprintln!("aviary: zenoh: the session did not close cleanly: {e}");
        }
    }
}

/// Each line `lines` carries, to `each`, until `mission_end` (given to `each` too) or
/// the feed's end. Lines missed by falling behind are said, naming `who`.
pub(crate) fn follow(
    mut lines: tokio::sync::broadcast::Receiver<std::sync::Arc<aviary_server::Line>>,
    who: &str,
    mut each: impl FnMut(&aviary_server::Line),
) {
    use tokio::sync::broadcast::error::RecvError;
    loop {
        match lines.blocking_recv() {
            Ok(line) => {
                each(&line);
                if line.end {
                    return;
                }
            }
            Err(RecvError::Lagged(missed)) => {
                eprintln!("aviary: {who} fell behind and {missed} events were not published")
            }
            Err(RecvError::Closed) => return,
        }
    }
}

/// A Zenoh error's reason, without the source location Zenoh appends
/// (` at /.../zenoh-config-1.10.2/src/lib.rs:1507.`), which says nothing to an operator.
pub(crate) fn reason(e: &dyn std::fmt::Display) -> String {
    let text = e.to_string();
    match text.rfind(" at ") {
        Some(i)
            if text[i..].trim_end_matches('.').rsplit_once(':').is_some_and(|(path, line)| {
                path.ends_with(".rs")
                    && !line.is_empty()
                    && line.bytes().all(|b| b.is_ascii_digit())
            }) =>
        {
            text[..i].to_string()
        }
        _ => text,
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_zenoh_error_is_said_without_its_source_location() {
        let e = "No such file or directory (os error 2) at /root/.cargo/registry/src/x/zenoh-config-1.10.2/src/lib.rs:1507.";
        assert_eq!(super::reason(&e), "No such file or directory (os error 2)");
        assert_eq!(super::reason(&"meet at noon"), "meet at noon");
    }
}
