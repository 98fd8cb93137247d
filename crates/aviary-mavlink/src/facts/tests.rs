use std::collections::BTreeMap;

use aviary_world::Drone;
use mavlink::dialects::ardupilotmega::MavParamType::{self, *};

use super::*;

/// The drone `d` of a world whose drone table holds `keys`.
fn drone(keys: &str) -> Drone {
    let text = format!("[drones.d]\nhome = [0, 0]\n{keys}\n");
    let (world, diags) = aviary_world::parse_world(Default::default(), &text);
    let world = world.unwrap_or_else(|| panic!("{diags:?}"));
    world.drones[0].clone()
}

/// Answers as a vehicle sends them: (name, value, type).
fn facts(flavour: Flavour, answers: &[(&str, f32, MavParamType)], charge: Option<f64>) -> Facts {
    let params: BTreeMap<String, (f32, MavParamType)> =
        answers.iter().map(|(n, v, t)| ((*n).to_owned(), (*v, *t))).collect();
    Facts::answered_by(0, "d", "tcp:127.0.0.1:5760", 1, flavour, &params, charge)
}

/// What ArduCopter SITL answered (types as it sends them).
const SITL: &[(&str, f32, MavParamType)] = &[
    ("BATT_CAPACITY", 3300.0, MAV_PARAM_TYPE_INT32),
    ("WPNAV_SPEED_UP", 250.0, MAV_PARAM_TYPE_REAL32),
    ("WPNAV_SPEED_DN", 150.0, MAV_PARAM_TYPE_REAL32),
    ("WPNAV_ACCEL", 250.0, MAV_PARAM_TYPE_REAL32),
    ("LAND_SPEED", 50.0, MAV_PARAM_TYPE_INT16),
    ("LAND_SPEED_HIGH", 0.0, MAV_PARAM_TYPE_INT16),
    ("LAND_ALT_LOW", 1000.0, MAV_PARAM_TYPE_INT16),
    ("RTL_ALT", 1500.0, MAV_PARAM_TYPE_INT32),
    ("RTL_LOIT_TIME", 5000.0, MAV_PARAM_TYPE_INT32),
];

#[test]
fn integers_are_cast_by_ardupilot_and_sent_bytewise_by_px4() {
    assert_eq!(decode(Flavour::ArduPilot, 3300.0, MAV_PARAM_TYPE_INT32), 3300.0);
    assert_eq!(decode(Flavour::Px4, f32::from_bits(3300), MAV_PARAM_TYPE_INT32), 3300.0);
    assert_eq!(decode(Flavour::Px4, f32::from_bits(-1i32 as u32), MAV_PARAM_TYPE_INT32), -1.0);
    assert_eq!(decode(Flavour::Px4, f32::from_bits(0xffff), MAV_PARAM_TYPE_INT16), -1.0);
    assert_eq!(decode(Flavour::Px4, 1.5, MAV_PARAM_TYPE_REAL32), 1.5);
    assert_eq!(decode(Flavour::ArduPilot, 1.5, MAV_PARAM_TYPE_REAL32), 1.5);
}

#[test]
fn sitl_s_parameters_become_the_drone_s_figures_in_si_units() {
    let mut d = drone("flight_current = 30");
    let lines = facts(Flavour::ArduPilot, SITL, Some(100.0)).apply(&mut d);
    assert_eq!(
        (
            d.climb_rate,
            d.descent_rate,
            d.acceleration,
            d.land_speed,
            d.land_speed_below,
            d.return_altitude,
            d.return_loiter
        ),
        (2.5, 1.5, 2.5, 0.5, 10.0, 15.0, 5.0)
    );
    assert_eq!(d.battery_capacity, Some(3300.0));
    // 3.3 Ah at 30 A: 396 s.
    assert!((d.endurance - 396.0).abs() < 1e-9, "{}", d.endurance);
    assert_eq!(d.battery, 100.0);
    // One line per figure that differs from the world's defaults (3 m/s, 3 m/s², 10 m,
    // no wait, 30 min): land_speed_below (10 m) and the charge (100 %) agree.
    let expected = [
        "d: climb 2.5 m/s (the vehicle's WPNAV_SPEED_UP), not the world's 3 m/s",
        "d: descent 1.5 m/s (the vehicle's WPNAV_SPEED_DN), not the world's 3 m/s",
        "d: acceleration 2.5 m/s² (the vehicle's WPNAV_ACCEL), not the world's 3 m/s²",
        "d: landing speed 0.5 m/s (the vehicle's LAND_SPEED), not the world's 3 m/s",
        "d: return altitude 15 m (the vehicle's RTL_ALT), not the world's 10 m",
        "d: wait above home 5 s (the vehicle's RTL_LOIT_TIME), not the world's 0 s",
        "d: battery 3300 mAh (the vehicle's BATT_CAPACITY); the world gave none",
        "d: endurance 6.6 min (3300 mAh at the world's flight_current 30 A), not the world's 30 min",
    ];
    assert_eq!(lines, expected);
    // LAND_SPEED_HIGH 0: the landing starts at WPNAV_SPEED_DN.
    let landing = facts(Flavour::ArduPilot, SITL, Some(100.0)).landing(&d);
    assert_eq!((landing.rate, landing.land_speed, landing.slow_below), (1.5, 0.5, 10.0));
}

