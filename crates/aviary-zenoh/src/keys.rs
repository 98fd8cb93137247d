//! The key expressions a run uses, all under one prefix (`aviary/MISSION` unless
//! `--zenoh-prefix` says otherwise). docs/DISTRIBUTED.md lists them for subscribers.

use zenoh::key_expr::KeyExpr;

/// The keys of one run.
#[derive(Clone, Debug, PartialEq)]
pub struct Keys {
    prefix: String,
}

/// The operator API's calls, each a queryable `PREFIX/api/CALL`: `state`, `mission`
/// (what a station shows of the mission: its name, block tree and map) and `history` (the
/// events so far) are read, the others are the control calls of `POST /api/CALL`.
pub const CALLS: [&str; 9] =
    ["state", "mission", "history", "leash", "signal", "drone", "pause", "resume", "abort"];

/// The calls that only read.
pub const READS: [&str; 3] = ["state", "mission", "history"];

impl Keys {
    /// The keys under `prefix`, refused with the reason when it is not a key expression
    /// of its own (no wildcard, no empty chunk, no `?`, `#`, `$`).
    pub fn new(prefix: &str) -> Result<Keys, String> {
        let prefix = prefix.trim_end_matches('/');
        let refused = |why: &str| {
            format!(
                "`{prefix}` cannot be a Zenoh key prefix: {why} (write it as aviary/my_mission)"
            )
        };
        if prefix.contains(['*', '$', '?', '#']) {
            return Err(refused("it may not hold `*`, `$`, `?` or `#`"));
        }
        KeyExpr::try_from(prefix).map_err(|e| refused(&e.to_string()))?;
        Ok(Keys { prefix: prefix.to_string() })
    }

    /// The default prefix of a mission: `aviary/NAME`, with what a key may not hold in a
    /// name replaced by `_`.
    pub fn of_mission(name: &str) -> Keys {
        let chunk: String = name
            .chars()
            .map(|c| if c.is_alphanumeric() || c == '_' || c == '-' { c } else { '_' })
            .collect();
        let chunk = if chunk.is_empty() { "mission".to_string() } else { chunk };
        Keys { prefix: format!("aviary/{chunk}") }
    }

    pub fn prefix(&self) -> &str {
        &self.prefix
    }

    /// Every trace event but telemetry, each the trace file's line (JSON).
    pub fn events(&self) -> String {
        format!("{}/events", self.prefix)
    }

    /// A drone's telemetry samples, each the trace file's `telemetry` line (JSON).
    pub fn telemetry(&self, drone: &str) -> String {
        format!("{}/telemetry/{drone}", self.prefix)
    }

    /// Whether `key` carries the run's lines: its events or a drone's telemetry.
    pub fn carries_lines(&self, key: &str) -> bool {
        key == self.events() || key.starts_with(&self.telemetry(""))
    }

    /// The operator state (`GET /api/state`'s document), once a second while it changes
    /// and once more at the end.
    pub fn state(&self) -> String {
        format!("{}/state", self.prefix)
    }

    /// The queryables of the operator API: `PREFIX/api/*`.
    pub fn api(&self) -> String {
        self.call("*")
    }

    /// The key of one call of the operator API: `PREFIX/api/CALL`.
    pub fn call(&self, call: &str) -> String {
        format!("{}/api/{call}", self.prefix)
    }

    /// The call a query's key names (`PREFIX/api/pause` → `pause`), if it is one.
    pub fn call_of<'a>(&self, key: &'a str) -> Option<&'a str> {
        let call = key.strip_prefix(&self.prefix)?.strip_prefix("/api/")?;
        CALLS.contains(&call).then_some(call)
    }
}

/// The keys of one agent (`aviary agent`), under `aviary-agent/NAME`: apart from every
/// mission's prefix, so that an agent is found by its name alone.
#[derive(Clone, Debug, PartialEq)]
pub struct AgentKeys {
    prefix: String,
}

impl AgentKeys {
    /// The keys of agent `name`, refused with the reason when the name is not one
    /// (`aviary_world::agent_name`'s rule: one chunk of letters, digits, `-`, `_`, `.`).
    pub fn new(name: &str) -> Result<AgentKeys, String> {
        aviary_world::agent_name(name)?;
        Ok(AgentKeys { prefix: format!("aviary-agent/{name}") })
    }

    /// The liveliness token the agent holds while it runs.
    pub fn alive(&self) -> &str {
        &self.prefix
    }

    /// The frames the vehicle sends, one MAVLink frame a sample, published by the agent.
    pub fn from_vehicle(&self) -> String {
        format!("{}/vehicle", self.prefix)
    }

    /// The frames for the vehicle, one MAVLink frame a sample, published by the mission.
    pub fn to_vehicle(&self) -> String {
        format!("{}/gcs", self.prefix)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_agent_s_keys_are_apart_from_every_mission_s() {
        let keys = AgentKeys::new("field-laptop.1").unwrap();
        assert_eq!(keys.alive(), "aviary-agent/field-laptop.1");
        assert_eq!(keys.from_vehicle(), "aviary-agent/field-laptop.1/vehicle");
        assert_eq!(keys.to_vehicle(), "aviary-agent/field-laptop.1/gcs");
        for bad in ["", "a/b", "a*", "$x", "a b", "a?"] {
            assert!(AgentKeys::new(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_prefix_is_a_key_of_its_own_and_names_each_call() {
        let keys = Keys::new("field/team_a/").unwrap();
        assert_eq!(keys.events(), "field/team_a/events");
        assert_eq!(keys.telemetry("scout1"), "field/team_a/telemetry/scout1");
        assert!(keys.carries_lines("field/team_a/events"));
        assert!(keys.carries_lines("field/team_a/telemetry/scout1"));
        assert!(!keys.carries_lines("field/team_a/state"));
        assert!(!keys.carries_lines("field/team_a/api/pause"));
        assert_eq!(keys.call("pause"), "field/team_a/api/pause");
        assert_eq!(keys.call_of("field/team_a/api/pause"), Some("pause"));
        assert_eq!(keys.call_of("field/team_a/api/launch"), None);
        assert_eq!(keys.call_of("field/team_b/api/pause"), None);
        for bad in ["a/*", "a/**/b", "a//b", "a?x", "$x", ""] {
            assert!(Keys::new(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_mission_name_becomes_one_chunk() {
        assert_eq!(Keys::of_mission("SearchAndRescue").prefix(), "aviary/SearchAndRescue");
        assert_eq!(Keys::of_mission("a/b*c").prefix(), "aviary/a_b_c");
        assert_eq!(Keys::of_mission("").prefix(), "aviary/mission");
    }
}
