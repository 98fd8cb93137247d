//! The messages each simulated vehicle sends on its own (the streams, each at a rate every
//! client can change with SET_MESSAGE_INTERVAL or REQUEST_DATA_STREAM): HEARTBEAT,
//! SYS_STATUS, GPS_RAW_INT, GLOBAL_POSITION_INT, BATTERY_STATUS, EKF_STATUS_REPORT,
//! EXTENDED_SYS_STATE, and HOME_POSITION (off unless asked for, as on ArduPilot), from the
//! simulator's telemetry.

use aviary_api::{DroneId, FlightState};
use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavBatteryFunction, MavBatteryType, MavLandedState, MavMessage, MavModeFlag,
    MavState, MavSysStatusSensor, MavType, MavVtolState, BATTERY_STATUS_DATA,
    EXTENDED_SYS_STATE_DATA, GLOBAL_POSITION_INT_DATA, HEARTBEAT_DATA, SYS_STATUS_DATA,
};
use aviary_mavlink::mode::COPTER_GUIDED;

use crate::autopilot::Autopilot;

/// (message id, default rate in Hz) of every stream. ArduPilot streams nothing but
/// HEARTBEAT until a ground station asks; these defaults let a client that asks for
/// nothing (pymavlink, `aviary run` before its SET_MESSAGE_INTERVAL) see the vehicle.
pub const STREAMS: &[(u32, f64)] = &[
    (0, 1.0),   // HEARTBEAT
    (1, 1.0),   // SYS_STATUS
    (24, 1.0),  // GPS_RAW_INT
    (33, 4.0),  // GLOBAL_POSITION_INT
    (147, 1.0), // BATTERY_STATUS
    (193, 1.0), // EKF_STATUS_REPORT
    (242, 0.0), // HOME_POSITION: sent when home is set, on request, or at an asked rate
    (245, 1.0), // EXTENDED_SYS_STATE
];

/// PX4's streams on a link to a ground station, at its rates (mavlink_main.cpp's normal
/// mode; MISSION_CURRENT from the mission manager at 1 Hz). PX4 has no EKF_STATUS_REPORT.
pub const PX4_STREAMS: &[(u32, f64)] = &[
    (0, 1.0),   // HEARTBEAT
    (1, 1.0),   // SYS_STATUS
    (24, 5.0),  // GPS_RAW_INT
    (33, 5.0),  // GLOBAL_POSITION_INT
    (42, 1.0),  // MISSION_CURRENT
    (147, 0.5), // BATTERY_STATUS
    (242, 0.5), // HOME_POSITION, once home is set
    (245, 1.0), // EXTENDED_SYS_STATE
];

/// The streams of REQUEST_DATA_STREAM's groups, as ArduPilot groups them (MAV_DATA_STREAM
/// ALL 0, EXTENDED_STATUS 2, POSITION 6, EXTRA3 12).
pub fn stream_group(group: u8) -> &'static [u32] {
    match group {
        0 => &[1, 24, 33, 147, 193, 245],
        2 => &[1, 24],
        6 => &[33],
        12 => &[147, 193, 245],
        _ => &[],
    }
}