#[test]
fn figures_the_world_already_has_say_nothing() {
    let mut d = drone(
        "climb_rate = 2.5\ndescent_rate = 1.5\nacceleration = 2.5\nland_speed = 0.5\nreturn_altitude = 15\nreturn_loiter = 5\nbattery_capacity = 3300\nflight_current = 30",
    );
    let before = d.clone();
    assert_eq!(facts(Flavour::ArduPilot, SITL, Some(100.0)).apply(&mut d), Vec::<String>::new());
    assert_eq!(d, before);
}

#[test]
fn the_vehicle_s_charge_is_the_start_charge() {
    let mut d = drone("");
    let lines = facts(Flavour::ArduPilot, SITL, Some(87.0)).apply(&mut d);
    assert_eq!(d.battery, 87.0);
    assert!(
        lines.contains(
            &"d: charge 87% (the vehicle's battery_remaining), not the world's 100%".to_owned()
        ),
        "{lines:?}"
    );
    let mut d = drone("battery = 90");
    let lines = facts(Flavour::ArduPilot, SITL, None).apply(&mut d);
    assert_eq!(d.battery, 90.0);
    assert!(
        lines.contains(&"d: the vehicle reports no charge: the world's 90% kept".to_owned()),
        "{lines:?}"
    );
}

#[test]
fn without_the_world_s_draw_the_capacity_does_not_change_the_endurance() {
    let mut d = drone("endurance = 900");
    let lines = facts(Flavour::ArduPilot, SITL, Some(100.0)).apply(&mut d);
    assert_eq!((d.endurance, d.battery_capacity), (900.0, Some(3300.0)));
    assert!(
        lines.iter().any(|l| l.contains("no `flight_current`") && l.contains("15 min")),
        "{lines:?}"
    );
}

#[test]
fn unanswered_and_unusable_parameters_keep_the_world_s_figures_and_say_so() {
    let answers: Vec<_> = SITL
        .iter()
        .filter(|(n, _, _)| !matches!(*n, "WPNAV_ACCEL" | "RTL_ALT"))
        .map(|&(n, v, t)| if n == "WPNAV_SPEED_UP" { (n, 0.0, t) } else { (n, v, t) })
        .collect();
    let mut d = drone("");
    let f = facts(Flavour::ArduPilot, &answers, Some(100.0));
    let lines = f.apply(&mut d);
    assert_eq!((d.climb_rate, d.acceleration, d.return_altitude), (3.0, 3.0, 10.0), "the world's");
    assert_eq!(d.descent_rate, 1.5, "the answered ones apply");
    assert!(
        lines.contains(
            &"d: the vehicle's WPNAV_SPEED_UP is 0 cm/s, no usable climb: the world's kept"
                .to_owned()
        ),
        "{lines:?}"
    );
    assert_eq!(
        lines.last().map(String::as_str),
        Some(
            "d: no answer for WPNAV_ACCEL, RTL_ALT: the world's acceleration, return_altitude kept"
        )
    );
    assert!(f.source().contains("7 of 9 parameters answered"), "{}", f.source());
}

