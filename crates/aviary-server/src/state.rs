//! What the operator sees: the mission's state, folded from its trace events.

use aviary_api::operator::{self, MissionStatus, OperatorState, Telemetry, Withdrawn};
use aviary_api::trace::{Event, OperatorAction, Record};
use aviary_api::BuiltinLeash;

#[derive(Default)]
pub struct MissionState {
    mission: Option<String>,
    t: f64,
    /// `running`, then the outcome (`ok`, `failed`, `aborted`); empty before the start.
    status: MissionStatus,
    reason: Option<String>,
    /// The operator paused the whole mission (`operator` events).
    paused: bool,
    blocks: Vec<String>,
    /// Running activities, in the order they started.
    activities: Vec<operator::Activity>,
    /// Each drone's last telemetry, by name, in the order first seen.
    drones: Vec<(String, Telemetry)>,
    /// What the operator did to single drones, by name, in the order first steered.
    steered: Vec<(String, Steered)>,
}

/// A drone the operator steered: held, or taken out of the mission (`home`, `land`).
#[derive(Clone, Copy, Default)]
struct Steered {
    held: bool,
    withdrawn: Option<Withdrawn>,
}

impl MissionState {
    pub fn observe(&mut self, record: &Record) {
        // A time that is not finite is `null` in the trace: the last one stands.
        if record.t.is_finite() {
            self.t = record.t;
        }
        match &record.event {
            Event::MissionStart { mission, .. } => {
                self.mission = Some(mission.to_string());
                self.status = MissionStatus::Running;
            }
            Event::MissionEnd { status, reason } => {
                self.status = (*status).into();
                self.reason = reason.as_deref().map(str::to_string);
            }
            Event::BlockStart { block } => self.blocks.push(block.to_string()),
            Event::BlockEnd { block, .. } => {
                if let Some(i) = self.blocks.iter().rposition(|b| b == block) {
                    self.blocks.remove(i);
                }
            }
            Event::CapabilityStart { actor, capability, tag, args, .. } => {
                self.activities.push(operator::Activity {
                    capability: capability.to_string(),
                    tag: tag.as_deref().map(str::to_string),
                    actor: actor.to_string(),
                    args: args.clone().into_owned(),
                    since: record.t,
                    paused: false,
                })
            }
            Event::CapabilityEnd { actor, capability, tag, .. } => {
                let same = |a: &operator::Activity| {
                    a.capability == *capability
                        && a.actor == *actor
                        && a.tag.as_deref() == tag.as_deref()
                };
                if let Some(i) = self.activities.iter().position(same) {
                    self.activities.remove(i);
                }
            }
            Event::Leash { capability, tag, action, .. } => {
                let paused = match BuiltinLeash::parse(action.as_ref()) {
                    Some(BuiltinLeash::Pause) => Some(true),
                    Some(BuiltinLeash::Resume) => Some(false),
                    Some(BuiltinLeash::Abort) | None => None,
                };
                if let Some(paused) = paused {
                    let tagged = |a: &&mut operator::Activity| {
                        a.capability == *capability && a.tag.as_deref() == Some(tag.as_ref())
                    };
                    for a in self.activities.iter_mut().filter(tagged) {
                        a.paused = paused;
                    }
                }
            }
            Event::Telemetry { actor, position, battery, state } => {
                let t = Telemetry {
                    position: *position,
                    battery: *battery,
                    state: *state,
                    t: record.t,
                };
                match self.drones.iter_mut().find(|(n, _)| n == actor) {
                    Some((_, v)) => *v = t,
                    None => self.drones.push((actor.to_string(), t)),
                }
            }
            Event::Operator { action, drone: None } => match action {
                OperatorAction::Pause => self.paused = true,
                OperatorAction::Resume => self.paused = false,
                _ => {}
            },
            Event::Operator { action, drone: Some(drone) } => {
                let i = match self.steered.iter().position(|(n, _)| n == drone) {
                    Some(i) => i,
                    None => {
                        self.steered.push((drone.to_string(), Steered::default()));
                        self.steered.len() - 1
                    }
                };
                let steered = &mut self.steered[i].1;
                match action {
                    OperatorAction::Hold => steered.held = true,
                    OperatorAction::Resume => steered.held = false,
                    OperatorAction::ReturnHome => {
                        *steered = Steered { held: false, withdrawn: Some(Withdrawn::Home) }
                    }
                    OperatorAction::Land => {
                        *steered = Steered { held: false, withdrawn: Some(Withdrawn::Land) }
                    }
                    OperatorAction::Pause | OperatorAction::Abort => {}
                }
            }
            Event::HandlerStart { .. }
            | Event::Autopilot { .. }
            | Event::HandlerEnd { .. }
            | Event::ApiCall { .. }
            | Event::ApiDone { .. }
            | Event::Signal { .. }
            | Event::Exception { .. }
            | Event::Detection { .. } => {}
        }
    }

