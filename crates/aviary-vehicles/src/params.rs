//! The parameter protocol over a small table of what the simulated vehicle really uses,
//! under ArduCopter's names and types, with ArduPilot's encoding (every value a float,
//! integers as their float value with their type).
//!
//! Only WPNAV_SPEED can be changed (it is the speed GUIDED flights start with). The others
//! are the world's airframe and site, which the simulator fixes: a PARAM_SET of one is
//! answered as ArduPilot answers a read-only parameter ("Param write denied" and the value
//! unchanged). As ArduPilot: an unknown name, or a value that is not a number, gets no
//! answer; a read by name answers with index 65535 (ArduPilot echoes the -1 it was sent);
//! a PARAM_VALUE for a change goes to every client, a read or a list only to the asker.

use aviary_api::flight::return_height;
use aviary_mavlink::mavlink::dialects::ardupilotmega::MavMessage;
use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavParamType, MavSeverity, PARAM_VALUE_DATA,
};

use crate::autopilot::{text, Autopilot, Out, Reply};

pub struct Param {
    pub name: &'static str,
    pub kind: MavParamType,
    pub value: f32,
    pub writable: bool,
}

fn param(name: &'static str, kind: MavParamType, value: f64) -> Param {
    Param { name, kind, value: value as f32, writable: false }
}

impl Autopilot {
    /// The world limits the simulator enforces (its geofence or its altitude limit).
    pub fn fence_enabled(&self) -> bool {
        self.fence.0 || self.fence.1.is_some()
    }

    /// The table of vehicle `i`, in name order (the order of the indexes).
    pub fn params(&self, i: usize) -> Vec<Param> {
        use MavParamType::*;
        let c = &self.copters[i];
        let (polygon, ceiling) = self.fence;
        let mut t = vec![
            // 1, "all": the simulated vehicle makes every pre-arm check it has (boot, the
            // GPS fix and position estimate, an armable mode); none can be skipped.
            param("ARMING_CHECK", MAV_PARAM_TYPE_INT32, 1.0),
            // FENCE_TYPE's bits: 1 altitude limit, 4 polygon.
            param("FENCE_ENABLE", MAV_PARAM_TYPE_INT8, f64::from(u8::from(self.fence_enabled()))),
            param(
                "FENCE_TYPE",
                MAV_PARAM_TYPE_INT8,
                f64::from(u8::from(ceiling.is_some()) | (4 * u8::from(polygon))),
            ),
            // The simulator lands at land_speed in the last land_speed_below metres.
            param("LAND_ALT_LOW", MAV_PARAM_TYPE_INT16, (c.descent.slow_below * 100.0).round()),
            param("LAND_SPEED", MAV_PARAM_TYPE_INT16, (c.descent.land_speed * 100.0).round()),
            param("MAV_SYSID", MAV_PARAM_TYPE_INT16, f64::from(c.system)),
            // An RTL climbs to at least this (cm): the height one from the ground flies home
            // at, the return altitude kept under the site's ceiling.
            param(
                "RTL_ALT",
                MAV_PARAM_TYPE_INT32,
                (return_height(0.0, c.return_altitude, ceiling) * 100.0).round(),
            ),
            // The wait above home before an RTL lands (ms).
            param("RTL_LOIT_TIME", MAV_PARAM_TYPE_INT32, (c.return_loiter * 1000.0).round()),
            param("WPNAV_ACCEL", MAV_PARAM_TYPE_REAL32, c.acceleration * 100.0),
            Param {
                writable: true,
                ..param("WPNAV_SPEED", MAV_PARAM_TYPE_REAL32, c.wpnav_speed * 100.0)
            },
            param("WPNAV_SPEED_DN", MAV_PARAM_TYPE_REAL32, c.descent.rate * 100.0),
            param("WPNAV_SPEED_UP", MAV_PARAM_TYPE_REAL32, c.climb_rate * 100.0),
        ];
        if let Some(max) = ceiling {
            t.push(param("FENCE_ALT_MAX", MAV_PARAM_TYPE_REAL32, max));
        }
        // Only a world that gives the capacity has one: the simulated battery is a flight
        // time (`endurance`), which with `flight_current` the capacity sets.
        if let Some(mah) = c.battery_capacity {
            t.push(param("BATT_CAPACITY", MAV_PARAM_TYPE_INT32, mah.round()));
        }
        t.sort_by_key(|p| p.name);
        t
    }

    /// PARAM_REQUEST_LIST: every parameter, with its index.
    pub fn param_list(&self, i: usize) -> Vec<Reply> {
        let system = self.copters[i].system;
        let t = self.params(i);
        let count = t.len();
        t.iter().enumerate().map(|(k, p)| Reply::asker(system, value(p, count, k as u16))).collect()
    }

    /// PARAM_REQUEST_READ, by index when it is not negative, else by name.
    pub fn param_read(&self, i: usize, name: &str, index: i16) -> Vec<Reply> {
        let system = self.copters[i].system;
        let t = self.params(i);
        let found = match usize::try_from(index) {
            Ok(k) => t.get(k).map(|p| (p, k as u16)),
            Err(_) => t.iter().find(|p| p.name == name).map(|p| (p, u16::MAX)),
        };
        found.map(|(p, k)| Reply::asker(system, value(p, t.len(), k))).into_iter().collect()
    }

    /// PARAM_SET: what every client is told.
    pub fn param_set(&mut self, i: usize, name: &str, v: f32) -> Vec<Reply> {
        let system = self.copters[i].system;
        let t = self.params(i);
        let Some(p) = t.iter().find(|p| p.name == name) else {
            return Vec::new();
        };
        if !v.is_finite() {
            return Vec::new();
        }
        let mut out = Vec::new();
        if !p.writable {
            let why = format!("Param write denied ({name})");
            out.push(Reply::all(text(system, MavSeverity::MAV_SEVERITY_WARNING, &why)));
        } else if name == "WPNAV_SPEED" {
            // At least 0.2 m/s, at most what the airframe can fly (the world's max_speed):
            // the value answered is the one flown.
            let c = &mut self.copters[i];
            c.wpnav_speed = (f64::from(v) / 100.0).clamp(0.2_f64.min(c.max_speed), c.max_speed);
            c.speed = c.wpnav_speed;
        }
        let t = self.params(i);
        if let Some(p) = t.iter().find(|p| p.name == name) {
            out.push(Reply::all(Out { system, msg: value(p, t.len(), u16::MAX).into() }));
        }
        out
    }
}

fn value(p: &Param, count: usize, index: u16) -> MavMessage {
    MavMessage::PARAM_VALUE(PARAM_VALUE_DATA {
        param_value: p.value,
        param_count: count as u16,
        param_index: index,
        param_id: p.name.into(),
        param_type: p.kind,
    })
}
