//! The client's side (`aviary ctl --zenoh`): the operator API of a run on Zenoh, reached
//! through its queryables, and its events through its keys.

use std::time::Duration;

use zenoh::Wait;

use crate::Keys;

/// How long a call waits for the run's answer.
const ANSWER_WITHIN: Duration = Duration::from_secs(10);

/// A session that reaches the run under `keys`.
pub struct Client {
    session: zenoh::Session,
    keys: Keys,
}

impl Client {
    /// The run's keys.
    pub fn keys(&self) -> &Keys {
        &self.keys
    }

    /// The session it reaches the run on.
    pub(crate) fn session(&self) -> &zenoh::Session {
        &self.session
    }

    pub fn open(config: zenoh::Config, keys: Keys) -> Result<Client, String> {
        let session = crate::open(config)?;
        Ok(Client { session, keys })
    }

    /// The operator API's `call` (`state`, or a control call with its JSON `body`), with
    /// the token: the HTTP status it stands for and the answer's JSON, as `aviary ctl`
    /// reads an HTTP answer. No run answering is an `Err`.
    pub fn call(
        &self,
        call: &str,
        body: Option<String>,
        token: Option<&str>,
    ) -> Result<(u16, String), String> {
        let key = self.keys.call(call);
        let mut get = self.session.get(&key).timeout(ANSWER_WITHIN);
        if let Some(body) = body {
            get = get.payload(body);
        }
        if let Some(token) = token {
            get = get.attachment(token.to_string());
        }
        let replies = get.wait().map_err(|e| format!("cannot ask {key}: {}", crate::reason(&e)))?;
        let reply = replies
            .recv()
            .map_err(|_| format!("no run answered on {key} within {ANSWER_WITHIN:?}"))?;
        match reply.result() {
            Ok(sample) => Ok((200, text(sample.payload()))),
            Err(error) => {
                let body = text(error.payload());
                Ok((crate::queries::status_of(&body), body))
            }
        }
    }

    /// Each event, its trace line, to `each` (telemetry included) until `mission_end`, or
    /// until `each` says stop (false).
    pub fn events(&self, mut each: impl FnMut(&str) -> bool) -> Result<(), String> {
        let all = format!("{}/**", self.keys.prefix());
        let heard = self
            .session
            .declare_subscriber(&all)
            .wait()
            .map_err(|e| format!("cannot subscribe to {all}: {}", crate::reason(&e)))?;
        let events = self.keys.events();
        while let Ok(sample) = heard.recv() {
            let key = sample.key_expr().as_str();
            if !self.keys.carries_lines(key) {
                continue;
            }
            let line = text(sample.payload());
            let end = key == events && line.contains(r#""event":"mission_end""#);
            if !each(&line) || end {
                break;
            }
        }
        Ok(())
    }
}

fn text(bytes: &zenoh::bytes::ZBytes) -> String {
    String::from_utf8_lossy(&bytes.to_bytes()).into_owned()
}
