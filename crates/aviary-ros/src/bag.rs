//! A recorded trace as a rosbag2 bag: a folder holding one MCAP file (`ros2` profile,
//! `ros2msg` schemas, CDR messages) and the `metadata.yaml` that `ros2 bag` and rosbags
//! read first. Foxglove opens the MCAP file alone.
//!
//! Its topics are [`crate::topics`]'s. Times are mission time: the bag starts at 0
//! (1 January 1970, as a bag reader shows it).

use std::collections::BTreeMap;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use aviary_api::geo::Origin;
use aviary_api::trace::Record;
use serde::Serialize;

use crate::msgs::Time;
use crate::topics::{self, Sent};
pub use crate::topics::{EVENTS, LOCAL_FRAME};

/// What a bag holds.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Written {
    /// The MCAP file.
    pub file: PathBuf,
    pub topics: Vec<Topic>,
}

/// A topic of a bag: its name, its message type and how many messages it has.
#[derive(Clone, Debug, PartialEq)]
pub struct Topic {
    pub name: String,
    pub ty: &'static str,
    pub messages: u64,
}

/// Writes the trace's `records` as a bag in `folder` (made; it must not exist, as
/// `ros2 bag record` wants), placing positions on the Earth about `origin` when there
/// is one.
pub fn write(
    folder: &Path,
    records: &[Record<'_>],
    origin: Option<Origin>,
) -> Result<Written, String> {
    let name = folder
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| format!("{} is no folder's name", folder.display()))?;
    if folder.exists() {
        return Err(format!("{} exists already: a bag is a new folder", folder.display()));
    }
    std::fs::create_dir_all(folder)
        .map_err(|e| format!("cannot make {}: {e}", folder.display()))?;
    let file_name = format!("{name}_0.mcap");
    let file = folder.join(&file_name);
    let out = std::fs::File::create(&file)
        .map_err(|e| format!("cannot write {}: {e}", file.display()))?;
    let mut bag = Bag::start(BufWriter::new(out), origin).map_err(|e| e.to_string())?;
    for record in records {
        bag.record(record).map_err(|e| e.to_string())?;
    }
    let (topics, end) = bag.finish().map_err(|e| e.to_string())?;
    let metadata = Metadata::of(&file_name, &topics, end);
    let yaml = serde_norway::to_string(&metadata).map_err(|e| e.to_string())?;
    let metadata_file = folder.join("metadata.yaml");
    std::fs::write(&metadata_file, yaml)
        .map_err(|e| format!("cannot write {}: {e}", metadata_file.display()))?;
    Ok(Written { file, topics })
}

/// A failure while writing: MCAP's, or a message's encoding.
#[derive(Debug)]
enum Failed {
    Mcap(mcap::McapError),
    Encoding(String),
}

impl std::fmt::Display for Failed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Failed::Mcap(e) => write!(f, "MCAP: {e}"),
            Failed::Encoding(why) => f.write_str(why),
        }
    }
}

impl From<mcap::McapError> for Failed {
    fn from(e: mcap::McapError) -> Failed {
        Failed::Mcap(e)
    }
}

/// The MCAP file as it is written: its channels by topic, with their counts.
struct Bag<W: std::io::Write + std::io::Seek> {
    mcap: mcap::Writer<W>,
    origin: Option<Origin>,
    /// Topic → (channel, type, messages so far).
    channels: BTreeMap<String, (u16, &'static str, u64)>,
    end: Time,
}

impl<W: std::io::Write + std::io::Seek> Bag<W> {
    fn start(out: W, origin: Option<Origin>) -> Result<Self, Failed> {
        let mcap = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("aviary ", env!("CARGO_PKG_VERSION")))
            .compression(None)
            // Unchunked: the bag starts at time 0, and a reader may take a chunk that
            // starts there for an empty one (rosbags 0.10 skips it); a reader scans an
            // unchunked file from end to end instead.
            .use_chunks(false)
            .create(out)?;
        Ok(Bag { mcap, origin, channels: BTreeMap::new(), end: Time::default() })
    }

