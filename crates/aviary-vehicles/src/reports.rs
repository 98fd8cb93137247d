//! What a vehicle reports of its GPS, its estimate, its home and itself: GPS_RAW_INT,
//! EKF_STATUS_REPORT, HOME_POSITION and AUTOPILOT_VERSION.

use aviary_api::DroneId;
use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    EkfStatusFlags, GpsFixType, MavMessage, MavProtocolCapability, AUTOPILOT_VERSION_DATA,
    EKF_STATUS_REPORT_DATA, GPS_RAW_INT_DATA, HOME_POSITION_DATA,
};

use crate::autopilot::Autopilot;

impl Autopilot {
    fn time_usec(&self) -> u64 {
        (self.fleet.time() * 1e6) as u64
    }

    /// GPS_RAW_INT: no fix (and no position, as a receiver without one) until the pre-arm
    /// time, then a 3D fix where the drone is. The simulated receiver has no accuracy,
    /// satellites or noise to report: those fields say "unknown".
    pub fn gps_raw_int(&self, i: usize) -> Option<MavMessage> {
        let t = self.fleet.telemetry(DroneId(i))?;
        let mut g = GPS_RAW_INT_DATA {
            time_usec: self.time_usec(),
            fix_type: GpsFixType::GPS_FIX_TYPE_NO_FIX,
            eph: u16::MAX,
            epv: u16::MAX,
            vel: u16::MAX,
            cog: u16::MAX,
            satellites_visible: u8::MAX,
            ..GPS_RAW_INT_DATA::default()
        };
        if self.ready() {
            let [x, y, z] = t.position;
            let (lat, lon) = self.origin.to_e7(x, y);
            g.fix_type = GpsFixType::GPS_FIX_TYPE_3D_FIX;
            g.lat = lat;
            g.lon = lon;
            g.alt = ((self.origin.alt + z) * 1000.0).round() as i32;
            g.vel = (t.speed * 100.0).round().clamp(0.0, 65_534.0) as u16;
            g.cog = (t.heading.rem_euclid(360.0) * 100.0).round() as u16 % 36_000;
        }
        Some(MavMessage::GPS_RAW_INT(g))
    }

    /// EKF_STATUS_REPORT: before the GPS fix, attitude and height only (ArduPilot's
    /// "constant position mode"); after it, every estimate ArduCopter needs to arm in
    /// GUIDED (the flags ArduCopter SITL reports, 0x33F). The simulator's state is exact:
    /// no variance.
    pub fn ekf_status(&self, _i: usize) -> MavMessage {
        use EkfStatusFlags as F;
        let flags = if self.ready() {
            F::EKF_ATTITUDE
                | F::EKF_VELOCITY_HORIZ
                | F::EKF_VELOCITY_VERT
                | F::EKF_POS_HORIZ_REL
                | F::EKF_POS_HORIZ_ABS
                | F::EKF_POS_VERT_ABS
                | F::EKF_PRED_POS_HORIZ_REL
                | F::EKF_PRED_POS_HORIZ_ABS
        } else {
            F::EKF_ATTITUDE | F::EKF_VELOCITY_VERT | F::EKF_POS_VERT_ABS | F::EKF_CONST_POS_MODE
        };
        MavMessage::EKF_STATUS_REPORT(EKF_STATUS_REPORT_DATA {
            flags,
            ..EKF_STATUS_REPORT_DATA::default()
        })
    }

    /// HOME_POSITION once home is set: the drone's world home, on the ground at the site
    /// origin's altitude (the simulator's ground is flat, so the surface quaternion is the
    /// identity); x, y, z in metres north, east, down of the origin, as ArduPilot's are of
    /// its EKF origin.
    pub fn home_position(&self, i: usize) -> Option<MavMessage> {
        let c = &self.copters[i];
        if !c.home_set {
            return None;
        }
        let (lat, lon) = self.origin.to_e7(c.home[0], c.home[1]);
        Some(MavMessage::HOME_POSITION(HOME_POSITION_DATA {
            latitude: lat,
            longitude: lon,
            altitude: (self.origin.alt * 1000.0).round() as i32,
            x: c.home[1] as f32,
            y: c.home[0] as f32,
            z: 0.0,
            q: [1.0, 0.0, 0.0, 0.0],
            time_usec: self.time_usec(),
            ..HOME_POSITION_DATA::default()
        }))
    }

    /// AUTOPILOT_VERSION: the capabilities of what is served (MAVLink 2, COMMAND_INT,
    /// SET_POSITION_TARGET_GLOBAL_INT, parameters as floats as ArduPilot encodes them; for
    /// PX4 missions and parameters bytewise, no position targets) and none of what is not
    /// (fences and rally points as missions, FTP, terrain, attitude and local targets);
    /// the version is Aviary's own, the uid the system id.
    #[allow(deprecated)] // PARAM_FLOAT: what ArduPilot still sets for its float encoding.
    pub fn autopilot_version(&self, i: usize) -> MavMessage {
        use MavProtocolCapability as C;
        let v = |k: usize| {
            env!("CARGO_PKG_VERSION")
                .split('.')
                .nth(k)
                .and_then(|n| n.parse::<u32>().ok())
                .unwrap_or(0)
                .min(255)
        };
        // major.minor.patch and FIRMWARE_VERSION_TYPE_DEV (0), MAVLink's packing.
        let version = v(0) << 24 | v(1) << 16 | v(2) << 8;
        // PX4's (mavlink_main.cpp) but FTP, the fence and rally missions and the
        // attitude and local targets, which are not served.
        let capabilities = if self.px4_flavour() {
            C::MAV_PROTOCOL_CAPABILITY_MAVLINK2
                | C::MAV_PROTOCOL_CAPABILITY_COMMAND_INT
                | C::MAV_PROTOCOL_CAPABILITY_MISSION_FLOAT
                | C::MAV_PROTOCOL_CAPABILITY_MISSION_INT
                | C::MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
                | C::MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE
        } else {
            C::MAV_PROTOCOL_CAPABILITY_MAVLINK2
                | C::MAV_PROTOCOL_CAPABILITY_COMMAND_INT
                | C::MAV_PROTOCOL_CAPABILITY_SET_POSITION_TARGET_GLOBAL_INT
                | C::MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
        };
        MavMessage::AUTOPILOT_VERSION(AUTOPILOT_VERSION_DATA {
            capabilities,
            uid: u64::from(self.copters[i].system),
            flight_sw_version: version,
            ..AUTOPILOT_VERSION_DATA::default()
        })
    }
}
