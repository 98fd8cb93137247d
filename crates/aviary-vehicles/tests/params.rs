//! The parameter protocol, as ArduPilot answers it, over what the simulated vehicle uses.

mod common;

use std::collections::BTreeMap;
use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavCmd, MavMessage, MavParamType, MavResult, COMMAND_INT_DATA, PARAM_REQUEST_LIST_DATA,
    PARAM_REQUEST_READ_DATA, PARAM_SET_DATA, PARAM_VALUE_DATA,
};
use aviary_mavlink::Origin;
use common::{fleet, quick, serve, Gcs, ORIGIN};

const SECOND: Duration = Duration::from_secs(1);

fn value(m: &MavMessage) -> Option<PARAM_VALUE_DATA> {
    match m {
        MavMessage::PARAM_VALUE(v) => Some(v.clone()),
        _ => None,
    }
}

fn name(v: &PARAM_VALUE_DATA) -> String {
    v.param_id.to_str().unwrap_or("").to_owned()
}

async fn read(gcs: &mut Gcs, id: &str, index: i16) -> Option<PARAM_VALUE_DATA> {
    gcs.send(&MavMessage::PARAM_REQUEST_READ(PARAM_REQUEST_READ_DATA {
        param_index: index,
        target_system: 1,
        target_component: 1,
        param_id: id.into(),
    }))
    .await;
    gcs.wait(1, SECOND, value).await
}

