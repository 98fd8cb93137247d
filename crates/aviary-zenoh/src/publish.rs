//! The publisher: each line the run's feed carries, on its key, and the operator state
//! once a second while events come, and once more at the end.

use std::collections::hash_map::{Entry, HashMap};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use aviary_server::{Feed, Line};
use tokio::sync::broadcast::Receiver;
use zenoh::bytes::Encoding;
use zenoh::pubsub::Publisher;
use zenoh::Wait;

use crate::Keys;

/// How often the state is published while the run goes on.
const STATE_EVERY: Duration = Duration::from_secs(1);

pub(crate) fn start(
    session: zenoh::Session,
    keys: Keys,
    lines: Receiver<Arc<Line>>,
    feed: Feed,
) -> Result<JoinHandle<()>, String> {
    let events = declare(&session, keys.events())?;
    let state = declare(&session, keys.state())?;
    std::thread::Builder::new()
        .name("aviary zenoh publisher".into())
        .spawn(move || {
            let mut publisher = Publishing {
                session,
                keys,
                events,
                state,
                telemetry: HashMap::new(),
                feed,
                last_state: None,
            };
            publisher.run(lines)
        })
        .map_err(|e| format!("cannot start the Zenoh publisher: {e}"))
}

/// A publisher of JSON on `key`.
fn declare(session: &zenoh::Session, key: String) -> Result<Publisher<'static>, String> {
    session
        .declare_publisher(key.clone())
        .encoding(Encoding::APPLICATION_JSON)
        .wait()
        .map_err(|e| format!("cannot publish on {key}: {}", crate::reason(&e)))
}

struct Publishing {
    session: zenoh::Session,
    keys: Keys,
    events: Publisher<'static>,
    state: Publisher<'static>,
    /// One publisher per drone, declared at its first sample.
    telemetry: HashMap<Box<str>, Publisher<'static>>,
    feed: Feed,
    last_state: Option<Instant>,
}

impl Publishing {
    fn run(&mut self, lines: Receiver<Arc<Line>>) {
        crate::follow(lines, "zenoh: the publisher", |line| {
            self.line(line);
            if self.last_state.is_none_or(|t| t.elapsed() >= STATE_EVERY) {
                self.publish_state();
            }
        });
        // The state after `mission_end`, or as the feed ended.
        self.publish_state();
    }

    fn line(&mut self, line: &Line) {
        let text = line.text.as_bytes().to_vec();
        let publisher = match &line.telemetry_of {
            None => &self.events,
            Some(drone) => match self.telemetry.entry(drone.clone()) {
                Entry::Occupied(known) => known.into_mut(),
                Entry::Vacant(new) => match declare(&self.session, self.keys.telemetry(drone)) {
                    Ok(publisher) => new.insert(publisher),
                    Err(why) => {
                        eprintln!("aviary: zenoh: {why}");
                        return;
                    }
                },
            },
        };
        // An event's place in the run, beside it: a station that asked for the history
        // (`PREFIX/api/history`) joins it to what it hears by it.
        let put = match line.telemetry_of {
            None => publisher.put(text).attachment(line.seq.to_string()),
            Some(_) => publisher.put(text),
        };
        if let Err(e) = put.wait() {
            eprintln!("aviary: zenoh: an event was not published: {}", crate::reason(&e));
        }
    }

    fn publish_state(&mut self) {
        self.last_state = Some(Instant::now());
        match serde_json::to_vec(&self.feed.document()) {
            Ok(bytes) => {
                if let Err(e) = self.state.put(bytes).wait() {
                    eprintln!("aviary: zenoh: the state was not published: {}", crate::reason(&e));
                }
            }
            Err(e) => eprintln!("aviary: zenoh: the state could not be written: {e}"),
        }
    }
}