#[test]
fn a_vehicle_not_heard_changes_nothing() {
    let mut d = drone("flight_current = 30");
    let before = d.clone();
    let f = Facts::unheard(0, "d", "tcp:127.0.0.1:5760", 1, "no HEARTBEAT".into());
    assert!(f.apply(&mut d).is_empty());
    assert_eq!(d, before);
    assert_eq!(f.source(), "d: no answer from tcp:127.0.0.1:5760 (system 1): no HEARTBEAT; planned with the world's figures");
    // Heard, but it serves no parameters (`aviary vehicles`).
    let f = facts(Flavour::ArduPilot, &[], Some(100.0));
    f.apply(&mut d);
    assert_eq!((d.climb_rate, d.endurance), (before.climb_rate, before.endurance));
    assert!(f.source().contains("answered no parameter"), "{}", f.source());
}

#[test]
fn land_speed_high_is_the_battery_rule_s_landing() {
    let answers: Vec<_> = SITL
        .iter()
        .map(|&(n, v, t)| if n == "LAND_SPEED_HIGH" { (n, 200.0, t) } else { (n, v, t) })
        .collect();
    let mut d = drone("");
    let f = facts(Flavour::ArduPilot, &answers, Some(100.0));
    let lines = f.apply(&mut d);
    assert_eq!(d.descent_rate, 1.5, "the world's descents stay WPNAV_SPEED_DN");
    assert_eq!(f.landing(&d).rate, 2.0);
    assert!(
        lines
            .iter()
            .any(|l| l.contains("lands from high at 2 m/s (the vehicle's LAND_SPEED_HIGH)")),
        "{lines:?}"
    );
}

#[test]
fn px4_s_parameters_are_in_si_units_and_minus_one_means_unset() {
    let answers = [
        ("MPC_Z_V_AUTO_UP", 3.0, MAV_PARAM_TYPE_REAL32),
        ("MPC_Z_V_AUTO_DN", 1.0, MAV_PARAM_TYPE_REAL32),
        ("MPC_TKO_SPEED", 1.5, MAV_PARAM_TYPE_REAL32),
        ("MPC_XY_CRUISE", 5.0, MAV_PARAM_TYPE_REAL32),
        ("MPC_LAND_SPEED", 0.7, MAV_PARAM_TYPE_REAL32),
        ("MPC_LAND_ALT1", 10.0, MAV_PARAM_TYPE_REAL32),
        ("RTL_RETURN_ALT", 60.0, MAV_PARAM_TYPE_REAL32),
        ("RTL_LAND_DELAY", -1.0, MAV_PARAM_TYPE_REAL32),
        ("BAT1_CAPACITY", -1.0, MAV_PARAM_TYPE_REAL32),
    ];
    let mut d = drone("");
    let lines = facts(Flavour::Px4, &answers, Some(100.0)).apply(&mut d);
    assert_eq!((d.descent_rate, d.return_altitude), (1.0, 60.0));
    assert!((d.land_speed - 0.7).abs() < 1e-6);
    // Up from the ground at MPC_TKO_SPEED, home at MPC_XY_CRUISE.
    assert_eq!((d.takeoff_speed, d.return_speed), (1.5, 5.0));
    assert!(
        lines.iter().any(|l| l.contains("take-off speed 1.5 m/s (the vehicle's MPC_TKO_SPEED)")),
        "{lines:?}"
    );
    assert_eq!((d.return_loiter, d.battery_capacity), (0.0, None), "-1 is no usable figure");
    assert!(lines.iter().any(|l| l.contains("RTL_LAND_DELAY is -1 s")), "{lines:?}");
    assert!(lines.iter().any(|l| l.contains("no answer for MPC_ACC_HOR")), "{lines:?}");
}

#[test]
fn only_the_facts_parameters_are_kept() {
    assert!(wanted("BATT_CAPACITY") && wanted("MPC_LAND_SPEED"));
    assert!(!wanted("BARO1_GND_PRESS"));
}

#[test]
fn numbers_read_as_people_write_them() {
    assert_eq!(
        (num(3.0), num(1.5), num(0.25), num(6.6), num(-0.0)),
        ("3".into(), "1.5".into(), "0.25".into(), "6.6".into(), "0".into())
    );
}
