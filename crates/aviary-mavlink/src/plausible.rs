//! Telemetry no vehicle could have sent is not believed: a position farther from the last
//! one than any multirotor flies in the time between them, a charge outside 0–100 %.
//! A vehicle whose positions keep jumping has lost its position, whatever else it says
//! (a GPS or EKF fault, a corrupt link): that is `PositionLost`, raised once it has lasted
//! [`DOUBT_FOR`], not a `BatteryCritical` or a flight of 700,000 km.

use std::time::Duration;

/// m/s: well above the fastest multirotors (racing quads reach about 50 m/s).
pub const MAX_SPEED: f64 = 100.0;
/// m: what a GPS may wander between two reports without the vehicle moving.
pub const JITTER: f64 = 10.0;
/// How long positions may keep jumping before the drone's position counts as lost.
pub const DOUBT_FOR: Duration = Duration::from_secs(2);

/// Whether a vehicle could have gone from `before` to `after` (local metres) in `dt`
/// seconds.
pub fn reachable(before: [f64; 3], after: [f64; 3], dt: f64) -> bool {
    let d = (0..3).map(|k| (after[k] - before[k]).powi(2)).sum::<f64>().sqrt();
    d.is_finite() && d <= MAX_SPEED * dt.max(0.0) + JITTER
}

/// Seconds between two positions: by the vehicle's own clock (`time_boot_ms`) when it
/// went forward, since a simulated vehicle may run faster than real time (SITL's
/// `--speedup`, `aviary vehicles --speed`); by the wall clock when the vehicle sends no
/// clock (0) or it went back (a reboot).
pub fn elapsed(boot_ms_before: u32, boot_ms_after: u32, wall: f64) -> f64 {
    if boot_ms_before > 0 && boot_ms_after > boot_ms_before {
        f64::from(boot_ms_after - boot_ms_before) / 1000.0
    } else {
        wall
    }
}

