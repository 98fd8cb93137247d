//! The run for ROS 2 (`aviary run --zenoh --ros`, docs/ROS2.md): each trace record's
//! messages (`aviary_ros::topics`: the events, and each drone's pose and fix) published as
//! rmw_zenoh, ROS 2's middleware on Zenoh, publishes them, so that ROS 2 nodes on
//! `rmw_zenoh` see the fleet (`ros2 topic echo /aviary/scout/fix`).
//!
//! As rmw_zenoh has it (its design document, and its `liveliness_utils.cpp` and
//! `attachment_helpers.cpp`):
//! - a message is put on `DOMAIN/TOPIC/TYPE/HASH` (the topic without its leading `/`, the
//!   type in its DDS form `pkg::msg::dds_::Name_`, the hash RIHS01), as CDR;
//! - with an attachment of 33 bytes: the publisher's sequence number (i64, from 1), the
//!   source time (i64 ns since the Unix epoch), `0x10`, and the publisher's 16-byte id;
//! - the node and each publisher hold liveliness tokens under `@ros2_lv/DOMAIN/...`, by
//!   which `ros2 topic list` and `ros2 node list` find them.

use std::collections::HashMap;
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{SystemTime, UNIX_EPOCH};

use aviary_api::geo::Origin;
use aviary_api::trace::Record;
use aviary_ros::topics::{self, Sent};
use aviary_server::Line;
use sha2::{Digest, Sha256};
use tokio::sync::broadcast::Receiver;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Publisher;
use zenoh::Wait;

/// The node's name, in the root namespace and the default enclave.
const NODE: &str = "aviary";
/// Reliable, volatile, keep the last 10: ROS 2's default profile, each value written out
/// (rmw_zenoh leaves out the ones equal to its own defaults, which changed between
/// releases; an explicit value reads the same in all).
const QOS: &str = "1:2:1,10:,:,:,,";

/// Where the run is seen from ROS 2.
#[derive(Clone, Copy, Debug)]
pub struct Ros {
    /// `ROS_DOMAIN_ID`.
    pub domain: u32,
    /// Where the world's frame sits on the Earth: without it, no fix is published.
    pub origin: Option<Origin>,
}

/// Publishes what `lines` carries for ROS 2 until `mission_end`.
pub(crate) fn start(
    session: zenoh::Session,
    lines: Receiver<Arc<Line>>,
    ros: Ros,
) -> Result<JoinHandle<()>, String> {
    let names = Names { domain: ros.domain, zid: session.zid().to_string() };
    let node =
        session.liveliness().declare_token(names.node()).wait().map_err(|e| {
            format!("cannot declare the ROS 2 node on Zenoh: {}", crate::reason(&e))
        })?;
    std::thread::Builder::new()
        .name("aviary ros 2".into())
        .spawn(move || {
            let mut publishing = Publishing {
                session,
                names,
                origin: ros.origin,
                topics: HashMap::new(),
                _node: node,
            };
            publishing.run(lines)
        })
        .map_err(|e| format!("cannot start the ROS 2 publisher: {e}"))
}

/// rmw_zenoh's names for this node and its publishers.
struct Names {
    domain: u32,
    zid: String,
}

impl Names {
    fn node(&self) -> String {
        format!("@ros2_lv/{}/{}/0/0/NN/%/%/{NODE}", self.domain, self.zid)
    }

    /// The liveliness token of publisher `id` of `topic`.
    fn publisher(&self, id: u64, topic: &str, ty: &str, hash: &str) -> String {
        format!(
            "@ros2_lv/{}/{}/0/{id}/MP/%/%/{NODE}/{}/{}/{hash}/{QOS}",
            self.domain,
            self.zid,
            topic.replace('/', "%"),
            dds_type(ty)
        )
    }

    /// Where `topic`'s messages go.
    fn data(&self, topic: &str, ty: &str, hash: &str) -> String {
        format!("{}/{}/{}/{hash}", self.domain, topic.trim_matches('/'), dds_type(ty))
    }
}

/// `sensor_msgs/msg/NavSatFix` as DDS names it: `sensor_msgs::msg::dds_::NavSatFix_`.
fn dds_type(ty: &str) -> String {
    match ty.rsplit_once('/') {
        Some((package, name)) => format!("{}::dds_::{name}_", package.replace('/', "::")),
        None => ty.to_string(),
    }
}

/// One topic's publisher, its token and what its attachment carries.
struct Topic {
    publisher: Publisher<'static>,
    _token: LivelinessToken,
    gid: [u8; 16],
    sequence: i64,
}

