//! What the operator sees: the mission's state, folded from its trace events.

use serde_json::{json, Value};

#[derive(Default)]
pub struct MissionState {
    mission: Option<String>,
    t: f64,
    /// `running`, then the outcome (`ok`, `failed`, `aborted`).
    status: String,
    reason: Option<String>,
    paused: bool,
    blocks: Vec<String>,
    /// Running activities, in the order they started.
    activities: Vec<Value>,
    /// Each drone's last telemetry, by name, in the order first seen.
    drones: Vec<(String, Value)>,
}

impl MissionState {
    pub fn observe(&mut self, e: &Value) {
        self.t = e["t"].as_f64().unwrap_or(self.t);
        match e["event"].as_str().unwrap_or("") {
            "mission_start" => {
                self.mission = e["mission"].as_str().map(str::to_string);
                self.status = "running".into();
            }
            "mission_end" => {
                self.status = e["status"].as_str().unwrap_or("").to_string();
                self.reason = e["reason"].as_str().map(str::to_string);
            }
            "block_start" => self.blocks.push(e["block"].as_str().unwrap_or("").to_string()),
            "block_end" => {
                if let Some(i) = self.blocks.iter().rposition(|b| *b == e["block"]) {
                    self.blocks.remove(i);
                }
            }
            "capability_start" => self.activities.push(json!({
                "capability": e["capability"], "tag": e["tag"], "actor": e["actor"], "args": e["args"], "since": e["t"], "paused": false,
            })),
            "capability_end" => {
                let same = |a: &Value| a["capability"] == e["capability"] && a["actor"] == e["actor"] && a["tag"] == e["tag"];
                if let Some(i) = self.activities.iter().position(same) {
                    self.activities.remove(i);
                }
            }
            "leash" => {
                let paused = match e["action"].as_str() {
                    Some("PAUSE") => Some(true),
                    Some("RESUME") => Some(false),
                    _ => None,
                };
                if let Some(paused) = paused {
                    for a in self.activities.iter_mut().filter(|a| a["capability"] == e["capability"] && a["tag"] == e["tag"]) {
                        a["paused"] = json!(paused);
                    }
                }
            }
            "telemetry" => {
                let name = e["actor"].as_str().unwrap_or("").to_string();
                let t = json!({ "position": e["position"], "battery": e["battery"], "state": e["state"], "t": e["t"] });
                match self.drones.iter_mut().find(|(n, _)| *n == name) {
                    Some((_, v)) => *v = t,
                    None => self.drones.push((name, t)),
                }
            }
            _ => {}
        }
    }

    pub fn set_paused(&mut self, paused: bool) {
        self.paused = paused;
    }

    pub fn to_json(&self) -> Value {
        json!({
            "mission": self.mission,
            "t": self.t,
            "status": self.status,
            "reason": self.reason,
            "paused": self.paused,
            "blocks": self.blocks,
            "activities": self.activities,
            "drones": self.drones.iter().map(|(n, v)| { let mut d = v.clone(); d["name"] = json!(n); d }).collect::<Vec<_>>(),
        })
    }
}
