//! What one trace record is in ROS 2: the messages, each on its topic, that a bag records
//! ([`crate::bag`]) and a live run publishes on rmw_zenoh (`aviary-zenoh`). One reading,
//! so a bag and a live subscriber see the same.
//!
//! The topics: `/aviary/events` (`aviary_msgs/msg/Event`, every event of the trace), and
//! for each drone `/aviary/DRONE/pose` (`geometry_msgs/msg/PoseStamped`, in the mission's
//! local frame `map`: metres east, north and up of the world's origin) and, when the world
//! places that origin on the Earth, `/aviary/DRONE/fix` (`sensor_msgs/msg/NavSatFix`),
//! each from the trace's telemetry. Stamps are mission time.

use aviary_api::geo::Origin;
use aviary_api::trace::{Event as TraceEvent, Record};

use crate::msgs::{
    self, Event, Header, Message, NavSatFix, NavSatStatus, Point, Pose, PoseStamped, Quaternion,
    Time,
};

/// The frame of the poses: the mission's local east-north-up metres.
pub const LOCAL_FRAME: &str = "map";
/// The topic of the trace's events.
pub const EVENTS: &str = "/aviary/events";

/// One message of any of Aviary's types.
#[derive(Clone, Debug, PartialEq)]
pub enum Sent {
    Event(Event),
    Pose(PoseStamped),
    Fix(NavSatFix),
}

impl Sent {
    /// Its type, as ROS 2 names it (`sensor_msgs/msg/NavSatFix`).
    pub fn ty(&self) -> &'static str {
        match self {
            Sent::Event(_) => Event::TYPE,
            Sent::Pose(_) => PoseStamped::TYPE,
            Sent::Fix(_) => NavSatFix::TYPE,
        }
    }

    /// As CDR behind its encapsulation header.
    pub fn cdr(&self) -> Result<Vec<u8>, String> {
        match self {
            Sent::Event(m) => msgs::cdr(m),
            Sent::Pose(m) => msgs::cdr(m),
            Sent::Fix(m) => msgs::cdr(m),
        }
    }

    /// Its type's definition, as a bag holds it.
    pub fn definition(&self) -> String {
        match self {
            Sent::Event(_) => Event::definition(),
            Sent::Pose(_) => PoseStamped::definition(),
            Sent::Fix(_) => NavSatFix::definition(),
        }
    }

    /// Its type's RIHS01 hash.
    pub fn hash(&self) -> Result<String, String> {
        match self {
            Sent::Event(_) => crate::hash::rihs01::<Event>(),
            Sent::Pose(_) => crate::hash::rihs01::<PoseStamped>(),
            Sent::Fix(_) => crate::hash::rihs01::<NavSatFix>(),
        }
    }
}

/// The messages of `record`, each with its topic, placing positions on the Earth about
/// `origin` when there is one.
pub fn of(record: &Record<'_>, origin: Option<Origin>) -> Result<Vec<(String, Sent)>, String> {
    let stamp = Time::of(record.t);
    let header = || Header { stamp, frame_id: LOCAL_FRAME.into() };
    let json = serde_json::to_string(record).map_err(|e| e.to_string())?;
    let event = record.event.kind().as_str().to_string();
    let mut out = vec![(EVENTS.to_string(), Sent::Event(Event { header: header(), event, json }))];
    if let TraceEvent::Telemetry { actor, position, .. } = &record.event {
        let [x, y, z] = *position;
        let pose = PoseStamped {
            header: header(),
            pose: Pose { position: Point { x, y, z }, orientation: Quaternion::IDENTITY },
        };
        out.push((format!("/aviary/{actor}/pose"), Sent::Pose(pose)));
        if let Some(origin) = origin {
            out.push((format!("/aviary/{actor}/fix"), Sent::Fix(fix(origin, header(), *position))));
        }
    }
    Ok(out)
}

/// Where a drone at local `position` is on the Earth; no fix where the trace has no
/// position (a coordinate that is not finite).
fn fix(origin: Origin, header: Header, position: [f64; 3]) -> NavSatFix {
    let [x, y, z] = position;
    let (latitude, longitude) = origin.to_geodetic(x, y);
    let known = position.iter().all(|c| c.is_finite());
    NavSatFix {
        header,
        status: NavSatStatus { status: if known { 0 } else { -1 }, service: 1 },
        latitude,
        longitude,
        altitude: origin.alt + z,
        position_covariance: [0.0; 9],
        position_covariance_type: 0,
    }
}
