//! PX4's parameters over what the simulated vehicle uses: PX4's names, types (INT32 or
//! REAL32, the only two PX4 has) and units, and PX4's encoding, in which an INT32 travels
//! as its four bytes in PARAM_VALUE's float (MAV_PROTOCOL_CAPABILITY_PARAM_ENCODE_BYTEWISE,
//! mavlink_parameters.cpp). What the protocol does is PX4's too: a list starts with
//! `_HASH_CHECK` (UINT32, index -1), a read by name answers with the parameter's index, a
//! PARAM_SET of an unknown name or of another type than the parameter's is not answered.
//!
//! The simulator can change MIS_TAKEOFF_ALT, MPC_XY_CRUISE (within the airframe's
//! MPC_XY_VEL_MAX) and NAV_ACC_RAD; a PARAM_SET of any other is answered with the value
//! kept, which is what the simulated drone flies (PX4 would take it).

use aviary_api::flight::return_height;
use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavMessage, MavParamType, PARAM_VALUE_DATA,
};

use crate::autopilot::{Autopilot, Out, Reply};
use crate::params::Param;

fn real(name: &'static str, value: f64) -> Param {
    Param { name, kind: MavParamType::MAV_PARAM_TYPE_REAL32, value: value as f32, writable: false }
}

/// An INT32 as PX4 sends it: its bytes in the float.
fn int(name: &'static str, value: i32) -> Param {
    Param {
        name,
        kind: MavParamType::MAV_PARAM_TYPE_INT32,
        value: f32::from_bits(value as u32),
        writable: false,
    }
}

fn writable(p: Param) -> Param {
    Param { writable: true, ..p }
}

impl Autopilot {
    /// Vehicle `i`'s table, in name order (the order of the indexes, as PX4's).
    pub(crate) fn px4_params(&self, i: usize) -> Vec<Param> {
        let c = &self.copters[i];
        let p = &c.px4;
        let (_, ceiling) = self.fence;
        // An RTL climbs to at least this above home (the world's return altitude, kept
        // under the site's ceiling) and comes down there: it neither descends to a lower
        // RTL_DESCEND_ALT first nor waits elsewhere than above home.
        let rtl = return_height(0.0, c.return_altitude, ceiling);
        let mut t = vec![
            // Unset (-1) when the world gives none: the simulated battery is a flight time.
            real("BAT1_CAPACITY", c.battery_capacity.map_or(-1.0, f64::round)),
            real("COM_DISARM_LAND", super::DISARM_LAND),
            real("COM_DISARM_PRFLT", super::DISARM_PREFLIGHT),
            // 3: Return at a critical battery (a world `battery_critical` fault).
            int("COM_LOW_BAT_ACT", 3),
            // 2: Hold, PX4's default geofence action; the simulator refuses to cross.
            int("GF_ACTION", 2),
            // The world's polygon is not a PX4 fence (no fence is served as a mission);
            // its ceiling is the vertical limit. 0: not set.
            real("GF_MAX_HOR_DIST", 0.0),
            real("GF_MAX_VER_DIST", ceiling.unwrap_or(0.0)),
            int("MAV_SYS_ID", i32::from(c.system)),
            real("MC_ORBIT_RAD_MAX", 1000.0),
            writable(real("MIS_TAKEOFF_ALT", p.takeoff_alt)),
            // The limit, of which PX4's paths average a share: the world's figure.
            real("MPC_ACC_HOR", c.acceleration / aviary_mavlink::facts::PX4_ACCELERATION_SHARE),
            // A landing slows to MPC_LAND_SPEED below MPC_LAND_ALT1 and is at it from
            // MPC_LAND_ALT2; the simulator slows at once, at the world's land_speed_below.
            real("MPC_LAND_ALT1", c.descent.slow_below),
            real("MPC_LAND_ALT2", c.descent.slow_below),
            real("MPC_LAND_SPEED", c.descent.land_speed),
            real("MPC_TKO_SPEED", c.takeoff_speed),
            writable(real("MPC_XY_CRUISE", p.xy_cruise)),
            real("MPC_XY_VEL_MAX", c.max_speed),
            real("MPC_Z_VEL_MAX_DN", c.descent.rate),
            real("MPC_Z_VEL_MAX_UP", c.climb_rate),
            real("MPC_Z_V_AUTO_DN", c.descent.rate),
            real("MPC_Z_V_AUTO_UP", c.climb_rate),
            writable(real("NAV_ACC_RAD", p.nav_acc_rad)),
            real("NAV_MC_ALT_RAD", super::ALT_RADIUS),
            int("PD_GRIPPER_EN", i32::from(p.has_gripper)),
            real("PD_GRIPPER_TO", super::GRIPPER_TIME),
            real("RTL_DESCEND_ALT", rtl),
            real("RTL_LAND_DELAY", c.return_loiter),
            real("RTL_RETURN_ALT", rtl),
        ];
        t.sort_by_key(|p| p.name);
        t
    }