/// A reported `battery_remaining` as a fraction: `None` for -1 (MAVLink's "unknown") and
/// for anything outside 0–100, which no battery has.
pub fn charge(remaining: i8) -> Option<f64> {
    (0..=100).contains(&remaining).then(|| f64::from(remaining) / 100.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drone_flies_what_it_can_and_no_farther() {
        assert!(reachable([0.0; 3], [15.0, 0.0, 0.0], 0.1), "GPS jitter");
        assert!(reachable([0.0; 3], [100.0, 0.0, 10.0], 1.0));
        assert!(!reachable([0.0; 3], [300_000.0, 0.0, 0.0], 0.1), "hundreds of km");
        assert!(!reachable([0.0; 3], [0.0, 0.0, 50_000.0], 1.0), "50 km up");
        assert!(!reachable([0.0; 3], [f64::NAN, 0.0, 0.0], 1.0));
    }

    #[test]
    fn time_is_the_vehicles_own_when_it_keeps_one() {
        assert_eq!(elapsed(1_000, 3_000, 0.1), 2.0, "a vehicle 20 times faster than real time");
        assert_eq!(elapsed(0, 0, 0.1), 0.1, "no clock sent");
        assert_eq!(elapsed(9_000, 200, 0.1), 0.1, "rebooted");
        assert_eq!(elapsed(5_000, 5_000, 0.1), 0.1, "the same instant twice");
    }

    #[test]
    fn a_charge_is_a_percentage() {
        assert_eq!(charge(55), Some(0.55));
        assert_eq!(charge(100), Some(1.0));
        assert_eq!(charge(-1), None);
        assert_eq!(charge(127), None);
        assert_eq!(charge(101), None);
    }

    /// A vehicle fed messages by hand, as its link would.
    mod vehicle {
        use aviary_api::DroneEvent;
        use mavlink::dialects::ardupilotmega::{
            MavMessage, GLOBAL_POSITION_INT_DATA, SYS_STATUS_DATA,
        };
        use tokio::sync::mpsc;

        use crate::vehicle::Vehicle;

        /// Runs `f` on a runtime of the run's clock, which only `advance` moves here.
        fn simulated(f: impl std::future::Future<Output = ()>) {
            aviary_clock::Runtime::new().unwrap().block_on(f);
        }
        use aviary_api::geo::Origin;

        const ORIGIN: Origin = Origin { lat: 46.6167, lon: 14.265, alt: 440.0 };

        fn at(x: f64, y: f64, z: f64) -> MavMessage {
            let (lat, lon) = ORIGIN.to_e7(x, y);
            MavMessage::GLOBAL_POSITION_INT(GLOBAL_POSITION_INT_DATA {
                lat,
                lon,
                relative_alt: (z * 1000.0) as i32,
                alt: ((440.0 + z) * 1000.0) as i32,
                ..Default::default()
            })
        }

        fn charge(remaining: i8) -> MavMessage {
            MavMessage::SYS_STATUS(SYS_STATUS_DATA {
                battery_remaining: remaining,
                ..Default::default()
            })
        }

        /// The x of the vehicle's fix, to a decimetre (1e-7° is about a centimetre).
        fn x(v: &Vehicle) -> Option<f64> {
            v.seen().fix.map(|f| (f.pos[0] * 10.0).round() / 10.0)
        }

        fn vehicle(
        ) -> (Vehicle, mpsc::UnboundedReceiver<(aviary_api::DroneId, aviary_api::Failure)>)
        {
            let (events, _) = mpsc::unbounded_channel::<DroneEvent>();
            let (alarms, rx) = mpsc::unbounded_channel();
            (
                Vehicle::new(
                    aviary_api::DroneId(0),
                    "d".into(),
                    1,
                    ORIGIN,
                    Vec::new(),
                    events,
                    alarms,
                ),
                rx,
            )
        }

        #[test]
        fn positions_that_jump_are_not_taken_and_become_position_lost() {
            simulated(async {
                let (v, mut alarms) = vehicle();
                v.observe(&at(0.0, 0.0, 10.0));
                aviary_clock::advance(std::time::Duration::from_millis(100)).await;
                v.observe(&at(5.0, 0.0, 10.0));
                // 300 km away a tenth of a second later, and again for 3 s.
                for _ in 0..30 {
                    aviary_clock::advance(std::time::Duration::from_millis(100)).await;
                    v.observe(&at(300_000.0, 0.0, 10.0));
                    assert_eq!(x(&v), Some(5.0), "the last believable position stands");
                }
                let (drone, failure) = alarms.try_recv().expect("PositionLost");
                assert_eq!(
                    (drone.0, failure.exception),
                    (0, aviary_api::BuiltinException::PositionLost)
                );
                assert!(failure.reason.contains("300 km"), "{}", failure.reason);
                assert!(alarms.try_recv().is_err(), "raised once");
                // Believable again: taken, and the odometer never saw the jump.
                aviary_clock::advance(std::time::Duration::from_millis(100)).await;
                v.observe(&at(8.0, 0.0, 10.0));
                assert_eq!(x(&v), Some(8.0));
                assert!(v.seen().odometer < 10.0);
            })
        }

        #[test]
        fn a_vehicle_faster_than_real_time_is_believed_by_its_own_clock() {
            simulated(async {
                let (v, mut alarms) = vehicle();
                // 300 m per wall-clock tenth of a second, 15 m/s by the vehicle's clock.
                for k in 0..40u32 {
                    let mut m = at(f64::from(k) * 300.0, 0.0, 10.0);
                    if let MavMessage::GLOBAL_POSITION_INT(p) = &mut m {
                        p.time_boot_ms = 1_000 + k * 20_000;
                    }
                    v.observe(&m);
                    aviary_clock::advance(std::time::Duration::from_millis(100)).await;
                }
                assert_eq!(x(&v), Some(39.0 * 300.0));
                assert!(alarms.try_recv().is_err(), "no PositionLost");
            })
        }

        #[test]
        fn a_short_glitch_is_dropped_without_an_exception() {
            simulated(async {
                let (v, mut alarms) = vehicle();
                v.observe(&at(0.0, 0.0, 10.0));
                aviary_clock::advance(std::time::Duration::from_millis(100)).await;
                v.observe(&at(9_000.0, 0.0, 10.0));
                aviary_clock::advance(std::time::Duration::from_millis(100)).await;
                v.observe(&at(1.0, 0.0, 10.0));
                assert_eq!(x(&v), Some(1.0));
                assert!(alarms.try_recv().is_err());
            })
        }

        #[test]
        fn a_charge_over_100_percent_is_not_believed() {
            let (v, _alarms) = vehicle();
            v.observe(&charge(80));
            v.observe(&charge(127));
            assert_eq!(v.seen().battery, Some(0.8));
            v.observe(&charge(-1));
            assert_eq!(v.seen().battery, Some(0.8), "unknown keeps the last");
        }
    }
}
