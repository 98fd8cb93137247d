//! The UDP socket: every peer that has sent a datagram in the last [`PEER_EXPIRY`] is a
//! client, with its own queue and sequence numbers, up to [`MAX_PEERS`] at once.
// A silent peer is forgotten after real seconds: tokio's timer, not the run's clock.
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

use std::collections::HashMap;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use aviary_mavlink::mavlink::SigningData;
use tokio::net::UdpSocket;
use tokio::time::Instant;

use crate::client::{Client, Registry, Sequences};
use crate::server::{frame, read_all, signing, Shared};

/// A UDP peer silent this long is gone: a ground station sends HEARTBEAT every second,
/// so ten missed ones are no lag. Without it, every source port ever seen (a client that
/// restarts, a scan) is sent every stream for ever.
pub const PEER_EXPIRY: Duration = Duration::from_secs(10);
/// UDP peers served at once; a new one past this is not served until another expires.
pub const MAX_PEERS: usize = 64;

struct Peer {
    client: Arc<Client>,
    heard: Instant,
}

pub(crate) async fn udp(
    socket: UdpSocket,
    ap: Shared,
    clients: Arc<Registry>,
    key: Option<[u8; 32]>,
) {
    let socket = Arc::new(socket);
    let sign = Arc::new(signing(key));
    let mut peers: HashMap<SocketAddr, Peer> = HashMap::new();
    let mut sweep = tokio::time::interval(Duration::from_secs(1));
    let mut buf = vec![0u8; 65_536];
    loop {
        let (n, from) = tokio::select! {
            r = socket.recv_from(&mut buf) => match r {
                Ok(r) => r,
                // An ICMP error from a peer that went away, reported on the next read.
                Err(_) => continue,
            },
            _ = sweep.tick() => {
                expire(&mut peers, &clients);
                continue;
            }
        };
        if !peers.contains_key(&from) {
            expire(&mut peers, &clients);
            if peers.len() >= MAX_PEERS {
                continue;
            }
            let client = peer(from, Arc::clone(&socket), Arc::clone(&sign));
            clients.add(Arc::clone(&client));
            peers.insert(from, Peer { client, heard: Instant::now() });
        }
        let Some(p) = peers.get_mut(&from) else {
            continue;
        };
        p.heard = Instant::now();
        let client = Arc::clone(&p.client);
        read_all(&buf[..n], sign.as_ref().as_ref(), &ap, &client, &clients).await;
    }
}

/// A new UDP peer: its client and the task that sends it its queue.
fn peer(to: SocketAddr, socket: Arc<UdpSocket>, sign: Arc<Option<SigningData>>) -> Arc<Client> {
    let client = Arc::new(Client::new());
    let c = Arc::clone(&client);
    let writer = tokio::spawn(async move {
        let mut sequences = Sequences::new();
        loop {
            let o = c.next().await;
            if let Some(bytes) = frame(&mut sequences, &o, sign.as_ref().as_ref()) {
                let _ = socket.send_to(&bytes, to).await;
            }
        }
    });
    client.tasks.lock().push(writer.abort_handle());
    client
}

fn expire(peers: &mut HashMap<SocketAddr, Peer>, clients: &Registry) {
    peers.retain(|_, p| {
        let alive = p.heard.elapsed() < PEER_EXPIRY;
        if !alive {
            p.client.abort();
            clients.remove(p.client.id);
        }
        alive
    });
}
