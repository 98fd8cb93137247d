//! PX4 SITL for tests, with PX4's built-in SIH simulator (no Gazebo): each vehicle a
//! process of its own, with its own instance number (so its own UDP ports and system id
//! N + 1) and working directory, stopped when dropped (also when the test panics).
//!
//! The binary is `AVIARY_PX4` (the `bin/px4` of a `px4_sitl_default` build, its ROMFS
//! `etc` beside `bin`). The tests that use it are ignored where `AVIARY_PX4` is not set
//! (build.rs). `AVIARY_PX4_SPEED` sets `PX4_SIM_SPEED_FACTOR` (1 when not set): the
//! mission keeps the vehicles' clock, so a faster PX4 flies the same mission sooner.

use std::collections::BTreeSet;
use std::net::UdpSocket;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use aviary_mavlink::Origin;

/// The world origin the PX4 tests use (the example worlds' site).
pub const ORIGIN: Origin = Origin { lat: 46.6167, lon: 14.2650, alt: 440.0 };

pub fn binary() -> PathBuf {
    let binary = PathBuf::from(std::env::var_os("AVIARY_PX4").unwrap_or_default());
    assert!(
        binary.is_file(),
        "PX4 SITL not found at `{}`: AVIARY_PX4 must name the bin/px4 of PX4's `make px4_sitl_default` build (docs/REAL_DRONES.md)",
        binary.display()
    );
    binary
}

/// `PX4_SIM_SPEED_FACTOR`: `AVIARY_PX4_SPEED`, else 1.
pub fn speed() -> String {
    std::env::var("AVIARY_PX4_SPEED")
        .ok()
        .filter(|s| s.parse::<f64>().is_ok_and(|x| x > 0.0))
        .unwrap_or_else(|| "1".into())
}

/// The instance numbers (0 to 9) in use by this test binary's copters. PX4 keeps a lock
/// file per number in the system's temporary folder, so copters that fly at once need
/// distinct numbers; a copter's number is free again once it is dropped.
static IN_USE: Mutex<BTreeSet<u16>> = Mutex::new(BTreeSet::new());

/// A free instance number, waited for while other tests' copters hold them all; a number
/// whose ports are taken by somebody else is passed over.
fn instance() -> u16 {
    let deadline = Instant::now() + Duration::from_secs(1800);
    loop {
        {
            let mut in_use = IN_USE.lock().unwrap_or_else(|e| e.into_inner());
            // From instance 10 on, PX4 sends every API link to the same port, 14549.
            let free = (0..=9u16).find(|n| {
                !in_use.contains(n)
                    // Its GCS port, its API port, and the API port it sends to.
                    && [18570, 14580, 14540]
                        .iter()
                        .all(|p| UdpSocket::bind(("127.0.0.1", p + n)).is_ok())
            });
            if let Some(n) = free {
                in_use.insert(n);
                return n;
            }
        }
        assert!(Instant::now() < deadline, "no PX4 instance number from 0 to 9 came free");
        std::thread::sleep(Duration::from_millis(500));
    }
}

/// One PX4 SITL copter.
pub struct Px4 {
    child: Option<Child>,
    pub instance: u16,
    pub system: u8,
    pub dir: PathBuf,
    home: [f64; 2],
}

impl Px4 {
    /// Starts a copter at `home` (local metres about [`ORIGIN`]) and waits until it says
    /// its start-up script has run.
    pub fn start(scratch: &Path, home: [f64; 2]) -> Px4 {
        let instance = instance();
        let dir = scratch.join(format!("px4_{instance}"));
        std::fs::create_dir_all(&dir).expect("PX4 dir");
        let system = u8::try_from(instance + 1).expect("a system id");
        let mut px4 = Px4 { child: None, instance, system, dir, home };
        px4.launch();
        px4
    }

