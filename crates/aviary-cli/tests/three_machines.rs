//! An operation over three machines on one box: three network namespaces made by the
//! test, for the mission, for an agent with its vehicles and for the stations, joined
//! through a bridge by a `zenohd` router that the test starts (docs/DISTRIBUTED.md).
//!
//! - The paper's mission flies with two of its drones behind the agent, and ends ok;
//!   two stations in the third namespace see the same events.
//! - A second mission's agent namespace cut off from the network: `ConnectionLost`.
//!   Joined again, the link is restored and the run brings its vehicles home.
//!
//! It needs root (to make namespaces) and `zenohd` (crates.io's, pinned, which `.ci/run`
//! installs): it runs where `AVIARY_ZENOHD` names the binary (build.rs).

mod common;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use aviary_api::trace::{Event, Record, Shown, Status};
use common::background;
use common::vehicles::Vehicles;
use common::{repo, scratch, wait_at_most, zenoh_client};

/// The two paper drones behind the agent, with their system ids in `aviary vehicles`'
/// numbering of the paper's world (its order).
const BEHIND: [(&str, u8); 2] = [("video_drone1", 1), ("flir_drone1", 3)];
const SUBNET: &str = "10.213.77";
const ROUTER: &str = "tcp/10.213.77.1:7447";
const PREFIX: &str = "aviary/paper";

