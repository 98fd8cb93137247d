//! The mission's side of an agent (`mavlink = "agent:NAME"` in a world): the frames of
//! the vehicle link an `aviary agent` holds on another machine, through the run's
//! session. The MAVLink backend reads and writes them as it does a socket's. It runs on
//! the run's runtime, so its waits keep the run's clock (`aviary_clock`).

use std::future::Future;
use std::pin::Pin;
use std::time::Duration;

use aviary_mavlink::{Carrier, Frames};
use tokio::sync::mpsc;
use zenoh::bytes::Encoding;
use zenoh::sample::SampleKind;

use crate::keys::AgentKeys;

/// Frames waiting either way; beyond, the newest are dropped, as a radio drops them.
const QUEUE: usize = 1024;
/// How long an agent's liveliness token is looked for: as long as a socket's link is
/// waited for, and a peer that is still joining the network has time to.
const LOOK_FOR: Duration = Duration::from_secs(5);

/// The agents a run reaches, on its session.
pub struct Agents {
    session: zenoh::Session,
}

impl Agents {
    pub fn new(session: zenoh::Session) -> Agents {
        Agents { session }
    }

    async fn frames(&self, name: &str) -> Result<Frames, String> {
        let keys = AgentKeys::new(name)?;
        // A subscriber with history hears an agent that is already there and one that
        // joins while we look; a single query would miss the latter.
        let (seen_tx, mut seen) = mpsc::channel(1);
        let looking = self
            .session
            .liveliness()
            .declare_subscriber(keys.alive())
            .history(true)
            .callback(move |sample| {
                if sample.kind() == SampleKind::Put {
                    let _ = seen_tx.try_send(());
                }
            })
            .await
            .map_err(|e| {
                format!("cannot look for agent `{name}` on Zenoh: {}", crate::reason(&e))
            })?;
        let heard = aviary_clock::timeout(LOOK_FOR, seen.recv()).await;
        drop(looking);
        if !matches!(heard, Ok(Some(()))) {
            return Err(format!(
                "no agent `{name}` on Zenoh (looked {} s for {}): is `aviary agent --name {name}` running, and does this run's Zenoh configuration reach it?",
                LOOK_FOR.as_secs(),
                keys.alive()
            ));
        }
        let (from_tx, from_vehicle) = mpsc::channel(QUEUE);
        let subscriber = self
            .session
            .declare_subscriber(keys.from_vehicle())
            .callback(move |sample| {
                let _ = from_tx.try_send(sample.payload().to_bytes().into_owned());
            })
            .await
            .map_err(|e| format!("cannot hear agent `{name}`: {}", crate::reason(&e)))?;
        let publisher = self
            .session
            .declare_publisher(keys.to_vehicle())
            .encoding(Encoding::APPLICATION_OCTET_STREAM)
            .await
            .map_err(|e| format!("cannot speak to agent `{name}`: {}", crate::reason(&e)))?;
        let (to_vehicle, mut to_rx) = mpsc::channel::<Vec<u8>>(QUEUE);
        // Both live as long as the link writes: its end undeclares them.
        tokio::spawn(async move {
            let _subscriber = subscriber;
            while let Some(frame) = to_rx.recv().await {
                let _ = publisher.put(frame).await;
            }
        });
        Ok(Frames { from_vehicle, to_vehicle })
    }
}

impl Carrier for Agents {
    fn open<'a>(
        &'a self,
        name: &'a str,
    ) -> Pin<Box<dyn Future<Output = Result<Frames, String>> + Send + 'a>> {
        Box::pin(self.frames(name))
    }
}
