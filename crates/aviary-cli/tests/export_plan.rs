//! `aviary export-plan`: a drone's part of a mission as QGroundControl's `.plan`, read
//! back as QGC reads it (fileType, version, items, geofence, rally points), each point
//! converted back to the local frame by the one projection.

mod common;

use aviary_api::geo::Origin;
use common::{aviary, repo, scratch};
use serde_json::Value;

const ORIGIN: Origin = Origin { lat: 47.07, lon: 15.44, alt: 350.0 };

/// A `[lat, lon]` of the file, in the local frame.
fn local(v: &Value) -> [f64; 2] {
    ORIGIN.to_local(v[0].as_f64().unwrap(), v[1].as_f64().unwrap())
}

fn near(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).hypot(a[1] - b[1]) < 0.05
}

#[test]
fn scout1_of_the_fire_front_as_a_qgroundcontrol_plan() {
    let dir = scratch("export_plan");
    let out = dir.join("scout1.plan");
    let (code, stdout, err) = aviary(
        &[
            "export-plan",
            "examples/fire_front.mission",
            "--drone",
            "scout1",
            "-o",
            out.to_str().unwrap(),
        ],
        &repo(),
    );
    assert_eq!(code, 0, "{stdout}{err}");
    let plan: Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(plan["fileType"], "Plan");
    assert_eq!(plan["version"], 1);
    let home = &plan["mission"]["plannedHomePosition"];
    assert!(near(local(home), [0.0, 0.0]), "{home}");
    let items = plan["mission"]["items"].as_array().unwrap();
    let commands: Vec<u64> = items.iter().map(|i| i["command"].as_u64().unwrap()).collect();
    assert_eq!(commands.first(), Some(&22), "a takeoff first: {commands:?}");
    assert_eq!(commands.last(), Some(&20), "a return to launch last: {commands:?}");
    assert!(commands[1..commands.len() - 1].iter().all(|&c| c == 16), "{commands:?}");
    for (n, item) in items.iter().enumerate() {
        assert_eq!(item["type"], "SimpleItem");
        assert_eq!(item["doJumpId"], n + 1);
    }
    // Taken off to 30 m; flies around the fire to the water point, then circles the fire.
    assert_eq!(items[0]["params"][6], 30.0);
    let ways: Vec<[f64; 2]> = items[1..items.len() - 1]
        .iter()
        .map(|i| local(&Value::Array(vec![i["params"][4].clone(), i["params"][5].clone()])))
        .collect();
    assert!(ways.iter().any(|w| near(*w, [600.0, 0.0])), "the water point: {ways:?}");
    assert!(ways.iter().all(|w| w[0].abs() <= 800.0 && w[1].abs() <= 800.0), "{ways:?}");
    assert!(items[1..items.len() - 1].iter().all(|i| i["params"][6] == 30.0 && i["frame"] == 3));
    // The geofence: the site's (inclusion), then each zone (exclusion), corner for corner.
    let polygons = plan["geoFence"]["polygons"].as_array().unwrap();
    let inclusion: Vec<bool> = polygons.iter().map(|p| p["inclusion"].as_bool().unwrap()).collect();
    assert_eq!(inclusion, [true, false, false]);
    let fire: Vec<[f64; 2]> =
        polygons[1]["polygon"].as_array().unwrap().iter().map(local).collect();
    let corners = [[200.0, -120.0], [420.0, -80.0], [400.0, 110.0], [230.0, 130.0], [180.0, 10.0]];
    assert_eq!(fire.len(), corners.len());
    assert!(fire.iter().zip(corners).all(|(a, b)| near(*a, b)), "{fire:?}");
    // The places as rally points.
    let rally = plan["rallyPoints"]["points"].as_array().unwrap();
    assert_eq!(rally.len(), 3);
    assert!(near(local(&rally[2]), [0.0, 600.0]), "Village: {}", rally[2]);
}

#[test]
fn an_unknown_drone_or_a_world_without_origin_writes_nothing() {
    let dir = scratch("export_plan_refused");
    let out = dir.join("x.plan");
    let (code, _, err) = aviary(
        &[
            "export-plan",
            "examples/fire_front.mission",
            "--drone",
            "nobody",
            "-o",
            out.to_str().unwrap(),
        ],
        &repo(),
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("no drone `nobody`"), "{err}");
    assert!(!out.exists());
    let world = std::fs::read_to_string(repo().join("examples/fire_front.world.toml")).unwrap();
    let without = world.replace("origin = { lat = 47.07, lon = 15.44, alt = 350.0 }\n", "");
    std::fs::write(dir.join("w.world.toml"), without).unwrap();
    std::fs::copy(repo().join("examples/fire_front.mission"), dir.join("m.mission")).unwrap();
    let (code, _, err) = aviary(
        &[
            "export-plan",
            "m.mission",
            "--world",
            "w.world.toml",
            "--drone",
            "scout1",
            "-o",
            "x.plan",
        ],
        &dir,
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("add `origin"), "{err}");
    assert!(!dir.join("x.plan").exists());
}

/// An exported plan imported again (`[imports]`): its waypoints are a line a mission can
/// follow, its items places, at the heights written.
#[test]
fn an_exported_plan_imports_as_a_line_and_places() {
    let dir = scratch("export_plan_again");
    let (code, _, err) = aviary(
        &[
            "export-plan",
            "examples/fire_front.mission",
            "--drone",
            "scout1",
            "-o",
            dir.join("route.plan").to_str().unwrap(),
        ],
        &repo(),
    );
    assert_eq!(code, 0, "{err}");
    std::fs::write(
        dir.join("m.world.toml"),
        "[site]\norigin = { lat = 47.07, lon = 15.44, alt = 350.0 }\n[imports]\nfeatures = \"route.plan\"\n[drones.d1]\nhome = [0, 0]\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("m.mission"),
        "MISSION Again:\n    d1 TakeOff WITH 30m\n    d1 FollowPath WITH route\n    d1 FlyTo WITH route_3\n    d1 ReturnHome\n",
    )
    .unwrap();
    let (code, out, err) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 0, "{out}{err}");
}
