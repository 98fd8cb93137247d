//! No-fly zones as a user meets them: `aviary run` of the wildfire example with telemetry
//! at 20 Hz, whose trace has no point inside a zone (at a height where it holds), and
//! goes around the fire where the straight line would cross it.

mod common;

use aviary_api::trace::{Event, Status};
use aviary_test_support::trace::Trace;
use common::{repo, scratch};

#[test]
fn the_wildfire_example_flies_around_the_fire_and_over_the_corridor_never_into_a_zone() {
    let dir = scratch("no_fly_example");
    let trace = dir.join("t.jsonl");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["run", "examples/fire_front.mission", "--quiet", "--telemetry-hz", "20", "--trace"])
        .arg(&trace)
        .current_dir(repo())
        .status()
        .expect("run aviary");
    assert!(status.success());
    let text = std::fs::read_to_string(repo().join("examples/fire_front.world.toml")).unwrap();
    let (world, diagnostics) = aviary_world::parse_world(aviary_diagnostics::FileId(0), &text);
    let world = world.unwrap_or_else(|| panic!("{diagnostics:?}"));
    assert_eq!(world.no_fly.len(), 2);
    let events = Trace::read(&trace);
    let samples: Vec<(String, [f64; 3])> = events
        .iter()
        .filter_map(|e| match &e.event {
            Event::Telemetry { actor, position, .. } => {
                assert!(position.iter().all(|c| c.is_finite()), "{e:?}");
                Some((actor.to_string(), *position))
            }
            _ => None,
        })
        .collect();
    // 20 Hz over about 340 s, for two drones.
    assert!(samples.len() > 10_000, "{} samples", samples.len());
    for (drone, p) in &samples {
        for z in &world.no_fly {
            let inside = aviary_api::geometry::contains(&z.polygon, [p[0], p[1]]);
            assert!(!(inside && z.holds_at(p[2])), "{drone} at {p:?} is inside {}", z.name);
        }
    }
    // The fire is between scout1's home and the water point: it went around, at the
    // planner's margin from the fire, never nearer.
    let fire = &world.no_fly[0].polygon;
    let nearest = (samples.iter())
        .filter(|(d, p)| d == "scout1" && p[2] > 0.0)
        .map(|(_, p)| aviary_api::geometry::dist_to_boundary(fire, [p[0], p[1]]))
        .fold(f64::INFINITY, f64::min);
    assert!(
        (aviary_route::MARGIN * 0.99..aviary_route::MARGIN + 1.0).contains(&nearest),
        "scout1 came within {nearest} m of the fire"
    );
    // scout2 crossed the corridor's ground, above it.
    let over = samples.iter().filter(|(d, p)| d == "scout2" && (250.0..=350.0).contains(&p[1]));
    assert!(over.clone().count() > 0 && over.clone().all(|(_, p)| p[2] > 60.0));
    assert!(matches!(events.last().unwrap().event, Event::MissionEnd { status: Status::Ok, .. }));

    // The report's map draws the zones, named, the one up to a height with it.
    let html = dir.join("report.html");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_aviary"))
        .args(["report", "--world", "examples/fire_front.world.toml", "--output"])
        .arg(&html)
        .arg(&trace)
        .current_dir(repo())
        .status()
        .expect("run aviary report");
    assert!(status.success());
    let html = std::fs::read_to_string(html).unwrap();
    assert!(html.contains("no-fly: Fire_Front\n"), "the fire is not named on the map");
    assert!(html.contains("no-fly: Heli_Corridor (up to 60 m)"), "the corridor is not named");
}

#[test]
fn explain_e128_names_the_no_fly_zones() {
    let (code, out, _) = common::aviary(&["explain", "E128"], &repo());
    assert_eq!(code, 0);
    assert!(out.contains("E128 (error): a flight into a no-fly zone"), "{out}");
}
