//! What the operator sees: the mission's state, folded from its trace events.

use aviary_api::trace::{Event, Params, Record};
use serde_json::{json, Value};

#[derive(Default)]
pub struct MissionState {
    mission: Option<String>,
    t: f64,
    /// `running`, then the outcome (`ok`, `failed`, `aborted`); empty before the start.
    status: &'static str,
    reason: Option<String>,
    paused: bool,
    blocks: Vec<String>,
    /// Running activities, in the order they started.
    activities: Vec<Activity>,
    /// Each drone's last telemetry, by name, in the order first seen.
    drones: Vec<(String, Value)>,
}

/// A running activity: who does what, since when, and whether it is paused.
struct Activity {
    capability: String,
    tag: Option<String>,
    actor: String,
    args: Value,
    since: f64,
    paused: bool,
}

impl MissionState {
    pub fn observe(&mut self, record: &Record) {
        // A time that is not finite is `null` in the trace: the last one stands.
        if record.t.is_finite() {
            self.t = record.t;
        }
        match &record.event {
            Event::MissionStart { mission } => {
                self.mission = Some(mission.to_string());
                self.status = "running";
            }
            Event::MissionEnd { status, reason } => {
                self.status = status.as_str();
                self.reason = reason.as_deref().map(str::to_string);
            }
            Event::BlockStart { block } => self.blocks.push(block.to_string()),
            Event::BlockEnd { block, .. } => {
                if let Some(i) = self.blocks.iter().rposition(|b| b == block) {
                    self.blocks.remove(i);
                }
            }
            Event::CapabilityStart { actor, capability, tag, args } => {
                self.activities.push(Activity {
                    capability: capability.to_string(),
                    tag: tag.as_deref().map(str::to_string),
                    actor: actor.to_string(),
                    args: shown(args),
                    since: record.t,
                    paused: false,
                })
            }
            Event::CapabilityEnd { actor, capability, tag, .. } => {
                let same = |a: &Activity| {
                    a.capability == *capability
                        && a.actor == *actor
                        && a.tag.as_deref() == tag.as_deref()
                };
                if let Some(i) = self.activities.iter().position(same) {
                    self.activities.remove(i);
                }
            }
            Event::Leash { capability, tag, action } => {
                let paused = match action.as_ref() {
                    "PAUSE" => Some(true),
                    "RESUME" => Some(false),
                    _ => None,
                };
                if let Some(paused) = paused {
                    let tagged = |a: &&mut Activity| {
                        a.capability == *capability && a.tag.as_deref() == Some(tag.as_ref())
                    };
                    for a in self.activities.iter_mut().filter(tagged) {
                        a.paused = paused;
                    }
                }
            }
            Event::Telemetry { actor, position, battery, state } => {
                let t = json!({ "position": position, "battery": battery, "state": state, "t": record.t });
                match self.drones.iter_mut().find(|(n, _)| n == actor) {
                    Some((_, v)) => *v = t,
                    None => self.drones.push((actor.to_string(), t)),
                }
            }
            Event::HandlerStart { .. }
            | Event::HandlerEnd { .. }
            | Event::ApiCall { .. }
            | Event::ApiDone { .. }
            | Event::Signal { .. }
            | Event::Exception { .. }
            | Event::Detection { .. } => {}
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
            "activities": self.activities.iter().map(|a| json!({
                "capability": a.capability, "tag": a.tag, "actor": a.actor, "args": a.args, "since": a.since, "paused": a.paused,
            })).collect::<Vec<_>>(),
            "drones": self.drones.iter().map(|(n, v)| { let mut d = v.clone(); d["name"] = json!(n); d }).collect::<Vec<_>>(),
        })
    }
}

/// An activity's arguments as the trace writes them.
fn shown(args: &Params) -> Value {
    serde_json::to_value(args).unwrap_or(Value::Null)
}
