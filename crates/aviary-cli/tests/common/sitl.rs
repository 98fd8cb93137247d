//! ArduCopter SITL for tests: each vehicle a process of its own, with its own instance
//! number (and so its own ports), system id and scratch directory, stopped when dropped
//! (also when the test panics). A second MAVLink client on the vehicle's SERIAL1 (the
//! test's "ground station") changes parameters mid-flight and records what the vehicle
//! reports, independently of `aviary run`.
//!
//! The binary is `AVIARY_SITL`, with ArduPilot's `copter.parm` beside it or in the
//! ArduPilot tree it was built in. The gripper's parameters are ours
//! (`tests/sitl/gripper.parm`). The tests that use it are ignored where `AVIARY_SITL` is
//! not set (build.rs); set to a path that is not a binary, they fail and say so.

use std::io::Write;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU16, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use aviary_mavlink::mavlink::{self, dialects::ardupilotmega as mav, MavConnection};
use aviary_mavlink::Origin;

/// The world origin the SITL tests use (the example worlds' site).
pub const ORIGIN: Origin = Origin { lat: 46.6167, lon: 14.2650, alt: 440.0 };

/// Battery parameters for a copter that can fly the paper's mission: SITL's default
/// (3300 mAh, some 6.5 minutes) is not enough for the longest drone's ~10 minutes.
pub const BIG_BATTERY: &[(&str, f64)] = &[("BATT_CAPACITY", 16500.0), ("SIM_BATT_CAP_AH", 16.5)];

/// The SITL binary and its parameter files.
pub struct Files {
    pub binary: PathBuf,
    pub copter_parm: PathBuf,
    pub gripper_parm: PathBuf,
}

pub fn files() -> Files {
    let binary = PathBuf::from(std::env::var_os("AVIARY_SITL").unwrap_or_default());
    assert!(
        binary.is_file(),
        "ArduCopter SITL not found at `{}`: AVIARY_SITL must name the binary that ArduPilot's `./waf copter` builds (build/sitl/bin/arducopter; docs/REAL_DRONES.md)",
        binary.display()
    );
    let copter_parm = copter_parm(&binary).unwrap_or_else(|| {
        panic!(
            "ArduPilot's copter.parm not found for {}: put Tools/autotest/default_params/copter.parm of the ArduPilot tree beside the binary",
            binary.display()
        )
    });
    let gripper_parm = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/sitl/gripper.parm");
    Files { binary, copter_parm, gripper_parm }
}

/// ArduPilot's default parameters for the copter: beside the binary, or in the tree it
/// was built in (`build/sitl/bin/arducopter` is three folders below the tree's top).
fn copter_parm(binary: &Path) -> Option<PathBuf> {
    let beside = binary.with_file_name("copter.parm");
    let tree = binary.ancestors().nth(4)?.join("Tools/autotest/default_params/copter.parm");
    [beside, tree].into_iter().find(|p| p.is_file())
}

/// SITL's `--speedup`: `AVIARY_SITL_SPEEDUP`, else 1 (real time). The mission keeps the
/// vehicles' clock, so a faster SITL makes the tests faster and flies the same.
pub fn speedup() -> String {
    std::env::var("AVIARY_SITL_SPEEDUP")
        .ok()
        .filter(|s| s.parse::<f64>().is_ok_and(|x| x > 0.0))
        .unwrap_or_else(|| "1".into())
}

/// Instance numbers this test binary hands out; each test binary has its own range
/// (`first`), and a number whose ports are taken by somebody else is passed over.
static NEXT: AtomicU16 = AtomicU16::new(0);

fn free(port: u16) -> bool {
    TcpListener::bind(("127.0.0.1", port)).is_ok()
}

fn instance(first: u16) -> u16 {
    loop {
        let n = first + NEXT.fetch_add(1, Ordering::SeqCst);
        assert!(n < first + 100, "no free SITL instance number from {first}");
        // SERIAL0..2 are TCP 5760, 5762 and 5763 plus 10 per instance.
        if [0, 2, 3].iter().all(|k| free(5760 + 10 * n + k)) {
            return n;
        }
    }
}

