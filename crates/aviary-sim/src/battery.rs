//! Battery: drains only in the air, `dt / endurance` of a full battery per `dt` seconds.
//!
//! The energy needed to get home is the time to fly there at `max_speed` plus the time to
//! descend at `climb_rate`, as a fraction of the endurance. `BatteryLow` is raised (once)
//! when what is left falls under twice that plus 10 %; `BatteryCritical` (once) under
//! that plus 10 %; at zero the drone falls and is lost.

use crate::drone::SimDrone;
use crate::geom::dist;

/// What the battery says after a tick.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Alarms {
    pub low: bool,
    pub critical: bool,
    pub empty: bool,
}

/// The fraction of a full battery the drone needs to fly home and land from where it is.
pub(crate) fn energy_home(d: &SimDrone) -> f64 {
    let time = dist(d.xy(), d.home) / d.spec.max_speed + d.pos[2].max(0.0) / d.spec.climb_rate;
    time / d.spec.endurance
}

/// Drains `dt` seconds of flight (when `airborne`) and raises each alarm at most once.
pub(crate) fn drain(d: &mut SimDrone, dt: f64, airborne: bool) -> Alarms {
    let mut alarms = Alarms {
        low: false,
        critical: false,
        empty: false,
    };
    if !airborne {
        return alarms;
    }
    d.battery -= dt / d.spec.endurance;
    if d.battery <= 0.0 {
        d.battery = 0.0;
        alarms.empty = true;
    }
    let need = energy_home(d);
    if !d.low_sent && d.battery < 2.0 * need + 0.10 {
        d.low_sent = true;
        alarms.low = true;
    }
    if !d.critical_sent && d.battery < need + 0.10 {
        d.critical_sent = true;
        alarms.critical = true;
    }
    alarms
}