    fn record(&mut self, record: &Record<'_>) -> Result<(), Failed> {
        let stamp = Time::of(record.t);
        self.end = stamp;
        for (topic, message) in topics::of(record, self.origin).map_err(Failed::Encoding)? {
            self.write(&topic, stamp, &message)?;
        }
        Ok(())
    }

    fn write(&mut self, topic: &str, stamp: Time, message: &Sent) -> Result<(), Failed> {
        let data = message.cdr().map_err(Failed::Encoding)?;
        let (channel, sequence) = match self.channels.get_mut(topic) {
            Some((channel, _, count)) => {
                *count += 1;
                (*channel, *count)
            }
            None => {
                // MCAP keeps each schema once, however many topics add it.
                let definition = message.definition();
                let ty = message.ty();
                let schema = self.mcap.add_schema(ty, "ros2msg", definition.as_bytes())?;
                let channel = self.mcap.add_channel(schema, topic, "cdr", &BTreeMap::new())?;
                self.channels.insert(topic.to_string(), (channel, ty, 1));
                (channel, 1)
            }
        };
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: u32::try_from(sequence).unwrap_or(u32::MAX),
            log_time: stamp.nanos(),
            publish_time: stamp.nanos(),
        };
        self.mcap.write_to_known_channel(&header, &data)?;
        Ok(())
    }

    fn finish(mut self) -> Result<(Vec<Topic>, Time), Failed> {
        self.mcap.finish()?;
        let topics = self
            .channels
            .into_iter()
            .map(|(name, (_, ty, messages))| Topic { name, ty, messages })
            .collect();
        Ok((topics, self.end))
    }
}

/// `metadata.yaml`, as rosbag2 writes it (version 5).
#[derive(Serialize)]
struct Metadata {
    rosbag2_bagfile_information: Information,
}

#[derive(Serialize)]
struct Information {
    version: u8,
    storage_identifier: &'static str,
    duration: Nanoseconds,
    starting_time: SinceEpoch,
    message_count: u64,
    topics_with_message_count: Vec<TopicCount>,
    compression_format: &'static str,
    compression_mode: &'static str,
    relative_file_paths: Vec<String>,
    files: Vec<FileInformation>,
}

#[derive(Serialize)]
struct Nanoseconds {
    nanoseconds: u64,
}

#[derive(Serialize)]
struct SinceEpoch {
    nanoseconds_since_epoch: u64,
}

#[derive(Serialize)]
struct TopicCount {
    topic_metadata: TopicMetadata,
    message_count: u64,
}

#[derive(Serialize)]
struct TopicMetadata {
    name: String,
    #[serde(rename = "type")]
    ty: &'static str,
    serialization_format: &'static str,
    offered_qos_profiles: &'static str,
}

#[derive(Serialize)]
struct FileInformation {
    path: String,
    starting_time: SinceEpoch,
    duration: Nanoseconds,
    message_count: u64,
}

impl Metadata {
    fn of(file: &str, topics: &[Topic], end: Time) -> Metadata {
        let message_count = topics.iter().map(|t| t.messages).sum();
        let topics_with_message_count = topics
            .iter()
            .map(|t| TopicCount {
                topic_metadata: TopicMetadata {
                    name: t.name.clone(),
                    ty: t.ty,
                    serialization_format: "cdr",
                    offered_qos_profiles: "",
                },
                message_count: t.messages,
            })
            .collect();
        let duration = end.nanos();
        Metadata {
            rosbag2_bagfile_information: Information {
                version: 5,
                storage_identifier: "mcap",
                duration: Nanoseconds { nanoseconds: duration },
                starting_time: SinceEpoch { nanoseconds_since_epoch: 0 },
                message_count,
                topics_with_message_count,
                compression_format: "",
                compression_mode: "",
                relative_file_paths: vec![file.to_string()],
                files: vec![FileInformation {
                    path: file.to_string(),
                    starting_time: SinceEpoch { nanoseconds_since_epoch: 0 },
                    duration: Nanoseconds { nanoseconds: duration },
                    message_count,
                }],
            },
        }
    }
}