    /// PARAM_REQUEST_LIST: `_HASH_CHECK`, then every parameter with its index.
    pub(crate) fn px4_param_list(&self, i: usize) -> Vec<Reply> {
        let system = self.copters[i].system;
        let t = self.px4_params(i);
        let count = t.len() as u16;
        let mut out = vec![Reply::asker(system, hash_check(&t))];
        out.extend(
            t.iter().enumerate().map(|(k, p)| Reply::asker(system, value(p, count, k as u16))),
        );
        out
    }

    /// PARAM_REQUEST_READ, by index when it is not negative, else by name; the answer
    /// carries the parameter's own index either way. `_HASH_CHECK` by name is answered.
    pub(crate) fn px4_param_read(&self, i: usize, name: &str, index: i16) -> Vec<Reply> {
        let system = self.copters[i].system;
        let t = self.px4_params(i);
        if index < 0 && name == "_HASH_CHECK" {
            return vec![Reply::asker(system, hash_check(&t))];
        }
        let found = match usize::try_from(index) {
            Ok(k) => t.get(k).map(|p| (p, k)),
            Err(_) => t.iter().enumerate().find(|(_, p)| p.name == name).map(|(k, p)| (p, k)),
        };
        found
            .map(|(p, k)| Reply::asker(system, value(p, t.len() as u16, k as u16)))
            .into_iter()
            .collect()
    }

    /// PARAM_SET: the value PX4 answers with, to every client; nothing for an unknown
    /// name or another type.
    pub(crate) fn px4_param_set(
        &mut self,
        i: usize,
        name: &str,
        v: f32,
        kind: MavParamType,
    ) -> Vec<Reply> {
        let system = self.copters[i].system;
        let t = self.px4_params(i);
        let Some(p) = t.iter().find(|p| p.name == name) else {
            return Vec::new();
        };
        if p.kind != kind {
            return Vec::new();
        }
        if p.writable && v.is_finite() {
            let c = &mut self.copters[i];
            let v = f64::from(v);
            match name {
                "MIS_TAKEOFF_ALT" => c.px4.takeoff_alt = v,
                // What the airframe can fly, and moving: the value answered is the one flown.
                "MPC_XY_CRUISE" => c.px4.xy_cruise = v.clamp(0.1_f64.min(c.max_speed), c.max_speed),
                "NAV_ACC_RAD" => c.px4.nav_acc_rad = v.max(0.05),
                _ => {}
            }
        }
        let t = self.px4_params(i);
        let k = t.iter().position(|p| p.name == name).unwrap_or(0);
        vec![Reply::all(Out { system, msg: value(&t[k], t.len() as u16, k as u16).into() })]
    }
}

fn value(p: &Param, count: u16, index: u16) -> MavMessage {
    MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
        param_value: p.value,
        param_count: count,
        param_index: index,
        param_id: p.name.into(),
        param_type: p.kind,
    })
}

/// `_HASH_CHECK`: a hash of the names and values (PX4's CRC32 of them; any hash serves a
/// ground station's cache), UINT32 bytewise, index -1, the count of parameters.
fn hash_check(t: &[Param]) -> MavMessage {
    // FNV-1a over the names and the values' bits.
    let mut h: u32 = 0x811c_9dc5;
    for p in t {
        for b in p.name.bytes().chain(p.value.to_bits().to_le_bytes()) {
            h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
        }
    }
    MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
        param_value: f32::from_bits(h),
        param_count: t.len() as u16,
        param_index: u16::MAX,
        param_id: "_HASH_CHECK".into(),
        param_type: MavParamType::MAV_PARAM_TYPE_UINT32,
    })
}