    /// The state as `GET /api/state` returns it, the operator's signals left empty
    /// (the trace does not say them: they are the mission's).
    pub fn document(&self) -> OperatorState {
        OperatorState {
            mission: self.mission.clone(),
            t: self.t,
            status: self.status,
            reason: self.reason.clone(),
            paused: self.paused,
            blocks: self.blocks.clone(),
            activities: self.activities.clone(),
            drones: self.drones(),
            operator_signals: Vec::new(),
            operator_signal_values: Default::default(),
        }
    }

    /// Each drone: its last telemetry and whether the operator holds it or took it out
    /// of the mission; a drone steered before its first telemetry is listed with the
    /// latter only.
    fn drones(&self) -> Vec<operator::Drone> {
        let steered = |name: &str| {
            self.steered.iter().find(|(n, _)| n == name).map(|(_, s)| *s).unwrap_or_default()
        };
        let mut out = Vec::with_capacity(self.drones.len());
        for (name, telemetry) in &self.drones {
            let s = steered(name);
            out.push(operator::Drone {
                telemetry: Some(telemetry.clone()),
                name: name.clone(),
                held: s.held,
                withdrawn: s.withdrawn,
            });
        }
        for (name, s) in &self.steered {
            if !self.drones.iter().any(|(n, _)| n == name) {
                out.push(operator::Drone {
                    telemetry: None,
                    name: name.clone(),
                    held: s.held,
                    withdrawn: s.withdrawn,
                });
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::{json, Value};

    fn observe(state: &mut MissionState, t: f64, line: &str) {
        let mut record: Record = serde_json::from_str(line).expect("a trace line");
        record.t = t;
        state.observe(&record);
    }

    #[test]
    fn the_operators_steering_shows_per_drone_and_for_the_mission() {
        let mut state = MissionState::default();
        observe(&mut state, 0.0, r#"{"t":0,"event":"mission_start","mission":"M"}"#);
        let telemetry = |d: &str| {
            format!(
                r#"{{"t":0,"event":"telemetry","actor":"{d}","position":[0.0,0.0,5.0],"battery":0.9,"state":"Flying"}}"#
            )
        };
        observe(&mut state, 1.0, &telemetry("a"));
        observe(&mut state, 1.0, &telemetry("b"));
        observe(&mut state, 2.0, r#"{"t":0,"event":"operator","action":"hold","drone":"a"}"#);
        observe(&mut state, 2.0, r#"{"t":0,"event":"operator","action":"pause","drone":null}"#);
        observe(&mut state, 3.0, r#"{"t":0,"event":"operator","action":"land","drone":"c"}"#);
        let json = serde_json::to_value(state.document()).unwrap();
        assert_eq!(json["paused"], true);
        let drone = |name: &str| {
            json["drones"].as_array().unwrap().iter().find(|d| d["name"] == name).unwrap().clone()
        };
        assert_eq!(
            (drone("a")["held"].clone(), drone("a")["withdrawn"].clone()),
            (json!(true), Value::Null)
        );
        assert_eq!(
            (drone("b")["held"].clone(), drone("b")["state"].clone()),
            (json!(false), json!("Flying"))
        );
        assert_eq!(drone("c"), json!({ "name": "c", "held": false, "withdrawn": "land" }));

        observe(&mut state, 4.0, r#"{"t":0,"event":"operator","action":"resume","drone":null}"#);
        observe(
            &mut state,
            4.0,
            r#"{"t":0,"event":"operator","action":"return_home","drone":"a"}"#,
        );
        let json = serde_json::to_value(state.document()).unwrap();
        assert_eq!(json["paused"], false, "the mission's resume");
        let a = json["drones"].as_array().unwrap().iter().find(|d| d["name"] == "a").unwrap();
        assert_eq!((a["held"].clone(), a["withdrawn"].clone()), (json!(false), json!("home")));
    }
}
