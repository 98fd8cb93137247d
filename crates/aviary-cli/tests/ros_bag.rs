//! `aviary export --mcap`: the paper's mission flown, its trace written as a ROS 2 bag, and
//! the bag read by rosbags (PyPI, pinned by .ci/run), a reader no one here wrote: every
//! message decodes through the definitions the bag carries, each topic holds what the
//! trace says, and the last fix of each drone is where its last telemetry puts it on the
//! Earth.

mod common;

use std::process::Command;

use aviary_api::geo::Origin;
use aviary_api::trace::{Event, EventKind};
use aviary_test_support::trace::Trace;
use common::{aviary, logs::python, repo, scratch, PAPER_DRONES};
use serde_json::Value;

#[test]
fn a_trace_exported_as_a_bag_is_read_by_rosbags_as_the_trace_says() {
    let dir = scratch("ros_bag");
    for f in ["search_and_rescue.mission", "search_and_rescue.world.toml"] {
        std::fs::copy(repo().join("examples").join(f), dir.join(f)).unwrap();
    }
    let (code, _, err) = aviary(
        &[
            "run",
            "search_and_rescue.mission",
            "--quiet",
            "--telemetry-hz",
            "1",
            "--trace",
            "t.jsonl",
        ],
        &dir,
    );
    assert_eq!(code, 0, "{err}");
    let (code, _, err) = aviary(&["export", "t.jsonl", "--mcap", "bag"], &dir);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("drawn on it") || err.contains("wrote"), "{err}");
    let bag = dir.join("bag");
    assert!(bag.join("metadata.yaml").is_file() && bag.join("bag_0.mcap").is_file());

    let out = Command::new(python())
        .arg(repo().join("tests/ros/read_bag.py"))
        .arg(&bag)
        .output()
        .unwrap();
    assert!(out.status.success(), "rosbags: {}", String::from_utf8_lossy(&out.stderr));
    let read: Value = serde_json::from_slice(&out.stdout).unwrap();

    let trace = Trace::read(&dir.join("t.jsonl"));
    // Every event, in order, on the events topic.
    let kinds: Vec<(f64, &str)> = trace.iter().map(|r| (r.t, r.event.kind().as_str())).collect();
    let events: Vec<(f64, String)> = read["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| (e[0].as_f64().unwrap(), e[1].as_str().unwrap().to_string()))
        .collect();
    assert_eq!(events.len(), kinds.len());
    for ((t, kind), (bt, bkind)) in kinds.iter().zip(&events) {
        assert!((t - bt).abs() < 1e-6 && kind == bkind, "{t} {kind} / {bt} {bkind}");
    }
    let topics = read["topics"].as_object().unwrap();
    assert_eq!(topics["/aviary/events"]["type"], "aviary_msgs/msg/Event");
    // A pose and a fix per telemetry sample of each drone; the last where it last was.
    let world = std::fs::read_to_string(dir.join("search_and_rescue.world.toml")).unwrap();
    let (world, _) = aviary_world::parse_world(aviary_diagnostics::FileId(0), &world);
    let o = world.unwrap().site.origin.unwrap();
    let origin = Origin { lat: o.lat, lon: o.lon, alt: o.alt };
    for drone in PAPER_DRONES {
        let samples: Vec<(f64, [f64; 3])> = trace
            .events(EventKind::Telemetry)
            .into_iter()
            .filter_map(|r| match &r.event {
                Event::Telemetry { actor, position, .. } if actor == drone => {
                    Some((r.t, *position))
                }
                _ => None,
            })
            .collect();
        assert!(!samples.is_empty(), "{drone} has telemetry");
        for (suffix, ty) in
            [("pose", "geometry_msgs/msg/PoseStamped"), ("fix", "sensor_msgs/msg/NavSatFix")]
        {
            let topic = &topics[&format!("/aviary/{drone}/{suffix}")];
            assert_eq!(
                (topic["type"].as_str(), topic["count"].as_u64()),
                (Some(ty), Some(samples.len() as u64))
            );
        }
        let (t, [x, y, z]) = *samples.last().unwrap();
        let fix = &read["last_fix"][drone];
        let (lat, lon) = origin.to_geodetic(x, y);
        assert!((fix[0].as_f64().unwrap() - t).abs() < 1e-6);
        assert!(
            (fix[1].as_f64().unwrap() - lat).abs() < 1e-9
                && (fix[2].as_f64().unwrap() - lon).abs() < 1e-9,
            "{fix}"
        );
        assert!((fix[3].as_f64().unwrap() - (origin.alt + z)).abs() < 1e-6, "{fix}");
        assert_eq!(fix[4], 0, "a fix");
        let pose = &read["last_pose"][drone];
        assert_eq!(pose[4], "map");
        assert!(
            [x, y, z].iter().zip(&pose.as_array().unwrap()[1..4]).all(|(a, b)| (a - b
                .as_f64()
                .unwrap())
            .abs()
                < 1e-9),
            "{pose}"
        );
    }
    // A bag is a new folder: writing over one is refused.
    let (code, _, err) = aviary(&["export", "t.jsonl", "--mcap", "bag"], &dir);
    assert_eq!(code, 2);
    assert!(err.contains("exists already"), "{err}");
}
