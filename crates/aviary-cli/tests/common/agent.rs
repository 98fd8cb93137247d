//! `aviary agent` for tests: the agent `field1` of the vehicles on a loopback port.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};

/// An `aviary agent`, its standard error kept as it comes; killed when dropped.
pub struct Agent {
    pub child: Child,
    said: Arc<Mutex<String>>,
}

impl Agent {
    /// Agent `field1` for the vehicles on loopback port `vehicles`, with the Zenoh
    /// configuration `config` (written to `dir/agent.json5`).
    pub fn start(dir: &Path, config: &str, vehicles: u16) -> Agent {
        std::fs::write(dir.join("agent.json5"), config).expect("config");
        let mut child = Command::new(env!("CARGO_BIN_EXE_aviary"))
            .args(["agent", "--name", "field1", "--zenoh", "agent.json5", "--mavlink"])
            .arg(format!("tcp:127.0.0.1:{vehicles}"))
            .current_dir(dir)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn aviary agent");
        let said = Arc::new(Mutex::new(String::new()));
        let stderr = BufReader::new(child.stderr.take().expect("stderr"));
        let into = Arc::clone(&said);
        std::thread::spawn(move || {
            for line in stderr.lines().map_while(Result::ok) {
                let mut said = into.lock().expect("lock");
                said.push_str(&line);
                said.push('\n');
            }
        });
        Agent { child, said }
    }

    /// What it has said on standard error so far.
    pub fn said(&self) -> String {
        self.said.lock().expect("lock").clone()
    }
}

impl Drop for Agent {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}
