//! A vehicle's MAVLink frames on Zenoh, one a sample, as both ends carry them: the agent
//! (`agent.rs`) and the mission's side (`carrier.rs`) hear the other's key and speak on
//! their own, the same way.

use tokio::sync::mpsc;
use zenoh::bytes::Encoding;
use zenoh::pubsub::{Publisher, Subscriber};

/// Frames waiting either way; beyond, the newest are dropped, as a radio drops them:
/// commands are sent again until acknowledged.
pub(crate) const QUEUE: usize = 1024;

/// Each sample put on `key`, its bytes, in order; and the subscriber, which hears as long
/// as it is kept.
pub(crate) async fn hear(
    session: &zenoh::Session,
    key: String,
) -> Result<(Subscriber<()>, mpsc::Receiver<Vec<u8>>), String> {
    let (tx, rx) = mpsc::channel(QUEUE);
    let subscriber = session
        .declare_subscriber(key.clone())
        .callback(move |sample| {
            let _ = tx.try_send(sample.payload().to_bytes().into_owned());
        })
        .await
        .map_err(|e| format!("cannot subscribe to {key}: {}", crate::reason(&e)))?;
    Ok((subscriber, rx))
}

/// A publisher of frames on `key`.
pub(crate) async fn speak(
    session: &zenoh::Session,
    key: String,
) -> Result<Publisher<'static>, String> {
    session
        .declare_publisher(key.clone())
        .encoding(Encoding::APPLICATION_OCTET_STREAM)
        .await
        .map_err(|e| format!("cannot publish on {key}: {}", crate::reason(&e)))
}