struct Publishing {
    session: zenoh::Session,
    names: Names,
    origin: Option<Origin>,
    topics: HashMap<String, Topic>,
    _node: LivelinessToken,
}

impl Publishing {
    fn run(&mut self, lines: Receiver<Arc<Line>>) {
        crate::follow(lines, "ros 2: the publisher", |line| self.line(line));
    }

    fn line(&mut self, line: &Line) {
        let record: Record = match serde_json::from_str(&line.text) {
            Ok(record) => record,
            Err(e) => return eprintln!("aviary: ros 2: an event not read again: {e}"),
        };
        let messages = match topics::of(&record, self.origin) {
            Ok(messages) => messages,
            Err(why) => return eprintln!("aviary: ros 2: {why}"),
        };
        for (topic, message) in messages {
            if let Err(why) = self.put(&topic, &message) {
                eprintln!("aviary: ros 2: {topic}: {why}");
            }
        }
    }

    fn put(&mut self, topic: &str, message: &Sent) -> Result<(), String> {
        let next_id = self.topics.len() as u64 + 1;
        let known = match self.topics.entry(topic.to_string()) {
            std::collections::hash_map::Entry::Occupied(known) => known.into_mut(),
            std::collections::hash_map::Entry::Vacant(new) => {
                new.insert(declare(&self.session, &self.names, next_id, topic, message)?)
            }
        };
        known.sequence += 1;
        let mut attachment = Vec::with_capacity(33);
        attachment.extend_from_slice(&known.sequence.to_le_bytes());
        let now = SystemTime::now().duration_since(UNIX_EPOCH).map_or(0, |d| d.as_nanos());
        attachment.extend_from_slice(&i64::try_from(now).unwrap_or(i64::MAX).to_le_bytes());
        attachment.push(16);
        attachment.extend_from_slice(&known.gid);
        known
            .publisher
            .put(message.cdr()?)
            .attachment(attachment)
            .wait()
            .map_err(|e| crate::reason(&e))
    }
}

/// A topic's publisher and its liveliness token, publisher `id` of the node.
fn declare(
    session: &zenoh::Session,
    names: &Names,
    id: u64,
    topic: &str,
    message: &Sent,
) -> Result<Topic, String> {
    let hash = message.hash()?;
    let token_key = names.publisher(id, topic, message.ty(), &hash);
    let token = session
        .liveliness()
        .declare_token(token_key.clone())
        .wait()
        .map_err(|e| format!("cannot declare its publisher: {}", crate::reason(&e)))?;
    let key = names.data(topic, message.ty(), &hash);
    let publisher = session
        .declare_publisher(key.clone())
        .wait()
        .map_err(|e| format!("cannot publish on {key}: {}", crate::reason(&e)))?;
    // rmw_zenoh's id of a publisher is a hash of its token (XXH3); any 16 bytes unique to
    // it serve the same ends (telling publishers apart, counting lost messages).
    let mut gid = [0; 16];
    gid.copy_from_slice(&Sha256::digest(token_key.as_bytes())[..16]);
    Ok(Topic { publisher, _token: token, gid, sequence: 0 })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// rmw_zenoh's own examples of its keys and tokens, for a node `aviary` publishing a
    /// NavSatFix on `/aviary/scout/fix`.
    #[test]
    fn the_keys_and_tokens_are_rmw_zenoh_s() {
        let names = Names { domain: 0, zid: "8b20917502ee955ac4476e0266340d5c".into() };
        let hash = "RIHS01_62223ab3fe210a15976021da7afddc9e200dc9ec75231c1b6a557fc598a65404";
        let ty = "sensor_msgs/msg/NavSatFix";
        assert_eq!(
            names.data("/aviary/scout/fix", ty, hash),
            format!("0/aviary/scout/fix/sensor_msgs::msg::dds_::NavSatFix_/{hash}")
        );
        assert_eq!(names.node(), "@ros2_lv/0/8b20917502ee955ac4476e0266340d5c/0/0/NN/%/%/aviary");
        assert_eq!(
            names.publisher(1, "/aviary/scout/fix", ty, hash),
            format!("@ros2_lv/0/8b20917502ee955ac4476e0266340d5c/0/1/MP/%/%/aviary/%aviary%scout%fix/sensor_msgs::msg::dds_::NavSatFix_/{hash}/1:2:1,10:,:,:,,")
        );
    }
}
