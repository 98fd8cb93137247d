//! A ground station for the tests: the `mavlink` crate over a real TCP connection to
//! `aviary vehicles`, reading raw frames so that sequence numbers, senders and messages
//! the dialect cannot parse are seen as they came.
#![allow(dead_code)]
// These tests talk to `aviary vehicles` in real time (its own clock is the wall's).
#![allow(clippy::disallowed_methods, clippy::disallowed_types)]

use std::net::SocketAddr;
use std::time::Duration;

use aviary_mavlink::mavlink::dialects::ardupilotmega::{
    MavCmd, MavMessage, COMMAND_ACK_DATA, COMMAND_LONG_DATA,
};
use aviary_mavlink::mavlink::{self, AsyncMavlinkReader, MAVLinkMessageRaw, MavHeader, Message};
use aviary_vehicles::{Behaviour, Listen, Options, Vehicles};
use aviary_world::World;
use tokio::net::tcp::{OwnedReadHalf, OwnedWriteHalf};
use tokio::net::TcpStream;
use tokio::time::Instant;

pub const ORIGIN: (f64, f64, f64) = (46.6, 14.2, 400.0);

pub fn world(text: &str) -> World {
    let mut sources = aviary_diagnostics::SourceMap::new();
    let file = sources.add("t.world.toml", text);
    let (world, diagnostics) = aviary_world::parse_world(file, text);
    world.unwrap_or_else(|| panic!("{diagnostics:?}"))
}

/// A world of `n` drones 10 m apart, with `site` added to its `[site]`.
pub fn fleet(n: usize, site: &str) -> World {
    let mut text = format!(
        "[site]\nname = \"t\"\norigin = {{ lat = {}, lon = {}, alt = {} }}\n{site}\n",
        ORIGIN.0, ORIGIN.1, ORIGIN.2
    );
    for k in 0..n {
        text += &format!("\n[drones.d{k}]\nhome = [{}, 0]\nmax_speed = 8\n", 10 * k);
    }
    world(&text)
}

pub async fn serve(world: &World, speed: f64, behaviour: Behaviour) -> Vehicles {
    aviary_vehicles::serve(
        world,
        Listen::Tcp("127.0.0.1:0".parse().unwrap()),
        Options { speed, behaviour, ..Options::default() },
    )
    .await
    .unwrap()
}

/// A frame as it came, and its message when the dialect could parse it.
pub struct Frame {
    pub raw: MAVLinkMessageRaw,
    pub msg: Option<MavMessage>,
}

impl Frame {
    pub fn system(&self) -> u8 {
        self.raw.system_id() as u8
    }
}

pub struct Gcs {
    reader: AsyncMavlinkReader<OwnedReadHalf>,
    write: OwnedWriteHalf,
    sequence: u8,
    pub system: u8,
    pub component: u8,
}

impl Gcs {
    pub async fn connect(address: SocketAddr) -> Gcs {
        Gcs::connect_as(address, 255, 190).await
    }

    pub async fn connect_as(address: SocketAddr, system: u8, component: u8) -> Gcs {
        let stream = TcpStream::connect(address).await.unwrap();
        Gcs::over(stream, system, component)
    }

    pub fn over(stream: TcpStream, system: u8, component: u8) -> Gcs {
        stream.set_nodelay(true).unwrap();
        let (read, write) = stream.into_split();
        Gcs { reader: AsyncMavlinkReader::new(read), write, sequence: 0, system, component }
    }

    pub async fn send(&mut self, msg: &MavMessage) {
        let header = MavHeader {
            system_id: u32::from(self.system),
            component_id: self.component,
            sequence: self.sequence,
        };
        self.sequence = self.sequence.wrapping_add(1);
        mavlink::write_v2_msg_async(&mut self.write, header, msg).await.unwrap();
    }

    pub async fn send_bytes(&mut self, bytes: &[u8]) {
        tokio::io::AsyncWriteExt::write_all(&mut self.write, bytes).await.unwrap();
    }

    /// The next frame, or `None` if nothing comes within `limit`.
    pub async fn frame(&mut self, limit: Duration) -> Option<Frame> {
        let raw = tokio::time::timeout(limit, self.reader.read_any_raw_message::<MavMessage>())
            .await
            .ok()?
            .ok()?;
        let msg = MavMessage::parse(raw.version(), raw.message_id(), raw.payload()).ok();
        Some(Frame { raw, msg })
    }

    /// The first message from `system` that `pick` takes, within `limit`.
    pub async fn wait<T>(
        &mut self,
        system: u8,
        limit: Duration,
        mut pick: impl FnMut(&MavMessage) -> Option<T>,
    ) -> Option<T> {
        let until = Instant::now() + limit;
        loop {
            let left = until.saturating_duration_since(Instant::now());
            let f = self.frame(left).await?;
            if f.system() != system {
                continue;
            }
            if let Some(t) = f.msg.as_ref().and_then(&mut pick) {
                return Some(t);
            }
        }
    }

    pub async fn command(&mut self, system: u8, command: MavCmd, p: [f32; 7]) -> COMMAND_ACK_DATA {
        self.send(&command_long(system, command, p)).await;
        self.ack(system, command).await
    }

    pub async fn ack(&mut self, system: u8, command: MavCmd) -> COMMAND_ACK_DATA {
        self.wait(system, Duration::from_secs(3), |m| match m {
            MavMessage::COMMAND_ACK(a) if a.command == command => Some(a.clone()),
            _ => None,
        })
        .await
        .unwrap_or_else(|| panic!("no COMMAND_ACK for {command:?} from system {system}"))
    }

    /// Arms in GUIDED (asking again while the vehicle boots) and takes off to `alt` m.
    pub async fn take_off(&mut self, system: u8, alt: f32) {
        use aviary_mavlink::mavlink::dialects::ardupilotmega::MavResult::MAV_RESULT_ACCEPTED;
        let until = Instant::now() + Duration::from_secs(20);
        loop {
            let mode = self
                .command(system, MavCmd::MAV_CMD_DO_SET_MODE, [1.0, 4.0, 0.0, 0.0, 0.0, 0.0, 0.0])
                .await;
            let arm = self
                .command(
                    system,
                    MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
                    [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                )
                .await;
            if mode.result == MAV_RESULT_ACCEPTED && arm.result == MAV_RESULT_ACCEPTED {
                break;
            }
            assert!(Instant::now() < until, "not armed: {mode:?} {arm:?}");
            tokio::time::sleep(Duration::from_millis(200)).await;
        }
        let ack = self
            .command(system, MavCmd::MAV_CMD_NAV_TAKEOFF, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, alt])
            .await;
        assert_eq!(ack.result, MAV_RESULT_ACCEPTED, "take-off");
        let up = self
            .wait(system, Duration::from_secs(20), |m| match m {
                MavMessage::GLOBAL_POSITION_INT(p)
                    if p.relative_alt as f32 >= (alt - 0.3) * 1000.0 =>
                {
                    Some(())
                }
                _ => None,
            })
            .await;
        assert!(up.is_some(), "did not reach {alt} m");
    }
}

/// A quick boot: tests wait for the pre-arm time in simulated seconds.
pub fn quick() -> Behaviour {
    Behaviour::default()
}

/// A COMMAND_LONG to `system`'s autopilot with parameters `p` (1 to 7).
pub fn command_long(system: u8, command: MavCmd, p: [f32; 7]) -> MavMessage {
    MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        param1: p[0],
        param2: p[1],
        param3: p[2],
        param4: p[3],
        param5: p[4],
        param6: p[5],
        param7: p[6],
        command,
        target_system: system,
        target_component: 1,
        confirmation: 0,
    })
}