/// One SITL copter.
pub struct Sitl {
    child: Option<Child>,
    pub instance: u16,
    pub system: u8,
    pub dir: PathBuf,
    args: Vec<String>,
}

impl Sitl {
    /// Starts a copter at `home` (local metres about [`ORIGIN`]) with `params` added to
    /// ArduPilot's defaults, and waits until it listens on SERIAL0.
    pub fn start(
        scratch: &Path,
        first: u16,
        system: u8,
        home: [f64; 2],
        params: &[(&str, f64)],
    ) -> Sitl {
        let files = files();
        let instance = instance(first);
        let dir = scratch.join(format!("sitl{instance}"));
        std::fs::create_dir_all(&dir).expect("SITL dir");
        let mut defaults =
            format!("{},{}", files.copter_parm.display(), files.gripper_parm.display());
        if !params.is_empty() {
            let mut f = std::fs::File::create(dir.join("extra.parm")).expect("extra.parm");
            for (name, value) in params {
                writeln!(f, "{name} {value}").expect("extra.parm");
            }
            defaults.push_str(",extra.parm");
        }
        let (lat, lon) = ORIGIN.to_geodetic(home[0], home[1]);
        let args = vec![
            "--model".into(),
            "quad".into(),
            "--speedup".into(),
            speedup(),
            "--home".into(),
            format!("{lat:.8},{lon:.8},{},0", ORIGIN.alt),
            "-I".into(),
            instance.to_string(),
            "--sysid".into(),
            system.to_string(),
            "--defaults".into(),
            defaults,
        ];
        let mut sitl = Sitl { child: None, instance, system, dir, args };
        sitl.launch(&files.binary);
        sitl
    }

    fn launch(&mut self, binary: &Path) {
        let log = std::fs::File::create(self.dir.join("sitl.log")).expect("sitl.log");
        let child = Command::new(binary)
            .args(&self.args)
            .current_dir(&self.dir)
            .stdin(Stdio::null())
            .stdout(log.try_clone().expect("log"))
            .stderr(log)
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {}: {e}", binary.display()));
        self.child = Some(child);
        // SITL says so once SERIAL0 listens (about 1 s); nothing else may connect there.
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            let log = std::fs::read_to_string(self.dir.join("sitl.log")).unwrap_or_default();
            if log.contains("Waiting for connection") {
                return;
            }
            if let Some(Some(status)) = self.child.as_mut().map(|c| c.try_wait().ok().flatten()) {
                panic!(
                    "SITL instance {} exited ({status}) before it listened:\n{log}",
                    self.instance
                );
            }
            assert!(
                Instant::now() < deadline,
                "SITL instance {} did not listen within 30 s:\n{log}",
                self.instance
            );
            std::thread::sleep(Duration::from_millis(100));
        }
    }

    /// The `mavlink =` address `aviary run` connects to (SERIAL0).
    pub fn address(&self) -> String {
        format!("tcp:127.0.0.1:{}", 5760 + 10 * self.instance)
    }

    /// Stops the process (the vehicle is gone, as on a lost link).
    pub fn kill(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }

    /// Starts it again in the same directory: same parameters, and it boots on the
    /// ground at home.
    pub fn restart(&mut self) {
        self.kill();
        self.launch(&files().binary);
    }

    /// A ground station on SERIAL1 (connect after `aviary run` has connected to SERIAL0:
    /// SITL opens SERIAL1 once SERIAL0 has its client).
    pub fn gcs(&self, within: Duration) -> Gcs {
        Gcs::connect(5762 + 10 * self.instance, self.system, within)
    }
}

impl Drop for Sitl {
    fn drop(&mut self) {
        self.kill();
    }
}

