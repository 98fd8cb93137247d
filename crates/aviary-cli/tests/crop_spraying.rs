//! The crop-spraying example as a user runs it (`aviary run
//! examples/crop_spraying.mission --trace OUT --telemetry-hz 20`): sprayer2 loses its link
//! half way through East_Field, and sprayer3 later sprays just what it left. From the
//! trace, lane by lane (`aviary_test_support::lanes`, on the telemetry of every
//! sprayer): every lane of East_Field is sprayed once, none twice and none missed; the
//! lanes before the loss by sprayer2, the one it was on by sprayer2 up to where it
//! stopped and by sprayer3 from there, the rest by sprayer3.

mod common;

use aviary_api::sweep;
use aviary_test_support::lanes;
use common::{aviary, repo, scratch};
use serde_json::Value;

const MISSION: &str = "examples/crop_spraying.mission";

fn xy(v: &Value) -> [f64; 2] {
    [v[0].as_f64().unwrap(), v[1].as_f64().unwrap()]
}

#[test]
fn the_lost_sprayers_field_is_sprayed_once_lane_by_lane() {
    let (code, out, _) = aviary(&["check", MISSION], &repo());
    assert_eq!((code, out.trim()), (0, "examples/crop_spraying.mission: ok"), "checks clean");
    let (code, out, err) = aviary(&["fmt", "--check", MISSION], &repo());
    assert_eq!(code, 0, "in canonical layout: {out}{err}");

    let trace = scratch("crop_spraying").join("crop.jsonl");
    let (code, out, err) = aviary(
        &["run", MISSION, "--quiet", "--telemetry-hz", "20", "--trace", &trace.to_string_lossy()],
        &repo(),
    );
    assert_eq!(code, 0, "runs to its end: {out}{err}");
    let events: Vec<Value> = std::fs::read_to_string(&trace)
        .expect("the trace")
        .lines()
        .map(|l| serde_json::from_str(l).expect("a trace line"))
        .collect();
    let find = |pred: &dyn Fn(&Value) -> bool| -> Vec<&Value> {
        events.iter().filter(|e| pred(e)).collect()
    };
    assert_eq!(events.last().unwrap()["status"], "ok");

    // One link loss, handled; sprayer2's sweep cut there, with what it left.
    let lost = find(&|e| e["event"] == "exception");
    assert_eq!(lost.len(), 1);
    assert_eq!(
        (lost[0]["name"].as_str(), lost[0]["actor"].as_str()),
        (Some("ConnectionLost"), Some("sprayer2"))
    );
    assert_eq!(lost[0]["handled"], true);
    let sweep_of = |actor: &str, event: &str| -> Vec<&Value> {
        events
            .iter()
            .filter(|e| e["event"] == event && e["actor"] == actor && e["function"] == "Sweep")
            .collect()
    };
    let cut = sweep_of("sprayer2", "api_done")[0];
    assert_eq!(cut["status"], "interrupted");
    assert!(cut["left"].as_f64().unwrap() > 0.0);
    let field: Vec<[f64; 2]> =
        sweep_of("sprayer2", "api_call")[0]["args"][0].as_array().unwrap().iter().map(xy).collect();

    // sprayer3: its own field, then nothing from sprayer1 (it finished: done at once), then
    // sprayer2's lanes left, the first from where sprayer2 stopped.
    let calls = sweep_of("sprayer3", "api_call");
    assert_eq!(calls.len(), 3, "its field, sprayer1's remainder, sprayer2's");
    assert_eq!(calls[1]["args"][0], serde_json::json!({"points": []}));
    let done = sweep_of("sprayer3", "api_done");
    assert_eq!((done[1]["status"].as_str(), &done[1]["t"]), (Some("ok"), &calls[1]["t"]));
    let handed = &calls[2]["args"][0];
    assert_eq!(xy(&handed["lanes"][0][0]), xy(&cut["position"]));
    assert_eq!(done[2]["status"], "ok");

    // Lane by lane, from every sprayer's track.
    let tracks = lanes::tracks(&events, &["sprayer1", "sprayer2", "sprayer3"]);
    let east = sweep::lanes(&field, 10.0);
    let owners = lanes::each_lane_once(&east, &tracks);
    let shared = owners.iter().position(|o| o.len() == 2).expect("the lane it was on");
    assert!(shared > 0, "{owners:?}");
    assert!(owners[..shared].iter().all(|o| o == &["sprayer2"]), "{owners:?}");
    assert_eq!(owners[shared], ["sprayer2", "sprayer3"]);
    assert!(owners[shared + 1..].iter().all(|o| o == &["sprayer3"]), "{owners:?}");
    // And the other fields, each by its own sprayer.
    for (d, area) in [("sprayer1", "North_Field"), ("sprayer3", "South_Field")] {
        let call = sweep_of(d, "api_call")[0];
        let polygon: Vec<[f64; 2]> = call["args"][0].as_array().unwrap().iter().map(xy).collect();
        let owners = lanes::each_lane_once(&sweep::lanes(&polygon, 10.0), &tracks);
        assert!(owners.iter().all(|o| o == &[d]), "{area}: {owners:?}");
    }
}
