//! The ROS 2 messages Aviary speaks, as serde types in the field order of their `.msg`
//! definitions (which CDR follows), with those definitions as text: a bag or a ROS 2 peer
//! that has never seen `aviary_msgs` reads them from it.
//!
//! `sensor_msgs/NavSatFix` and `geometry_msgs/PoseStamped` are ROS 2's own (Humble and
//! later, unchanged since); `aviary_msgs/Event` is the project's: one trace event, its
//! kind and its line of JSON (docs/TRACE.md).

use serde::Serialize;

/// `builtin_interfaces/msg/Time`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Time {
    pub sec: i32,
    pub nanosec: u32,
}

impl Time {
    /// `seconds` of mission time (none before 0; at most `i32::MAX` s, some 68 years).
    pub fn of(seconds: f64) -> Time {
        let whole = seconds.max(0.0).floor();
        let nanosec = ((seconds.max(0.0) - whole) * 1e9).round().min(999_999_999.0) as u32;
        Time { sec: whole.min(f64::from(i32::MAX)) as i32, nanosec }
    }

    /// In nanoseconds, as MCAP's log times are.
    pub fn nanos(self) -> u64 {
        u64::try_from(self.sec).unwrap_or(0) * 1_000_000_000 + u64::from(self.nanosec)
    }
}

/// `std_msgs/msg/Header`.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Header {
    pub stamp: Time,
    pub frame_id: String,
}

/// `sensor_msgs/msg/NavSatStatus`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NavSatStatus {
    /// `STATUS_FIX` (0), or `STATUS_NO_FIX` (-1).
    pub status: i8,
    /// `SERVICE_GPS` (1).
    pub service: u16,
}

/// `sensor_msgs/msg/NavSatFix`: where a drone is on the Earth.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NavSatFix {
    pub header: Header,
    pub status: NavSatStatus,
    /// Degrees.
    pub latitude: f64,
    pub longitude: f64,
    /// Metres above the WGS 84 ellipsoid (here: above sea level, as the world's origin).
    pub altitude: f64,
    pub position_covariance: [f64; 9],
    /// `COVARIANCE_TYPE_UNKNOWN` (0).
    pub position_covariance_type: u8,
}

/// `geometry_msgs/msg/Point`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// `geometry_msgs/msg/Quaternion`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Quaternion {
    pub x: f64,
    pub y: f64,
    pub z: f64,
    pub w: f64,
}

impl Quaternion {
    pub const IDENTITY: Quaternion = Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 };
}

/// `geometry_msgs/msg/Pose`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Pose {
    pub position: Point,
    pub orientation: Quaternion,
}

/// `geometry_msgs/msg/PoseStamped`: where a drone is in the mission's local frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PoseStamped {
    pub header: Header,
    pub pose: Pose,
}

/// `aviary_msgs/msg/Event`: one event of the trace.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Event {
    pub header: Header,
    /// The trace's `event`: `signal`, `capability_end`, ...
    pub event: String,
    /// The event's line of the trace file, as JSON.
    pub json: String,
}

/// A message type: its name as ROS 2 writes it, and its `.msg` definition followed by
/// those of the types it uses, as rosbag2 stores one in a bag (`ros2msg`).
pub trait Message: Serialize {
    const TYPE: &'static str;
    /// Its own `.msg` text.
    const TEXT: &'static str;
    /// The types it uses, each once, with their `.msg` texts.
    const USES: &'static [(&'static str, &'static str)];

    /// The definition a bag holds: its text, then each type it uses after a separator
    /// line and `MSG: package/Type`.
    fn definition() -> String {
        let mut out = String::from(Self::TEXT);
        for (name, text) in Self::USES {
            out.push_str(SEPARATOR);
            out.push_str("MSG: ");
            out.push_str(name);
            out.push('\n');
            out.push_str(text);
        }
        out
    }
}

const SEPARATOR: &str =
    "================================================================================\n";

const TIME: (&str, &str) = ("builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n");
const HEADER: (&str, &str) =
    ("std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n");
