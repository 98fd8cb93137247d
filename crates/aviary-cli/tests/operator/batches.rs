//! The event stream in batches (`?from=start&every=MS`), as the ground station's page
//! reads it: the history, then one JSON array a window; every event but telemetry exactly
//! once and in the trace's order, and at most one telemetry sample per drone a batch.

use std::collections::HashSet;

use super::common::scratch;
use super::serve::serve;

#[test]
fn batches_carry_every_event_once_in_order_and_a_sample_per_drone() {
    let dir = scratch("operator_batches");
    let run =
        serve(&dir, super::MISSION, super::WORLD, "0", &["--speed", "10", "--telemetry-hz", "20"]);
    let url = format!("ws://{}/api/events?from=start&every=50", run.addr);
    let (mut socket, _) = tungstenite::connect(url.as_str()).expect("the stream opens");
    let mut events = Vec::new();
    let mut batches = 0;
    let mut busiest = 0;
    'read: loop {
        let message = socket.read().expect("a message before mission_end");
        let text = match message {
            tungstenite::Message::Text(t) => t.to_string(),
            tungstenite::Message::Close(_) => break,
            _ => continue,
        };
        let value: serde_json::Value = serde_json::from_str(&text).expect("JSON");
        let items = match value {
            serde_json::Value::Array(items) => {
                batches += 1;
                let samples: Vec<&str> = items
                    .iter()
                    .filter(|e| e["event"] == "telemetry")
                    .map(|e| e["actor"].as_str().unwrap())
                    .collect();
                let drones: HashSet<&&str> = samples.iter().collect();
                assert_eq!(
                    drones.len(),
                    samples.len(),
                    "one sample per drone a batch: {samples:?}"
                );
                busiest = busiest.max(samples.len());
                items
            }
            one => vec![one],
        };
        for e in items {
            assert!(e.get("dropped").is_none(), "nothing is let go here: {e}");
            let end = e["event"] == "mission_end";
            events.push(e);
            if end {
                break 'read;
            }
        }
    }
    assert!(batches > 3, "the live part came in batches ({batches})");
    assert!(busiest >= 1, "telemetry came along");
    let streamed: Vec<String> =
        events.iter().filter(|e| e["event"] != "telemetry").map(|e| e.to_string()).collect();
    // The trace file is whole once the process has ended.
    let mut run = run;
    let _ = run.child.wait();
    let trace = std::fs::read_to_string(dir.join("t.jsonl")).expect("the trace");
    let written: Vec<String> = trace
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .filter(|e| e["event"] != "telemetry")
        .map(|e| e.to_string())
        .collect();
    assert_eq!(streamed, written, "every event but telemetry, once, in the trace's order");
}