/// What the test's own ground station saw.
#[derive(Default)]
pub struct Seen {
    /// (seconds since connect, local x, y, height above home)
    pub track: Vec<(f64, [f64; 3])>,
    pub texts: Vec<String>,
    pub params: Vec<(String, f32)>,
    /// The vehicle's answers to commands, in order.
    pub acks: Vec<(mav::MavCmd, mav::MavResult)>,
}

pub struct Gcs {
    conn: Arc<dyn MavConnection<mav::MavMessage> + Send + Sync>,
    system: u8,
    pub seen: Arc<Mutex<Seen>>,
}

impl Gcs {
    pub fn connect(port: u16, system: u8, within: Duration) -> Gcs {
        Gcs::connect_to(&format!("tcpout:127.0.0.1:{port}"), system, within)
    }

    /// A ground station on `address` (as the `mavlink` crate names it) for `system`.
    pub fn connect_to(address: &str, system: u8, within: Duration) -> Gcs {
        let deadline = Instant::now() + within;
        let conn = loop {
            match mavlink::connect::<mav::MavMessage>(address) {
                Ok(c) => break c,
                Err(e) => {
                    assert!(Instant::now() < deadline, "no ground station link on {address}: {e}");
                    std::thread::sleep(Duration::from_millis(250));
                }
            }
        };
        let conn: Arc<dyn MavConnection<mav::MavMessage> + Send + Sync> = Arc::from(conn);
        let seen = Arc::new(Mutex::new(Seen::default()));
        let (c, s) = (Arc::clone(&conn), Arc::clone(&seen));
        let start = Instant::now();
        std::thread::spawn(move || {
            loop {
                // A message this dialect cannot read is passed over; a closed link ends the reader.
                let (header, msg) = match c.recv() {
                    Ok(m) => m,
                    // The connection reads with a timeout: waiting is not an end.
                    Err(mavlink::error::MessageReadError::Io(e))
                        if !matches!(
                            e.kind(),
                            std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                        ) =>
                    {
                        break
                    }
                    Err(_) => continue,
                };
                if header.system_id != u32::from(system) {
                    continue;
                }
                let mut seen = s.lock().unwrap();
                match msg {
                    // 0°N 0°E: no position yet.
                    mav::MavMessage::GLOBAL_POSITION_INT(p) if p.lat == 0 && p.lon == 0 => {}
                    mav::MavMessage::GLOBAL_POSITION_INT(p) => {
                        let xy = ORIGIN.from_e7(p.lat, p.lon);
                        seen.track.push((
                            start.elapsed().as_secs_f64(),
                            [xy[0], xy[1], f64::from(p.relative_alt) / 1000.0],
                        ));
                    }
                    mav::MavMessage::STATUSTEXT(t) => seen
                        .texts
                        .push(t.text.to_str().unwrap_or("").trim_end_matches('\0').to_owned()),
                    mav::MavMessage::COMMAND_ACK(a) => seen.acks.push((a.command, a.result)),
                    mav::MavMessage::PARAM_VALUE(v) => seen.params.push((
                        v.param_id.to_str().unwrap_or("").trim_end_matches('\0').to_owned(),
                        v.param_value,
                    )),
                    _ => {}
                }
            }
        });
        // Positions at 10 Hz on this link too, asked until they come (a request sent
        // while the vehicle boots is lost).
        let (c, s) = (Arc::clone(&conn), Arc::clone(&seen));
        std::thread::spawn(move || {
            while Arc::strong_count(&c) > 1 && s.lock().unwrap().track.len() < 5 {
                let ask = mav::MavMessage::COMMAND_LONG(mav::COMMAND_LONG_DATA {
                    command: mav::MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL,
                    param1: 33.0,
                    param2: 100_000.0,
                    target_system: system,
                    target_component: 1,
                    ..Default::default()
                });
                let _ = c.send(
                    &mavlink::MavHeader { system_id: 250, component_id: 190, sequence: 0 },
                    &ask,
                );
                std::thread::sleep(Duration::from_secs(2));
            }
        });
        Gcs { conn, system, seen }
    }