    fn launch(&mut self) {
        let binary = binary();
        let etc = binary.parent().and_then(Path::parent).map(|b| b.join("etc")).unwrap_or_default();
        let (lat, lon) = ORIGIN.to_geodetic(self.home[0], self.home[1]);
        let log = std::fs::File::create(self.dir.join("px4.log")).expect("px4.log");
        let child = Command::new(&binary)
            .args(["-i", &self.instance.to_string(), "-d", "-w"])
            .arg(&self.dir)
            .args(["-s", "etc/init.d-posix/rcS"])
            .arg(&etc)
            .env("PX4_SYS_AUTOSTART", "10040")
            .env("PX4_SIMULATOR", "sihsim")
            .env("PX4_SIM_MODEL", "sihsim_quadx")
            .env("PX4_HOME_LAT", format!("{lat:.8}"))
            .env("PX4_HOME_LON", format!("{lon:.8}"))
            .env("PX4_HOME_ALT", format!("{}", ORIGIN.alt))
            .env("PX4_SIM_SPEED_FACTOR", speed())
            .current_dir(&self.dir)
            .stdin(Stdio::null())
            .stdout(log.try_clone().expect("log"))
            .stderr(log)
            .spawn()
            .unwrap_or_else(|e| panic!("cannot start {}: {e}", binary.display()));
        self.child = Some(child);
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let log = std::fs::read_to_string(self.dir.join("px4.log")).unwrap_or_default();
            if log.contains("Startup script returned successfully") {
                return;
            }
            if let Some(Some(status)) = self.child.as_mut().map(|c| c.try_wait().ok().flatten()) {
                panic!(
                    "PX4 instance {} exited ({status}) before it started:\n{log}",
                    self.instance
                );
            }
            assert!(
                Instant::now() < deadline,
                "PX4 instance {} did not start within 60 s:\n{log}",
                self.instance
            );
            std::thread::sleep(Duration::from_millis(200));
        }
    }

    /// Where `aviary run` listens for it: PX4 sends its API link to UDP 14540 + instance.
    pub fn address(&self) -> String {
        format!("udp:127.0.0.1:{}", 14540 + self.instance)
    }

    /// Stops the process, as a vehicle that loses power (its parameters stay).
    pub fn kill(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }

    /// Starts it again in the same folder (the parameters it saved there hold).
    pub fn restart(&mut self) {
        self.kill();
        self.launch();
    }

    /// A ground station on its GCS port (UDP 18570 + instance), which PX4 answers once
    /// it hears from it.
    pub fn gcs(&self) -> super::sitl::Gcs {
        let address = format!("udpout:127.0.0.1:{}", 18570 + self.instance);
        super::sitl::Gcs::connect_to(&address, self.system, Duration::from_secs(10))
    }

    /// With its gripper (PX4's payload deliverer, started at boot when PD_GRIPPER_EN is
    /// 1): the parameter set and saved, and the vehicle started again.
    /// PX4 saves a changed parameter at most 2 s (of its time) after the last save, so
    /// the restart waits, and is made again when the parameter did not survive it (a
    /// payload deliverer that is not running leaves DO_GRIPPER unanswered).
    pub fn with_gripper(mut self) -> Px4 {
        for _ in 0..3 {
            {
                let gcs = self.gcs();
                if gcs.param("PD_GRIPPER_EN").to_bits() == 1 {
                    return self;
                }
                gcs.set_param_px4_int("PD_GRIPPER_EN", 1);
            }
            std::thread::sleep(Duration::from_millis(2500));
            self.restart();
        }
        panic!("PX4 instance {} kept PD_GRIPPER_EN 0 over three restarts", self.instance);
    }

    /// The flight logs (ULog) it wrote.
    pub fn logs(&self) -> Vec<PathBuf> {
        super::logs::files_ending(&self.dir.join("log"), ".ulg")
    }
}

impl Drop for Px4 {
    fn drop(&mut self) {
        self.kill();
        IN_USE.lock().unwrap_or_else(|e| e.into_inner()).remove(&self.instance);
    }
}