impl Autopilot {
    /// The streams of the autopilot served.
    pub fn streams(&self) -> &'static [(u32, f64)] {
        if self.px4_flavour() {
            PX4_STREAMS
        } else {
            STREAMS
        }
    }

    /// Any message the vehicle can send, by id: a stream, HOME_POSITION once home is set,
    /// AUTOPILOT_VERSION (for MAV_CMD_REQUEST_MESSAGE).
    pub fn message(&self, i: usize, id: u32) -> Option<MavMessage> {
        if self.px4_flavour() {
            return match id {
                42 => Some(self.px4_mission_current(i)),
                193 => None,
                _ => self.any_message(i, id),
            };
        }
        self.any_message(i, id)
    }

    fn any_message(&self, i: usize, id: u32) -> Option<MavMessage> {
        match id {
            0 => Some(self.heartbeat(i)),
            1 => self.sys_status(i),
            24 => self.gps_raw_int(i),
            33 => self.position(i),
            147 => self.battery_status(i),
            148 => Some(self.autopilot_version(i)),
            193 => Some(self.ekf_status(i)),
            242 => self.home_position(i),
            245 => self.extended_sys_state(i),
            _ => None,
        }
    }

    pub fn heartbeat(&self, i: usize) -> MavMessage {
        if self.px4_flavour() {
            return self.px4_heartbeat(i);
        }
        let c = &self.copters[i];
        let state = self.fleet.telemetry(DroneId(i)).map_or(FlightState::Lost, |t| t.state);
        let mut base = MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED
            | MavModeFlag::MAV_MODE_FLAG_STABILIZE_ENABLED;
        if c.mode == COPTER_GUIDED {
            base |= MavModeFlag::MAV_MODE_FLAG_GUIDED_ENABLED;
        }
        if c.armed {
            base |= MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED;
        }
        // As ArduCopter: CRITICAL in a failsafe, STANDBY on the ground (armed or not),
        // ACTIVE in the air; BOOT (which ArduCopter does not show on the ground) marks the
        // simulated boot, when mode changes are refused.
        let status = if self.booting() {
            MavState::MAV_STATE_BOOT
        } else if state == FlightState::Lost {
            MavState::MAV_STATE_EMERGENCY
        } else if c.failsafe {
            MavState::MAV_STATE_CRITICAL
        } else if state.airborne() {
            MavState::MAV_STATE_ACTIVE
        } else {
            MavState::MAV_STATE_STANDBY
        };
        MavMessage::HEARTBEAT(HEARTBEAT_DATA {
            custom_mode: c.mode,
            mavtype: MavType::MAV_TYPE_QUADROTOR,
            autopilot: MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA,
            base_mode: base,
            system_status: status,
            mavlink_version: 3,
        })
    }

    /// PX4's HEARTBEAT (streams/HEARTBEAT.hpp): MAV_AUTOPILOT_PX4, the mode in
    /// `custom_mode`, the base mode of its controls (AUTO, GUIDED and STABILIZE in the auto
    /// modes, MANUAL_INPUT in the manual ones), and the state: ACTIVE armed (CRITICAL in
    /// a failsafe), STANDBY when it could arm, else UNINIT.
    fn px4_heartbeat(&self, i: usize) -> MavMessage {
        let c = &self.copters[i];
        let nav = c.px4.nav;
        let state = self.fleet.telemetry(DroneId(i)).map_or(FlightState::Lost, |t| t.state);
        let mut base = MavModeFlag::MAV_MODE_FLAG_CUSTOM_MODE_ENABLED;
        if c.armed {
            base |= MavModeFlag::MAV_MODE_FLAG_SAFETY_ARMED;
        }
        if nav.manual() {
            base |= MavModeFlag::MAV_MODE_FLAG_MANUAL_INPUT_ENABLED;
        }
        if nav != crate::px4::Nav::Acro {
            base |= MavModeFlag::MAV_MODE_FLAG_STABILIZE_ENABLED;
        }
        if nav.auto() {
            base |=
                MavModeFlag::MAV_MODE_FLAG_AUTO_ENABLED | MavModeFlag::MAV_MODE_FLAG_GUIDED_ENABLED;
        }
        let status = if state == FlightState::Lost {
            MavState::MAV_STATE_EMERGENCY
        } else if c.armed && c.failsafe {
            MavState::MAV_STATE_CRITICAL
        } else if c.armed {
            MavState::MAV_STATE_ACTIVE
        } else if self.px4_can_arm(i) {
            MavState::MAV_STATE_STANDBY
        } else {
            MavState::MAV_STATE_UNINIT
        };
        MavMessage::HEARTBEAT(HEARTBEAT_DATA {
            custom_mode: nav.custom_mode(),
            mavtype: MavType::MAV_TYPE_QUADROTOR,
            autopilot: MavAutopilot::MAV_AUTOPILOT_PX4,
            base_mode: base,
            system_status: status,
            mavlink_version: 3,
        })
    }

    pub fn position(&self, i: usize) -> Option<MavMessage> {
        let t = self.fleet.telemetry(DroneId(i))?;
        let [x, y, z] = t.position;
        let (lat, lon) = self.origin.to_e7(x, y);
        let h = t.heading.to_radians();
        Some(MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
            time_boot_ms: (self.fleet.time() * 1000.0) as u32,
            lat,
            lon,
            alt: ((self.origin.alt + z) * 1000.0).round() as i32,
            relative_alt: (z * 1000.0).round() as i32,
            // North, east, down in cm/s.
            vx: (t.speed * h.cos() * 100.0).round() as i16,
            vy: (t.speed * h.sin() * 100.0).round() as i16,
            vz: 0,
            hdg: ((t.heading.rem_euclid(360.0)) * 100.0).round() as u16,
        }))
    }

    /// SYS_STATUS with the sensor bits ground stations judge a vehicle by (MAVSDK's health:
    /// GPS present, enabled and healthy is a global position; PREARM_CHECK healthy is
    /// armable). The simulated sensors are perfect; what is not ready until the pre-arm
    /// time is the GPS fix, the attitude and position estimate (AHRS) and so the pre-arm
    /// checks. The geofence is present always (as ArduPilot's), enabled when the world has
    /// one or an altitude limit, healthy always (the simulator refuses to cross it); the
    /// battery turns unhealthy with its failsafe.
    pub fn sys_status(&self, i: usize) -> Option<MavMessage> {
        use MavSysStatusSensor as S;
        let t = self.fleet.telemetry(DroneId(i))?;
        let always = S::MAV_SYS_STATUS_SENSOR_3D_GYRO
            | S::MAV_SYS_STATUS_SENSOR_3D_ACCEL
            | S::MAV_SYS_STATUS_SENSOR_3D_MAG
            | S::MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
            | S::MAV_SYS_STATUS_SENSOR_ANGULAR_RATE_CONTROL
            | S::MAV_SYS_STATUS_SENSOR_ATTITUDE_STABILIZATION
            | S::MAV_SYS_STATUS_SENSOR_YAW_POSITION
            | S::MAV_SYS_STATUS_SENSOR_Z_ALTITUDE_CONTROL
            | S::MAV_SYS_STATUS_SENSOR_XY_POSITION_CONTROL
            | S::MAV_SYS_STATUS_SENSOR_MOTOR_OUTPUTS;
        let fixed =
            S::MAV_SYS_STATUS_SENSOR_GPS | S::MAV_SYS_STATUS_AHRS | S::MAV_SYS_STATUS_PREARM_CHECK;
        let present =
            always | fixed | S::MAV_SYS_STATUS_SENSOR_BATTERY | S::MAV_SYS_STATUS_GEOFENCE;
        let mut enabled = present;
        if !self.fence_enabled() {
            enabled.remove(S::MAV_SYS_STATUS_GEOFENCE);
        }
        let mut health = always | S::MAV_SYS_STATUS_GEOFENCE;
        if self.ready() {
            health |= fixed;
        }
        if self.px4_flavour() && !self.px4_can_arm(i) {
            // PX4's pre-arm bit is its canArm in the mode it is in.
            health.remove(S::MAV_SYS_STATUS_PREARM_CHECK);
        }
        if !self.copters[i].failsafe {
            health |= S::MAV_SYS_STATUS_SENSOR_BATTERY;
        }
        Some(MavMessage::SYS_STATUS(SYS_STATUS_DATA {
            onboard_control_sensors_present: present,
            onboard_control_sensors_enabled: enabled,
            onboard_control_sensors_health: health,
            // A simulated 3S battery: 12.6 V full, 10.5 V empty.
            voltage_battery: (10_500.0 + 2_100.0 * t.battery) as u16,
            current_battery: -1,
            battery_remaining: remaining(t.battery),
            ..SYS_STATUS_DATA::default()
        }))
    }

    pub fn battery_status(&self, i: usize) -> Option<MavMessage> {
        let t = self.fleet.telemetry(DroneId(i))?;
        Some(MavMessage::BATTERY_STATUS(BATTERY_STATUS_DATA {
            current_consumed: -1,
            energy_consumed: -1,
            temperature: i16::MAX,
            voltages: [u16::MAX; 10],
            current_battery: -1,
            id: 0,
            battery_function: MavBatteryFunction::MAV_BATTERY_FUNCTION_ALL,
            mavtype: MavBatteryType::MAV_BATTERY_TYPE_LIPO,
            battery_remaining: remaining(t.battery),
            ..BATTERY_STATUS_DATA::default()
        }))
    }

    pub fn extended_sys_state(&self, i: usize) -> Option<MavMessage> {
        let t = self.fleet.telemetry(DroneId(i))?;
        let landed = match t.state {
            FlightState::Landed | FlightState::Lost => MavLandedState::MAV_LANDED_STATE_ON_GROUND,
            FlightState::TakingOff => MavLandedState::MAV_LANDED_STATE_TAKEOFF,
            FlightState::Flying => MavLandedState::MAV_LANDED_STATE_IN_AIR,
            FlightState::Landing => MavLandedState::MAV_LANDED_STATE_LANDING,
        };
        Some(MavMessage::EXTENDED_SYS_STATE(EXTENDED_SYS_STATE_DATA {
            vtol_state: MavVtolState::MAV_VTOL_STATE_UNDEFINED,
            landed_state: landed,
        }))
    }
}

fn remaining(battery: f64) -> i8 {
    (battery * 100.0).round().clamp(0.0, 100.0) as i8
}