    fn send(&self, msg: mav::MavMessage) {
        let header = mavlink::MavHeader { system_id: 250, component_id: 190, sequence: 0 };
        let _ = self.conn.send(&header, &msg);
    }

    /// Sends a command (COMMAND_LONG), again until the vehicle answers it: its answer.
    pub fn command(&self, command: mav::MavCmd, p: [f32; 7]) -> mav::MavResult {
        let deadline = Instant::now() + Duration::from_secs(10);
        let answered = |seen: &Seen| seen.acks.iter().filter(|a| a.0 == command).count();
        let before = answered(&self.seen.lock().unwrap());
        loop {
            self.send(mav::MavMessage::COMMAND_LONG(mav::COMMAND_LONG_DATA {
                command,
                param1: p[0],
                param2: p[1],
                param3: p[2],
                param4: p[3],
                param5: p[4],
                param6: p[5],
                param7: p[6],
                target_system: self.system,
                target_component: 1,
                confirmation: 0,
            }));
            std::thread::sleep(Duration::from_millis(500));
            let seen = self.seen.lock().unwrap();
            if answered(&seen) > before {
                return seen.acks.iter().rev().find(|a| a.0 == command).map(|a| a.1).unwrap();
            }
            drop(seen);
            assert!(Instant::now() < deadline, "the vehicle did not answer {command:?}");
        }
    }

    /// A parameter's value as the vehicle sends it (PARAM_REQUEST_READ, asked again
    /// until it answers, for at most 10 s).
    pub fn param(&self, name: &str) -> f32 {
        let deadline = Instant::now() + Duration::from_secs(10);
        let before = self.seen.lock().unwrap().params.len();
        loop {
            self.send(mav::MavMessage::PARAM_REQUEST_READ(mav::PARAM_REQUEST_READ_DATA {
                param_index: -1,
                target_system: self.system,
                target_component: 1,
                param_id: name.into(),
            }));
            std::thread::sleep(Duration::from_millis(300));
            if let Some((_, v)) =
                self.seen.lock().unwrap().params[before..].iter().rev().find(|(n, _)| n == name)
            {
                return *v;
            }
            assert!(Instant::now() < deadline, "the vehicle did not send {name}");
        }
    }

    /// Sets a parameter and waits for the vehicle to echo it.
    pub fn set_param(&self, name: &str, value: f32) {
        self.set_param_as(name, value, mav::MavParamType::MAV_PARAM_TYPE_REAL32);
    }

    /// Sets an integer parameter as PX4 takes it: its bytes in the float's place.
    pub fn set_param_px4_int(&self, name: &str, value: i32) {
        self.set_param_as(
            name,
            f32::from_bits(value as u32),
            mav::MavParamType::MAV_PARAM_TYPE_INT32,
        );
    }

    fn set_param_as(&self, name: &str, value: f32, kind: mav::MavParamType) {
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            self.send(mav::MavMessage::PARAM_SET(mav::PARAM_SET_DATA {
                param_value: value,
                target_system: self.system,
                target_component: 1,
                param_id: name.into(),
                param_type: kind,
            }));
            std::thread::sleep(Duration::from_millis(300));
            if self.seen.lock().unwrap().params.iter().any(|(n, v)| {
                n == name && (v.to_bits() == value.to_bits() || (*v - value).abs() < 1e-3)
            }) {
                return;
            }
            assert!(Instant::now() < deadline, "the vehicle did not confirm {name} = {value}");
        }
    }

    /// The last position the vehicle reported on this link.
    pub fn last(&self) -> Option<[f64; 3]> {
        self.seen.lock().unwrap().track.last().map(|p| p.1)
    }
}

/// Waits until `check` holds, or fails the test after `limit` saying `what`.
pub fn wait_until(limit: Duration, what: &str, mut check: impl FnMut() -> bool) {
    let deadline = Instant::now() + limit;
    while !check() {
        assert!(Instant::now() < deadline, "waited {} s for {what}", limit.as_secs());
        std::thread::sleep(Duration::from_millis(200));
    }
}
