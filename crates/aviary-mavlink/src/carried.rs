//! A link that no socket of this machine holds: the `agent:NAME` address of a world
//! (docs/DISTRIBUTED.md). An agent on another machine holds the vehicle's link, and a
//! [`Carrier`] (Zenoh, in `aviary-zenoh`) brings its frames here and takes ours there.
//! This crate knows only the frames, one MAVLink frame each, so it needs no network of
//! its own: the carrier is handed in by whoever runs the mission.

use std::future::Future;
use std::io;
use std::pin::Pin;

use mavlink::dialects::ardupilotmega::MavMessage;
use mavlink::error::{MessageReadError, MessageWriteError};
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion, SigningData};
use tokio::sync::mpsc;

/// The frames of one agent's vehicle link, as a carrier delivers them.
pub struct Frames {
    /// Each one MAVLink frame the vehicle sent, in order. Closed when the carrier is.
    pub from_vehicle: mpsc::Receiver<Vec<u8>>,
    /// Each one MAVLink frame for the vehicle. A full queue drops the frame, as a radio
    /// does: commands are sent again until acknowledged.
    pub to_vehicle: mpsc::Sender<Vec<u8>>,
}

/// What reaches the agents a world names.
pub trait Carrier: Send + Sync {
    /// The frames of agent `name`; an error says, for the operator, why it cannot be
    /// reached (no such agent heard within the carrier's wait).
    fn open<'a>(
        &'a self,
        name: &'a str,
    ) -> Pin<Box<dyn Future<Output = Result<Frames, String>> + Send + 'a>>;
}

/// The agent's name, when `address` is `agent:NAME`.
pub fn agent_of(address: &str) -> Option<&str> {
    address.strip_prefix("agent:")
}

/// One agent's link, read and written as a socket's MAVLink connection is.
pub(crate) struct CarriedConn {
    from_vehicle: tokio::sync::Mutex<mpsc::Receiver<Vec<u8>>>,
    to_vehicle: mpsc::Sender<Vec<u8>>,
    signing: Option<SigningData>,
}

impl CarriedConn {
    pub fn new(frames: Frames, signing: Option<SigningData>) -> CarriedConn {
        CarriedConn {
            from_vehicle: tokio::sync::Mutex::new(frames.from_vehicle),
            to_vehicle: frames.to_vehicle,
            signing,
        }
    }

    /// The next frame that is a MAVLink message (and, with a key, signed with it).
    /// Anything else is skipped, as a socket's reader skips noise. An error only when
    /// the carrier has closed.
    pub async fn recv(&self) -> Result<(MavHeader, MavMessage), MessageReadError> {
        let mut from = self.from_vehicle.lock().await;
        loop {
            let Some(frame) = from.recv().await else {
                return Err(MessageReadError::Io(io::Error::new(
                    io::ErrorKind::ConnectionAborted,
                    "the agent's carrier closed",
                )));
            };
            let mut reader = MavlinkReader::new(frame.as_slice());
            if let Ok(message) = reader.read_any_message_signed(self.signing.as_ref()) {
                return Ok(message);
            }
        }
    }

    pub fn send(&self, header: &MavHeader, msg: &MavMessage) -> Result<usize, MessageWriteError> {
        let mut frame = Vec::with_capacity(64);
        let n = mavlink::write_versioned_msg_signed(
            &mut frame,
            MavlinkVersion::V2,
            *header,
            msg,
            self.signing.as_ref(),
        )?;
        // Full: the frame is lost, as on a radio that cannot keep up.
        let _ = self.to_vehicle.try_send(frame);
        Ok(n)
    }
}