async fn set(gcs: &mut Gcs, id: &str, v: f32, kind: MavParamType) {
    gcs.send(&MavMessage::PARAM_SET(PARAM_SET_DATA {
        param_value: v,
        target_system: 1,
        target_component: 1,
        param_id: id.into(),
        param_type: kind,
    }))
    .await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_list_reads_and_sets_answer_as_arducopter() {
    let vehicles = serve(&fleet(1, "max_altitude = 60.0"), 5.0, quick()).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    gcs.send(&MavMessage::PARAM_REQUEST_LIST(PARAM_REQUEST_LIST_DATA {
        target_system: 1,
        target_component: 1,
    }))
    .await;
    let mut list: BTreeMap<u16, PARAM_VALUE_DATA> = BTreeMap::new();
    while let Some(v) = gcs.wait(1, SECOND, value).await {
        assert!(list.insert(v.param_index, v.clone()).is_none(), "index {} twice", v.param_index);
        if list.len() == usize::from(v.param_count) {
            break;
        }
    }
    let count = list.values().next().expect("a PARAM_VALUE").param_count;
    assert_eq!(list.keys().copied().collect::<Vec<_>>(), (0..count).collect::<Vec<_>>());
    let by_name: BTreeMap<String, (f32, MavParamType)> =
        list.values().map(|v| (name(v), (v.param_value, v.param_type))).collect();
    use MavParamType::*;
    // The world's drone: max_speed 8, the default climb_rate and acceleration of 3;
    // RTL climbs to 10 m; the site has a ceiling of 60 m and no polygon.
    for (id, want) in [
        ("WPNAV_SPEED", (800.0, MAV_PARAM_TYPE_REAL32)),
        ("WPNAV_SPEED_UP", (300.0, MAV_PARAM_TYPE_REAL32)),
        ("WPNAV_SPEED_DN", (300.0, MAV_PARAM_TYPE_REAL32)),
        ("WPNAV_ACCEL", (300.0, MAV_PARAM_TYPE_REAL32)),
        ("RTL_ALT", (1000.0, MAV_PARAM_TYPE_INT32)),
        ("MAV_SYSID", (1.0, MAV_PARAM_TYPE_INT16)),
        ("FENCE_ENABLE", (1.0, MAV_PARAM_TYPE_INT8)),
        ("FENCE_TYPE", (1.0, MAV_PARAM_TYPE_INT8)),
        ("FENCE_ALT_MAX", (60.0, MAV_PARAM_TYPE_REAL32)),
        ("ARMING_CHECK", (1.0, MAV_PARAM_TYPE_INT32)),
    ] {
        assert_eq!(by_name.get(id), Some(&want), "{id}");
    }

    // By index: that one, with its index; by name: ArduPilot's index 65535.
    let third = read(&mut gcs, "", 2).await.expect("by index");
    assert_eq!((name(&third), third.param_index), (name(&list[&2]), 2));
    let rtl = read(&mut gcs, "RTL_ALT", -1).await.expect("by name");
    assert_eq!((rtl.param_value, rtl.param_index), (1000.0, u16::MAX));
    assert!(read(&mut gcs, "NO_SUCH_PARAM", -1).await.is_none(), "unknown: no answer");
    assert!(read(&mut gcs, "", count as i16).await.is_none(), "past the end: no answer");

    // Read-only: refused in ArduPilot's words, the value unchanged.
    set(&mut gcs, "WPNAV_ACCEL", 100.0, MAV_PARAM_TYPE_REAL32).await;
    let said = gcs
        .wait(1, SECOND, |m| match m {
            MavMessage::STATUSTEXT(t) => Some(t.text.to_str().unwrap_or("").to_owned()),
            _ => None,
        })
        .await;
    assert_eq!(said.as_deref(), Some("Param write denied (WPNAV_ACCEL)"));
    let v = gcs.wait(1, SECOND, value).await.expect("the value");
    assert_eq!((name(&v), v.param_value), ("WPNAV_ACCEL".into(), 300.0));
    // Unknown, or not a number: ignored, as ArduPilot ignores them.
    set(&mut gcs, "NO_SUCH_PARAM", 1.0, MAV_PARAM_TYPE_REAL32).await;
    set(&mut gcs, "WPNAV_SPEED", f32::NAN, MAV_PARAM_TYPE_REAL32).await;
    assert!(gcs.wait(1, SECOND, value).await.is_none());
    vehicles.stop();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_new_wpnav_speed_is_told_to_every_client_and_flown() {
    let vehicles = serve(&fleet(1, ""), 5.0, quick()).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    let mut other = Gcs::connect(vehicles.address).await;
    gcs.take_off(1, 10.0).await;
    set(&mut gcs, "WPNAV_SPEED", 300.0, MavParamType::MAV_PARAM_TYPE_REAL32).await;
    for g in [&mut gcs, &mut other] {
        let v = g.wait(1, SECOND, value).await.expect("the new value");
        assert_eq!((name(&v), v.param_value), ("WPNAV_SPEED".into(), 300.0));
    }
    // Above the airframe's max_speed (8 m/s): what is answered is what is flown.
    set(&mut other, "WPNAV_SPEED", 5000.0, MavParamType::MAV_PARAM_TYPE_REAL32).await;
    let v = other.wait(1, SECOND, value).await.expect("the value");
    assert_eq!(v.param_value, 800.0);
    set(&mut other, "WPNAV_SPEED", 300.0, MavParamType::MAV_PARAM_TYPE_REAL32).await;
    assert_eq!(other.wait(1, SECOND, value).await.map(|v| v.param_value), Some(300.0));

    // 60 m north in GUIDED: flown at 3 m/s, not the world's 8.
    let o = Origin { lat: ORIGIN.0, lon: ORIGIN.1, alt: ORIGIN.2 };
    let to = o.to_e7(0.0, 60.0);
    gcs.send(&MavMessage::COMMAND_INT(COMMAND_INT_DATA {
        x: to.0,
        y: to.1,
        z: 10.0,
        command: MavCmd::MAV_CMD_DO_REPOSITION,
        target_system: 1,
        target_component: 1,
        frame: aviary_mavlink::mavlink::dialects::ardupilotmega::MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT,
        ..Default::default()
    }))
    .await;
    assert_eq!(
        gcs.ack(1, MavCmd::MAV_CMD_DO_REPOSITION).await.result,
        MavResult::MAV_RESULT_ACCEPTED
    );
    let mut fastest: f64 = 0.0;
    let arrived = gcs
        .wait(1, Duration::from_secs(20), |m| match m {
            MavMessage::GLOBAL_POSITION_INT(p) => {
                fastest = fastest.max(f64::from(p.vx).hypot(f64::from(p.vy)) / 100.0);
                (o.from_e7(p.lat, p.lon)[1] > 59.0).then_some(())
            }
            _ => None,
        })
        .await;
    assert!(arrived.is_some(), "did not arrive");
    assert!((2.9..=3.05).contains(&fastest), "flew at up to {fastest} m/s");
    vehicles.stop();
}
