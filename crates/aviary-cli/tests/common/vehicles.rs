//! `aviary vehicles` for tests: the simulated MAVLink vehicles a user runs, on a free
//! loopback port that its first line says.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

/// A field of two drones, `scout` and `buddy`, with two places, `Near` and `Far`, on the
/// Earth: what the MAVLink tests fly on loopback.
pub const SMALL_WORLD: &str = "\
[site]
name = \"Loopback field\"
origin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }
geofence = [[-100, -100], [100, -100], [100, 100], [-100, 100]]

[places]
Near = [10, 10]
Far = [-20, 10]

[drones.scout]
home = [0, 0]

[drones.buddy]
home = [10, 0]
";

/// A running `aviary vehicles`, killed when dropped.
pub struct Vehicles {
    pub child: Child,
    pub port: u16,
    /// Kept open: the server's later lines must have somewhere to go.
    _stdout: BufReader<std::process::ChildStdout>,
}

impl Vehicles {
    pub fn start(world: &Path, speed: &str) -> Vehicles {
        Vehicles::start_as(world, speed, "ardupilot")
    }

    /// `aviary vehicles --autopilot AUTOPILOT`.
    pub fn start_as(world: &Path, speed: &str, autopilot: &str) -> Vehicles {
        let mut command = Command::new(env!("CARGO_BIN_EXE_aviary"));
        command.args(["vehicles", "--autopilot", autopilot]);
        Vehicles::spawn(command, world, speed)
    }

    /// Listening on loopback `port`: vehicles started again where the last ones were.
    pub fn start_on(world: &Path, speed: &str, port: u16) -> Vehicles {
        let mut command = Command::new(env!("CARGO_BIN_EXE_aviary"));
        command.args(["vehicles", "--listen", &format!("tcp:127.0.0.1:{port}")]);
        Vehicles::spawn(command, world, speed)
    }

    /// Taking only commands signed with `key` (MAVLink 2 signing), and signing their own.
    pub fn start_signed(world: &Path, speed: &str, key: &str) -> Vehicles {
        let mut command = Command::new(env!("CARGO_BIN_EXE_aviary"));
        command.args(["vehicles", "--signing-key", key]);
        Vehicles::spawn(command, world, speed)
    }

    /// In the network namespace `netns` (`ip netns exec`), listening on its loopback.
    pub fn start_in(netns: &str, world: &Path, speed: &str) -> Vehicles {
        let mut command = Command::new("ip");
        command.args(["netns", "exec", netns, env!("CARGO_BIN_EXE_aviary"), "vehicles"]);
        Vehicles::spawn(command, world, speed)
    }

    /// `command` (`aviary vehicles` and its own options) serving `world` at `speed`, on a
    /// free loopback port unless the command says where.
    fn spawn(mut command: Command, world: &Path, speed: &str) -> Vehicles {
        if !command.get_args().any(|a| a == "--listen") {
            command.args(["--listen", "tcp:127.0.0.1:0"]);
        }
        let mut child = command
            .args(["--world", &world.to_string_lossy()])
            .args(["--speed", speed])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn aviary vehicles");
        let mut first = String::new();
        let mut stdout = BufReader::new(child.stdout.take().expect("stdout"));
        stdout.read_line(&mut first).expect("read the first line");
        let port = first
            .trim()
            .rsplit(':')
            .next()
            .and_then(|p| p.parse().ok())
            .unwrap_or_else(|| panic!("no port in {first:?}"));
        Vehicles { child, port, _stdout: stdout }
    }
}

impl Drop for Vehicles {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