/// Runs `ip ARGS`; a failure is the test's.
fn ip(args: &[&str]) {
    let out = Command::new("ip").args(args).output().expect("run ip (iproute2)");
    assert!(
        out.status.success(),
        "ip {}: {} (the test makes network namespaces: it needs root)",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The namespaces, the bridge and its cables; taken down when dropped.
struct Network {
    tag: String,
}

impl Network {
    /// `mission` (.2), `agent` (.3) and `station` (.4), each with its loopback and a cable
    /// to a bridge in the test's own namespace (.1), where the router listens.
    fn new() -> Network {
        let tag = format!("{}", std::process::id() % 100_000);
        let network = Network { tag };
        network.take_down();
        let bridge = network.bridge();
        ip(&["link", "add", &bridge, "type", "bridge"]);
        ip(&["addr", "add", &format!("{SUBNET}.1/24"), "dev", &bridge]);
        ip(&["link", "set", &bridge, "up"]);
        for (n, role) in [(2, "mission"), (3, "agent"), (4, "station")] {
            let (ns, cable) = (network.ns(role), network.cable(role));
            ip(&["netns", "add", &ns]);
            ip(&["link", "add", &cable, "type", "veth", "peer", "name", "eth0", "netns", &ns]);
            ip(&["link", "set", &cable, "master", &bridge]);
            ip(&["link", "set", &cable, "up"]);
            ip(&["-n", &ns, "addr", "add", &format!("{SUBNET}.{n}/24"), "dev", "eth0"]);
            ip(&["-n", &ns, "link", "set", "eth0", "up"]);
            ip(&["-n", &ns, "link", "set", "lo", "up"]);
        }
        network
    }

    fn ns(&self, role: &str) -> String {
        format!("av-{role}-{}", self.tag)
    }

    /// The host's end of a namespace's cable (at most 15 characters).
    fn cable(&self, role: &str) -> String {
        format!("av{}{}", &role[..1], self.tag)
    }

    fn bridge(&self) -> String {
        format!("avb{}", self.tag)
    }

    /// `ip netns exec NS aviary ARGS`.
    fn aviary(&self, role: &str, args: &[&str]) -> Command {
        let mut command = Command::new("ip");
        command.args(["netns", "exec", &self.ns(role), env!("CARGO_BIN_EXE_aviary")]).args(args);
        command
    }

    /// Cuts the namespace's cable (`false`), or joins it again.
    fn connect(&self, role: &str, joined: bool) {
        ip(&["link", "set", &self.cable(role), if joined { "up" } else { "down" }]);
    }

    fn take_down(&self) {
        for role in ["mission", "agent", "station"] {
            let _ = Command::new("ip").args(["netns", "del", &self.ns(role)]).output();
            let _ = Command::new("ip").args(["link", "del", &self.cable(role)]).output();
        }
        let _ = Command::new("ip").args(["link", "del", &self.bridge()]).output();
    }
}

impl Drop for Network {
    fn drop(&mut self) {
        self.take_down();
    }
}

/// A process killed when dropped, its standard output and error kept as they come.
struct Running {
    child: Child,
    out: Arc<Mutex<String>>,
    err: Arc<Mutex<String>>,
}

/// Each line of `from`, kept in `into` as it comes.
fn keep(from: impl std::io::Read + Send + 'static, into: &Arc<Mutex<String>>) {
    let into = Arc::clone(into);
    std::thread::spawn(move || {
        for line in BufReader::new(from).lines().map_while(Result::ok) {
            let mut kept = into.lock().expect("lock");
            kept.push_str(&line);
            kept.push('\n');
        }
    });
}

impl Running {
    fn start(command: &mut Command, dir: &Path) -> Running {
        let mut child = command
            .current_dir(dir)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn");
        let (out, err) = (Arc::default(), Arc::default());
        keep(child.stdout.take().expect("stdout"), &out);
        keep(child.stderr.take().expect("stderr"), &err);
        Running { child, out, err }
    }

    fn out(&self) -> String {
        self.out.lock().expect("lock").clone()
    }

    /// What it said on standard error, for a failure's message.
    fn err(&self) -> String {
        self.err.lock().expect("lock").clone()
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn zenohd() -> PathBuf {
    let binary = PathBuf::from(std::env::var_os("AVIARY_ZENOHD").unwrap_or_default());
    assert!(
        binary.is_file(),
        "zenohd not found at `{}`: AVIARY_ZENOHD must name it (cargo install zenohd --version =1.10.2 --locked)",
        binary.display()
    );
    binary
}

/// The paper's world with the drones of [`BEHIND`] behind agent `field1`.
fn paper_world_behind_the_agent() -> String {
    common::example_world_with(|drone| match BEHIND.iter().find(|(d, _)| *d == drone) {
        Some((_, system)) => format!("mavlink = \"agent:field1\"\nsystem_id = {system}\n"),
        None => String::new(),
    })
}

/// The events a station printed, without telemetry (whose samples a late joiner may
/// take up at another one).
fn events_of(printed: &str) -> Vec<String> {
    printed.lines().filter(|l| !l.contains(r#""event":"telemetry""#)).map(String::from).collect()
}

#[test]
#[cfg_attr(
    not(zenohd),
    ignore = "zenohd not named: set AVIARY_ZENOHD=/path/to/zenohd (as root) to run it (docs/DISTRIBUTED.md)"
)]
fn an_operation_over_three_machines_flies_and_survives_a_cut() {
    let dir = scratch("three_machines");
    let network = Network::new();
    std::fs::write(
        dir.join("router.json5"),
        format!(
            r#"{{ mode: "router", listen: {{ endpoints: ["{ROUTER}"] }},
                scouting: {{ multicast: {{ enabled: false }} }} }}"#
        ),
    )
    .expect("config");
    let _router = Running::start(Command::new(zenohd()).args(["-c", "router.json5"]), &dir);
    common::wait_for_listener(ROUTER.trim_start_matches("tcp/"), Duration::from_secs(30));
    std::fs::write(dir.join("client.json5"), zenoh_client(ROUTER)).expect("config");

    // The agent's machine: the paper's vehicles at 20 times real time, and the agent.
    let examples = repo().join("examples");
    let vehicles = Vehicles::start_in(
        &network.ns("agent"),
        &examples.join("search_and_rescue.world.toml"),
        "20",
    );
    let mavlink = format!("tcp:127.0.0.1:{}", vehicles.port);
    let agent_args =
        ["agent", "--name", "field1", "--zenoh", "client.json5", "--mavlink", &mavlink];
    let _agent = Running::start(&mut network.aviary("agent", &agent_args), &dir);

    // The stations' machine: two stations watching every event.
    let watch = ["ctl", "--zenoh", "client.json5", "--zenoh-prefix", PREFIX];
    let stations: Vec<Running> = (0..2)
        .map(|_| {
            Running::start(
                &mut network.aviary("station", &[&watch[..], &["events"]].concat()),
                &dir,
            )
        })
        .collect();
    // Subscribed before the mission's first event: a station that joins late misses it.
    std::thread::sleep(Duration::from_secs(2));

    // The mission's machine.
    std::fs::copy(examples.join("search_and_rescue.mission"), dir.join("m.mission")).expect("copy");
    std::fs::write(dir.join("m.world.toml"), paper_world_behind_the_agent()).expect("world");
    let mut run = Running::start(
        &mut network.aviary(
            "mission",
            &[
                "run",
                "m.mission",
                "--zenoh",
                "client.json5",
                "--zenoh-prefix",
                PREFIX,
                "--quiet",
                "--trace",
                "t.jsonl",
            ],
        ),
        &dir,
    );
    let code = wait_at_most(&mut run.child, Duration::from_secs(240), "the paper's mission");
    let flown = background::events(&dir.join("t.jsonl"));
    assert_eq!(code, 0, "{}\nagent: {}\n{:?}", run.err(), _agent.err(), flown.last());
    assert!(
        matches!(
            flown.last().map(|e| &e.event),
            Some(Event::MissionEnd { status: Status::Ok, .. })
        ),
        "{:?}",
        flown.last()
    );
    for (drone, _) in BEHIND {
        let via_agent =
            |e: &Record| matches!(&e.event, Event::ApiDone { actor, .. } if actor == drone);
        assert!(flown.iter().any(via_agent), "{drone} flew nothing: {flown:?}");
    }
    // Both stations saw every event of the trace, in its order, up to the mission's end.
    let start = Instant::now();
    while stations.iter().any(|s| !s.out().contains(r#""event":"mission_end""#)) {
        assert!(start.elapsed() < Duration::from_secs(10), "a station missed the end");
        std::thread::sleep(Duration::from_millis(50));
    }
    let written = std::fs::read_to_string(dir.join("t.jsonl")).expect("trace");
    let expected = events_of(&written);
    for station in &stations {
        assert_eq!(events_of(&station.out()), expected, "a station saw what the trace holds");
    }
    drop(stations);

    // A second mission; its agent's machine cut off mid-flight, and joined again.
    std::fs::write(
        dir.join("hold.mission"),
        "MISSION Hold:\n    video_drone1 TakeOff WITH 10m\n    video_drone1 Hover WITH 600s\n",
    )
    .expect("mission");
    std::fs::write(dir.join("hold.world.toml"), paper_world_behind_the_agent()).expect("world");
    let mut hold = Running::start(
        &mut network.aviary(
            "mission",
            &["run", "hold.mission", "--zenoh", "client.json5", "--quiet", "--trace", "hold.jsonl"],
        ),
        &dir,
    );
    let held = dir.join("hold.jsonl");
    let hover = |e: &Record| background::is_call(e, aviary_api::Function::Hover);
    background::first_event(&held, Duration::from_secs(60), "hover", hover);
    network.connect("agent", false);
    // 3 s of silence, on the vehicles' clock (20 times real time) or the wall's.
    let lost = |e: &Record| background::is_exception(e, "ConnectionLost");
    let exception = background::first_event(&held, Duration::from_secs(6), "ConnectionLost", lost);
    let Event::Exception { args, .. } = &exception.event else { unreachable!() };
    let reason = args.first().and_then(Shown::as_str).unwrap_or("");
    assert!(reason.contains("on agent:field1"), "{exception:?}");
    network.connect("agent", true);
    let code = wait_at_most(&mut hold.child, Duration::from_secs(90), "the cut mission");
    assert_eq!(code, 1, "unhandled, ConnectionLost fails the mission");
    let held = background::events(&held);
    assert!(background::signalled(&held, "ConnectionRestored"), "{held:?}");
}
