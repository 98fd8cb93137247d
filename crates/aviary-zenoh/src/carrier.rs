//! The mission's side of an agent (`mavlink = "agent:NAME"` in a world): the frames of
//! the vehicle link an `aviary agent` holds on another machine, through the run's
//! session. The MAVLink backend reads and writes them as it does a socket's. It runs on
//! the run's runtime, so its waits keep the run's clock (`aviary_clock`).

use std::future::Future;
use std::pin::Pin;
use std::time::Duration;

use aviary_mavlink::{Carrier, Frames};
use tokio::sync::mpsc;
use zenoh::sample::SampleKind;

use crate::frames;
use crate::keys::AgentKeys;

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
        let (subscriber, from_vehicle) = frames::hear(&self.session, keys.from_vehicle()).await?;
        let publisher = frames::speak(&self.session, keys.to_vehicle()).await?;
        let (to_vehicle, mut to_rx) = mpsc::channel::<Vec<u8>>(frames::QUEUE);
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
