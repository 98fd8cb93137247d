//! Naming a failsafe: the exception an RTL or LAND that the autopilot chose by itself
//! stands for, from what the vehicle reports of itself or its own words.

use aviary_api::{BuiltinException, Failure};

/// How long a failsafe mode change waits for the vehicle to say why.
pub const FAILSAFE_WAIT: std::time::Duration = std::time::Duration::from_millis(2500);

/// The exception a failsafe RTL or LAND stands for: from what the vehicle reports of
/// itself (`state`: its battery, fence or GPS), else from its own words.
pub fn failsafe(name: &str, mode: &str, why: &str, state: Option<BuiltinException>) -> Failure {
    let lower = why.to_ascii_lowercase();
    let exception = if let Some(e) = state {
        e
    } else if lower.contains("battery") {
        BuiltinException::BatteryCritical
    } else if ["gps", "ekf", "position"].iter().any(|w| lower.contains(w)) {
        BuiltinException::PositionLost
    } else if lower.contains("fence") {
        BuiltinException::GeofenceViolation
    } else if ["radio", "gcs", "link", "telemetry", "rc "].iter().any(|w| lower.contains(w)) {
        BuiltinException::ConnectionLost
    } else {
        BuiltinException::CommandFailed
    };
    let said =
        if why.is_empty() { "no reason given".to_owned() } else { format!("it said: {why}") };
    Failure::new(exception, format!("{name}: the autopilot switched to {mode} by itself ({said})"))
}

#[cfg(test)]
mod tests {
    use super::failsafe;
    use aviary_api::BuiltinException;

    #[test]
    fn failsafe_reasons_pick_the_exception() {
        assert_eq!(
            failsafe("a", "RTL", "Battery 1 is critical", None).exception,
            BuiltinException::BatteryCritical
        );
        assert_eq!(
            failsafe("a", "LAND", "EKF variance", None).exception,
            BuiltinException::PositionLost
        );
        assert_eq!(
            failsafe("a", "RTL", "Radio Failsafe", None).exception,
            BuiltinException::ConnectionLost
        );
        assert_eq!(failsafe("a", "RTL", "", None).exception, BuiltinException::CommandFailed);
        // What the vehicle reports of itself comes before its words.
        assert_eq!(
            failsafe("a", "RTL", "Fence breached", Some(BuiltinException::BatteryCritical))
                .exception,
            BuiltinException::BatteryCritical
        );
    }
}
