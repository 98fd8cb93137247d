//! Battery: drains only in the air, `dt / endurance` of a full battery per `dt` seconds.
//!
//! The energy needed to get home is the time to fly there at `return_speed`, wait above home
//! and land (`aviary_api::flight::time_home`), as a fraction of the endurance. `BatteryLow` is raised (once)
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
    time_home(dist(d.xy(), d.home), d) / d.spec.endurance
}

/// At least [`energy_home`] (or NaN), bit for bit: `|dx| + |dy|`, widened far beyond the
/// rounding of both, bounds the distance, and rounding keeps the order of the rest.
pub(crate) fn energy_home_bound(d: &SimDrone) -> f64 {
    if !(d.spec.return_speed > 0.0
        && d.spec.descent.rate > 0.0
        && d.spec.descent.land_speed > 0.0
        && d.spec.endurance > 0.0)
    {
        return f64::NAN;
    }
    let far = ((d.home[0] - d.pos[0]).abs() + (d.home[1] - d.pos[1]).abs()) * (1.0 + 1e-12);
    time_home(far, d) / d.spec.endurance
}

fn time_home(ground: f64, d: &SimDrone) -> f64 {
    aviary_api::flight::time_home(
        ground,
        d.spec.return_speed,
        d.pos[2],
        d.spec.return_loiter,
        &d.spec.descent,
    )
}

/// Drains `dt` seconds of flight (when `airborne`) and raises each alarm at most once.
/// `air` (with `[air]`): the drain's factor this tick, for the wind and the battery's
/// capacity (`crate::air::AirState::drain_factor`), and that capacity, as a fraction of
/// the nominal one: the energy home is a larger part of a smaller battery.
// `!(a >= b)` on purpose: a NaN charge or bound counts as "may be due", never as safe.
#[allow(clippy::neg_cmp_op_on_partial_ord)]
pub(crate) fn drain(d: &mut SimDrone, dt: f64, airborne: bool, air: Option<(f64, f64)>) -> Alarms {
    let mut alarms = Alarms { low: false, critical: false, empty: false };
    if !airborne {
        return alarms;
    }
    // Without `[air]` a capacity of exactly 1: dividing by it changes no bit.
    let capacity = match air {
        None => {
            d.battery -= dt / d.spec.endurance;
            1.0
        }
        Some((k, capacity)) => {
            d.battery -= dt * k / d.spec.endurance;
            capacity
        }
    };
    if d.battery <= 0.0 {
        d.battery = 0.0;
        alarms.empty = true;
    }
    // Most ticks the bound shows that neither alarm can be due: no square root.
    let bound = energy_home_bound(d) / capacity;
    let may = |k: f64| !(d.battery >= k * bound + 0.10);
    let maybe_due = (!d.low_sent && may(2.0)) || (!d.critical_sent && may(1.0));
    if !maybe_due {
        return alarms;
    }
    let need = energy_home(d) / capacity;
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn the_bound_is_never_below_the_energy(
            x in -1e5f64..1e5, y in -1e5f64..1e5, z in -10f64..200.0,
            hx in -1e5f64..1e5, hy in -1e5f64..1e5, axis in 0u8..3,
            speed in 0.5f64..30.0, climb in 0.5f64..10.0, endurance in 10f64..5000.0,
        ) {
            let world = crate::tests::one_drone();
            let mut spec = crate::drone::Spec::of(&world.drones[0]);
            (spec.return_speed, spec.climb_rate, spec.endurance) = (speed, climb, endurance);
            let mut d = SimDrone::new(&world.drones[0], std::sync::Arc::new(spec));
            d.home = [hx, hy];
            // On an axis of home, too, where the distance is one side alone.
            d.pos = match axis { 0 => [hx, y, z], 1 => [x, hy, z], _ => [x, y, z] };
            let (exact, bound) = (energy_home(&d), energy_home_bound(&d));
            prop_assert!(bound >= exact, "{bound} < {exact}");
            for k in [1.0, 2.0] {
                prop_assert!(k * bound + 0.10 >= k * exact + 0.10);
            }
        }
    }
}
