//! The messages each simulated vehicle sends on its own: HEARTBEAT, GLOBAL_POSITION_INT,
//! SYS_STATUS, BATTERY_STATUS and EXTENDED_SYS_STATE, from the simulator's telemetry.

use aviary_api::FlightState;
use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavBatteryFunction, MavBatteryType, MavLandedState, MavMessage, MavModeFlag,
    MavState, MavSysStatusSensor, MavType, MavVtolState, BATTERY_STATUS_DATA,
    EXTENDED_SYS_STATE_DATA, GLOBAL_POSITION_INT_DATA, HEARTBEAT_DATA, SYS_STATUS_DATA,
};
use aviary_mavlink::mode::COPTER_GUIDED;

use crate::autopilot::Autopilot;

impl Autopilot {
    pub fn heartbeat(&self, i: usize) -> MavMessage {
        let c = &self.copters[i];
        let state = self
            .fleet
            .telemetry(i)
            .map_or(FlightState::Lost, |t| t.state);
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

    pub fn position(&self, i: usize) -> Option<MavMessage> {
        let t = self.fleet.telemetry(i)?;
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

    /// SYS_STATUS, BATTERY_STATUS and EXTENDED_SYS_STATE.
    pub fn status(&self, i: usize) -> Vec<MavMessage> {
        let Some(t) = self.fleet.telemetry(i) else {
            return Vec::new();
        };
        let remaining = (t.battery * 100.0).round().clamp(0.0, 100.0) as i8;
        let sensors = MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_GPS
            | MavSysStatusSensor::MAV_SYS_STATUS_SENSOR_3D_GYRO;
        let landed = match t.state {
            FlightState::Landed | FlightState::Lost => MavLandedState::MAV_LANDED_STATE_ON_GROUND,
            FlightState::TakingOff => MavLandedState::MAV_LANDED_STATE_TAKEOFF,
            FlightState::Flying => MavLandedState::MAV_LANDED_STATE_IN_AIR,
            FlightState::Landing => MavLandedState::MAV_LANDED_STATE_LANDING,
        };
        vec![
            MavMessage::SYS_STATUS(SYS_STATUS_DATA {
                onboard_control_sensors_present: sensors,
                onboard_control_sensors_enabled: sensors,
                onboard_control_sensors_health: sensors,
                load: 0,
                voltage_battery: (10_500.0 + 2_100.0 * t.battery) as u16,
                current_battery: -1,
                drop_rate_comm: 0,
                errors_comm: 0,
                errors_count1: 0,
                errors_count2: 0,
                errors_count3: 0,
                errors_count4: 0,
                battery_remaining: remaining,
            }),
            MavMessage::BATTERY_STATUS(BATTERY_STATUS_DATA {
                current_consumed: -1,
                energy_consumed: -1,
                temperature: i16::MAX,
                voltages: [u16::MAX; 10],
                current_battery: -1,
                id: 0,
                battery_function: MavBatteryFunction::MAV_BATTERY_FUNCTION_ALL,
                mavtype: MavBatteryType::MAV_BATTERY_TYPE_LIPO,
                battery_remaining: remaining,
            }),
            MavMessage::EXTENDED_SYS_STATE(EXTENDED_SYS_STATE_DATA {
                vtol_state: MavVtolState::MAV_VTOL_STATE_UNDEFINED,
                landed_state: landed,
            }),
        ]
    }
}
