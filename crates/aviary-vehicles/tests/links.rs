//! Each ground station's link: its own sequence numbers per vehicle, its own queue (one
//! client's flood of commands is answered to it alone and costs the others nothing), and
//! heartbeats that are never dropped.
// These tests talk to `aviary vehicles` in real time (its own clock is the wall's).
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

mod common;

use std::collections::HashMap;
use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavCmd, MavMessage, COMMAND_LONG_DATA};
use common::{fleet, quick, serve, Gcs};
use tokio::time::Instant;

/// Sequence numbers of each system, in the order they came.
fn sequences(frames: &[(u8, u8)]) -> HashMap<u8, Vec<u8>> {
    let mut by: HashMap<u8, Vec<u8>> = HashMap::new();
    for (system, seq) in frames {
        by.entry(*system).or_default().push(*seq);
    }
    by
}

fn assert_consecutive(system: u8, seqs: &[u8]) {
    for w in seqs.windows(2) {
        assert_eq!(
            w[1],
            w[0].wrapping_add(1),
            "system {system}: sequence {} after {} ({} messages)",
            w[1],
            w[0],
            seqs.len()
        );
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn each_vehicle_numbers_its_messages_one_by_one_on_each_link() {
    let vehicles = serve(&fleet(3, ""), 5.0, quick()).await;
    let mut gcs = Gcs::connect(vehicles.address).await;
    // Positions at 50 Hz from each: some hundreds of messages, interleaved.
    for system in [1u8, 2, 3] {
        let ack = gcs
            .command(
                system,
                MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
                [33.0, 20_000.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            )
            .await;
        assert_eq!(ack.result as u8, 0, "{ack:?}");
    }
    let mut frames = Vec::new();
    let until = Instant::now() + Duration::from_secs(3);
    while Instant::now() < until {
        let f = gcs.frame(Duration::from_secs(1)).await.expect("a message");
        frames.push((f.system(), f.raw.sequence()));
    }
    let by = sequences(&frames);
    for system in [1u8, 2, 3] {
        let seqs = &by[&system];
        assert!(seqs.len() > 100, "system {system}: only {} messages", seqs.len());
        assert_consecutive(system, seqs);
    }
    // A second link starts its own numbering: each vehicle's first message on it is 0.
    let mut second = Gcs::connect(vehicles.address).await;
    let mut first_seen = HashMap::new();
    while first_seen.len() < 3 {
        let f = second.frame(Duration::from_secs(3)).await.expect("a message");
        first_seen.entry(f.system()).or_insert(f.raw.sequence());
    }
    assert!(first_seen.values().all(|s| *s == 0), "{first_seen:?}");
    vehicles.stop();
}

/// What a client saw: (seconds since the start, system, sequence, message name).
type Seen = Vec<(f64, u8, u8, String)>;

async fn record(mut gcs: Gcs, start: Instant, until: Instant) -> Seen {
    let mut seen = Vec::new();
    while Instant::now() < until {
        let left = until.saturating_duration_since(Instant::now());
        let Some(f) = gcs.frame(left).await else {
            break;
        };
        let name = f
            .msg
            .as_ref()
            .map_or("?".into(), |m| aviary_mavlink::mavlink::Message::message_name(m).to_owned());
        seen.push((start.elapsed().as_secs_f64(), f.system(), f.raw.sequence(), name));
    }
    seen
}

fn beats(seen: &Seen, system: u8) -> Vec<f64> {
    seen.iter().filter(|(_, s, _, n)| *s == system && n == "HEARTBEAT").map(|(t, ..)| *t).collect()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_flood_of_commands_is_answered_to_its_sender_alone_and_heartbeats_go_on() {
    let vehicles = serve(&fleet(2, ""), 5.0, quick()).await;
    let start = Instant::now();
    let watcher = Gcs::connect(vehicles.address).await;
    let watching = tokio::spawn(record(watcher, start, start + Duration::from_secs(9)));
    let mut flooder = Gcs::connect(vehicles.address).await;
    // 20,000 requests for AUTOPILOT_VERSION, each answered by an ACK and the message,
    // sent without reading a byte.
    let ask = MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        param1: 148.0,
        command: MavCmd::MAV_CMD_REQUEST_MESSAGE,
        target_system: 1,
        target_component: 1,
        ..COMMAND_LONG_DATA::default()
    });
    for _ in 0..20_000 {
        flooder.send(&ask).await;
    }
    let flooded = start.elapsed().as_secs_f64();
    tokio::time::sleep_until(start + Duration::from_secs(6)).await;
    // Now the flooder reads what waited for it.
    let mine = record(flooder, start, start + Duration::from_secs(9)).await;
    let theirs = watching.await.unwrap();

    let answers = |seen: &Seen| {
        seen.iter().filter(|(.., n)| n == "COMMAND_ACK" || n == "AUTOPILOT_VERSION").count()
    };
    assert_eq!(answers(&theirs), 0, "the watcher was sent the flooder's answers");
    assert!(answers(&mine) > 100, "the flooder got {} answers", answers(&mine));
    for system in [1u8, 2] {
        let t = beats(&theirs, system);
        assert!(t.len() >= 8, "watcher: {} heartbeats of {system} in 9 s: {t:?}", t.len());
        let gaps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(
            gaps.iter().all(|g| *g < 2.0),
            "watcher: heartbeats of {system} at {t:?} (flood sent by {flooded:.1} s)"
        );
        // The flooder's heartbeats waited behind its answers, but none was lost...
        let m = beats(&mine, system);
        assert!(m.len() >= 8, "flooder: {} heartbeats of {system}: {m:?}", m.len());
    }
    // ... and neither was anything numbered: each vehicle's sequence has no gap.
    for (system, seqs) in sequences(&mine.iter().map(|(_, s, q, _)| (*s, *q)).collect::<Vec<_>>()) {
        assert_consecutive(system, &seqs);
    }
    vehicles.stop();
}
