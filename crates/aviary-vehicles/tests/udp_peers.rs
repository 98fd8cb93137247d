//! UDP peers: every peer that sends is served, up to MAX_PEERS at once, and one silent
//! for PEER_EXPIRY is no longer sent anything (before, every source port ever seen was
//! sent every message for ever).
// These tests talk to `aviary vehicles` in real time (its own clock is the wall's).
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

mod common;

use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavAutopilot, MavMessage, MavModeFlag, MavState, MavType, HEARTBEAT_DATA,
};
use aviary_mavlink::mavlink::{self, MavHeader};
use aviary_vehicles::{Listen, Options, MAX_PEERS, PEER_EXPIRY};
use common::fleet;
use tokio::net::UdpSocket;
use tokio::time::Instant;

fn heartbeat() -> Vec<u8> {
    let msg = MavMessage::HEARTBEAT(HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype: MavType::MAV_TYPE_GCS,
        autopilot: MavAutopilot::MAV_AUTOPILOT_INVALID,
        base_mode: MavModeFlag::empty(),
        system_status: MavState::MAV_STATE_ACTIVE,
        mavlink_version: 3,
    });
    let header = MavHeader { system_id: 255, component_id: 190, sequence: 0 };
    let mut buf = Vec::new();
    mavlink::write_v2_msg(&mut buf, header, &msg).unwrap();
    buf
}

/// Datagrams waiting at `socket`, taken.
fn drain(socket: &UdpSocket) -> usize {
    let mut buf = [0u8; 2048];
    let mut n = 0;
    while socket.try_recv(&mut buf).is_ok() {
        n += 1;
    }
    n
}

async fn serve_udp() -> aviary_vehicles::Vehicles {
    aviary_vehicles::serve(
        &fleet(1, ""),
        Listen::Udp("127.0.0.1:0".parse().unwrap()),
        Options { speed: 5.0, ..Options::default() },
    )
    .await
    .unwrap()
}

/// A peer that has said one HEARTBEAT.
async fn peer(to: std::net::SocketAddr) -> UdpSocket {
    let s = UdpSocket::bind("127.0.0.1:0").await.unwrap();
    s.connect(to).await.unwrap();
    s.send(&heartbeat()).await.unwrap();
    s
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_silent_peer_expires_and_is_served_again_when_it_speaks() {
    let vehicles = serve_udp().await;
    let live = peer(vehicles.address).await;
    let mut silent = Vec::new();
    for _ in 0..5 {
        silent.push(peer(vehicles.address).await);
    }
    tokio::time::sleep(Duration::from_millis(1500)).await;
    assert!(silent.iter().all(|s| drain(s) > 0), "every peer is served");
    assert_eq!(vehicles.clients(), 6);

    // The live peer keeps talking; the silent ones are dropped after PEER_EXPIRY.
    let until = Instant::now() + PEER_EXPIRY + Duration::from_secs(1);
    while Instant::now() < until {
        live.send(&heartbeat()).await.unwrap();
        tokio::time::sleep(Duration::from_millis(500)).await;
    }
    assert_eq!(vehicles.clients(), 1);
    for s in &silent {
        drain(s); // what was sent before they expired
    }
    drain(&live);
    tokio::time::sleep(Duration::from_millis(1500)).await;
    let after: usize = silent.iter().map(drain).sum();
    assert_eq!(after, 0, "expired peers were still sent {after} datagrams");
    assert!(drain(&live) > 0, "the live peer is still served");
    // An expired peer that speaks again is served again.
    silent[0].send(&heartbeat()).await.unwrap();
    tokio::time::sleep(Duration::from_millis(1500)).await;
    assert!(drain(&silent[0]) > 0);
    vehicles.stop();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn at_most_max_peers_are_served_at_once() {
    let vehicles = serve_udp().await;
    let mut peers = Vec::new();
    for _ in 0..MAX_PEERS + 6 {
        peers.push(peer(vehicles.address).await);
    }
    tokio::time::sleep(Duration::from_millis(1500)).await;
    let served = peers.iter().filter(|s| drain(s) > 0).count();
    assert_eq!(served, MAX_PEERS);
    assert_eq!(vehicles.clients(), MAX_PEERS);
    vehicles.stop();
}