const NAV_SAT_STATUS: (&str, &str) = ("sensor_msgs/NavSatStatus", "int8 STATUS_NO_FIX = -1\nint8 STATUS_FIX = 0\nint8 STATUS_SBAS_FIX = 1\nint8 STATUS_GBAS_FIX = 2\nint8 status\nuint16 SERVICE_GPS = 1\nuint16 SERVICE_GLONASS = 2\nuint16 SERVICE_COMPASS = 4\nuint16 SERVICE_GALILEO = 8\nuint16 service\n");
const POSE: (&str, &str) = ("geometry_msgs/Pose", "Point position\nQuaternion orientation\n");
const POINT: (&str, &str) = ("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n");
const QUATERNION: (&str, &str) =
    ("geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n");

impl Message for NavSatFix {
    const TYPE: &'static str = "sensor_msgs/msg/NavSatFix";
    const TEXT: &'static str = "uint8 COVARIANCE_TYPE_UNKNOWN = 0\nuint8 COVARIANCE_TYPE_APPROXIMATED = 1\nuint8 COVARIANCE_TYPE_DIAGONAL_KNOWN = 2\nuint8 COVARIANCE_TYPE_KNOWN = 3\nstd_msgs/Header header\nNavSatStatus status\nfloat64 latitude\nfloat64 longitude\nfloat64 altitude\nfloat64[9] position_covariance\nuint8 position_covariance_type\n";
    const USES: &'static [(&'static str, &'static str)] = &[HEADER, TIME, NAV_SAT_STATUS];
}

impl Message for PoseStamped {
    const TYPE: &'static str = "geometry_msgs/msg/PoseStamped";
    const TEXT: &'static str = "std_msgs/Header header\nPose pose\n";
    const USES: &'static [(&'static str, &'static str)] = &[HEADER, TIME, POSE, POINT, QUATERNION];
}

impl Message for Event {
    const TYPE: &'static str = "aviary_msgs/msg/Event";
    const TEXT: &'static str = "# One event of an Aviary mission's trace (docs/TRACE.md).\nstd_msgs/Header header\n# The trace's `event`: signal, capability_end, ...\nstring event\n# The event's line of the trace, as JSON.\nstring json\n";
    const USES: &'static [(&'static str, &'static str)] = &[HEADER, TIME];
}

/// A message as CDR, little-endian, behind its 4-byte encapsulation header (`CDR_LE`), as
/// DDS, rmw_zenoh and rosbag2 carry it.
pub fn cdr<M: Message>(message: &M) -> Result<Vec<u8>, String> {
    let body = cdr_encoding::to_vec::<M, byteorder::LittleEndian>(message)
        .map_err(|e| format!("{} as CDR: {e}", M::TYPE))?;
    let mut out = Vec::with_capacity(4 + body.len());
    out.extend_from_slice(&[0x00, 0x01, 0x00, 0x00]);
    out.extend_from_slice(&body);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A definition is its text, then each type it uses after a separator line.
    #[test]
    fn a_definition_lists_the_types_it_uses_after_its_own() {
        let d = PoseStamped::definition();
        let parts: Vec<&str> = d.split(SEPARATOR).collect();
        assert_eq!(parts[0], PoseStamped::TEXT);
        assert_eq!(
            parts[1],
            "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
        );
        assert_eq!(parts.len(), 1 + PoseStamped::USES.len());
    }

    /// CDR aligns each primitive to its size from the start of the body, after the header.
    #[test]
    fn a_pose_is_the_cdr_ros_2_writes() {
        let pose = PoseStamped {
            header: Header { stamp: Time { sec: 1, nanosec: 2 }, frame_id: "map".into() },
            pose: Pose {
                position: Point { x: 1.0, y: 2.0, z: 3.0 },
                orientation: Quaternion::IDENTITY,
            },
        };
        let bytes = cdr(&pose).unwrap();
        let mut want = vec![0, 1, 0, 0];
        want.extend(1i32.to_le_bytes());
        want.extend(2u32.to_le_bytes());
        want.extend(4u32.to_le_bytes()); // "map" and its NUL
        want.extend(b"map\0");
        // 16 bytes so far: the float64s need no padding.
        for f in [1.0f64, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0] {
            want.extend(f.to_le_bytes());
        }
        assert_eq!(bytes, want);
    }

    #[test]
    fn mission_time_is_a_stamp() {
        assert_eq!(Time::of(12.25), Time { sec: 12, nanosec: 250_000_000 });
        assert_eq!(Time::of(-1.0), Time::default());
        assert_eq!(Time::of(3.5).nanos(), 3_500_000_000);
    }
}
