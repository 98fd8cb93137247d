//! Positions from the operator: `{"lat", "lon"}` (and `aviary ctl`'s `GEO(...)`) placed by
//! the world's projection, `[x, y]` as before, and a position beyond the world's limits
//! (the geofence, a no-fly zone under its top, `max_altitude`) refused with the limit and
//! by how much, before the mission hears it, while the run goes on to its end.

use super::serve::{http, raise, serve, Run};
use crate::common::{aviary, scratch};
use aviary_api::trace::{Event, Shown, Status};
use aviary_test_support::trace::{is, Trace};

/// `Go` carries where `b` is to fly; `a` hovers meanwhile, so the run lasts 60 s.
const MISSION: &str = "MISSION M:
    OPERATOR SIGNAL Go
    PARALLEL:
        a Hover WITH 60s
        ON EVERY Go WITH where:
            b FlyTo WITH where
";

/// A square fence of ±300 m, a ceiling of 120 m, and a zone from (100, 100) to (200, 200)
/// up to 40 m; the origin 500 m above sea level.
const WORLD: &str = "[site]
origin = { lat = 47.45, lon = 13.10, alt = 500 }
geofence = [[-300, -300], [300, -300], [300, 300], [-300, 300]]
max_altitude = 120

[no_fly.Hangar]
polygon = [[100, 100], [200, 100], [200, 200], [100, 200]]
up_to = 40

[drones.a]
home = [0, 0]
[drones.b]
home = [10, 0]
";

fn go(run: &Run, args: &str) -> (u16, String) {
    raise(run, "Go", args)
}

#[test]
fn a_position_is_taken_by_latitude_and_longitude_or_metres_and_refused_beyond_the_worlds_limits() {
    let dir = scratch("operator_positions");
    let mut run = serve(&dir, MISSION, WORLD, "0", &["--speed", "10"]);
    std::thread::sleep(std::time::Duration::from_millis(300));

    let state = http(&run, "GET", "/api/state", &[], "").json();
    assert_eq!(state["operator_signal_values"], serde_json::json!({ "Go": ["position"] }));

    // Each refusal names the limit and by how much.
    for (args, why) in [
        ("[[400, 0]]", "value 1 of Go: (400, 0) is outside the geofence, 100.0 m beyond its nearest side: choose a position inside it"),
        ("[{\"lat\": 47.46, \"lon\": 13.10}]", "value 1 of Go: GEO(47.46, 13.1), at (0, 1111.9), is outside the geofence, 811.9 m beyond its nearest side: choose a position inside it"),
        ("[[150, 150, 30]]", "value 1 of Go: (150, 150, 30) is inside the no-fly zone `Hangar` (up to 40.0 m), 50.0 m from its nearest side and 10.0 m below its top: choose a position outside it (a flight is routed around a zone, not into it), or give a height above 40.0 m"),
        ("[[120, 190]]", "value 1 of Go: (120, 190) is inside the no-fly zone `Hangar` (up to 40.0 m), 10.0 m from its nearest side, and has no height to pass above it: choose a position outside it (a flight is routed around a zone, not into it), or give a height above 40.0 m, e.g. [120.0, 190.0, 50]"),
        ("[[0, 50, 150]]", "value 1 of Go: (0, 50, 150) is 30.0 m above the site's max_altitude of 120.0 m: give a height of at most 120.0 m"),
        ("[{\"lat\": 47.45, \"lon\": 13.10, \"alt\": 650}]", "value 1 of Go: GEO(47.45, 13.1, 650), at (0, 0, 150), is 30.0 m above the site's max_altitude of 120.0 m: give a height of at most 120.0 m"),
        ("[{\"lat\": 91, \"lon\": 13.10}]", "value 1 of Go: `lat` is 91, and must be within ±90 degrees"),
        ("[{\"lat\": 47.45}]", "value 1 of Go: `lon` is missing: write {\"lat\": 47.45, \"lon\": 13.1} in degrees, with \"alt\" in metres above sea level if the height matters"),
        ("[{\"lat\": 47.45, \"lon\": 13.1, \"height\": 3}]", "value 1 of Go: a position by latitude and longitude has no `height`: write {\"lat\": 47.45, \"lon\": 13.1} in degrees, with \"alt\" in metres above sea level if the height matters"),
    ] {
        assert_eq!(go(&run, args), (400, why.to_string()), "{args}");
    }

    // By latitude and longitude: 0.0005° north and east of the origin, 30 m up.
    let (status, body) = go(&run, "[{\"lat\": 47.4505, \"lon\": 13.1005, \"alt\": 530}]");
    assert_eq!(status, 200, "{body}");
    std::thread::sleep(std::time::Duration::from_millis(2500));
    let ctl = |args: &[&str]| {
        let mut all = vec!["ctl", "--url", &run.url, "--token", &run.token];
        all.extend(args);
        aviary(&all, &dir)
    };
    let (code, _, err) = ctl(&["signal", "Go", "GEO(47.4490, 13.0990)"]);
    assert_eq!(code, 0, "{err}");
    std::thread::sleep(std::time::Duration::from_millis(2500));
    let (code, _, err) = ctl(&["signal", "Go", "GEO(47.4600, 13.1000)"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("refused (400): value 1 of Go: GEO(47.46, 13.1), at (0, 1111.9), is outside the geofence, 811.9 m beyond its nearest side"), "{err}");
    let (code, _, err) = ctl(&["signal", "Go", "GEO(47.46, north)"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("GEO takes degrees of latitude and longitude"), "{err}");
    // And in metres, as before.
    assert_eq!(go(&run, "[[-50, 40]]").0, 200);

    // The refusals changed nothing: the run went on to its end, and the mission heard
    // only the positions it was given, placed about the origin.
    assert_eq!(run.child.wait().unwrap().code(), Some(0), "the mission ends ok");
    let trace = std::fs::read_to_string(dir.join("t.jsonl")).unwrap();
    let events = Trace::parse(&trace);
    let heard: Vec<Vec<f64>> = events
        .find(is::signal("Go"))
        .iter()
        .map(|e| match &e.event {
            Event::Signal { args, .. } => match &args[0] {
                Shown::Position(p) => [Some(p.x), Some(p.y), p.z].into_iter().flatten().collect(),
                other => panic!("not a position: {other:?}"),
            },
            _ => unreachable!(),
        })
        .collect();
    // 0.0005° of latitude is 55.6 m; of longitude, at 47.45° N, 37.6 m.
    let expected = [vec![37.6, 55.6, 30.0], vec![-75.1, -111.2], vec![-50.0, 40.0]];
    assert_eq!(heard.len(), expected.len(), "{heard:?}");
    for (got, want) in heard.iter().zip(&expected) {
        assert_eq!(got.len(), want.len(), "{got:?}");
        assert!(got.iter().zip(want).all(|(g, w)| (g - w).abs() < 0.1), "{got:?} is not {want:?}");
    }
    let end = events.first(|e| matches!(e, Event::MissionEnd { .. }));
    assert!(matches!(end.event, Event::MissionEnd { status: Status::Ok, .. }), "{end:?}");
}
