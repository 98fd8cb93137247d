//! The air a drone flies in (`[air]` of the world file, docs/WORLD.md; the models and
//! their sources in docs/CAMPAIGNS.md): wind with Dryden gusts, the radio's reach, GPS
//! noise, the spread of battery capacities and random faults. Detection's fall with
//! range is the `sensors` module's.
//!
//! A world without `[air]` has no [`AirState`] at all (`Fleet::air` is `None`): every
//! path below is behind that one test, so such a world flies exactly as before `[air]`
//! existed. With it, the state of each drone is in [`AirDrone`], beside the drone, and
//! every number is drawn from the run's seed in a stream of its own (`luck`): a drone's
//! gusts, its GPS error, its capacity, and each kind of its random faults. Nothing is
//! allocated per step.

use aviary_api::{DroneId, FlightState};
use aviary_world::{Falloff, FaultKind, Gps, Radio, World};

use crate::fleet::Report;
use crate::randomness::{Purpose, Stream};

/// Metres in a foot: MIL-F-8785C gives its scales in feet.
const FOOT: f64 = 0.3048;

/// Seconds of simulated time between two moves of the air's slow processes, the gusts and
/// the GPS errors: every fifth step of 0.05 s. Each move is their exact transition over
/// the time since the last one, so their statistics do not change; their time constants
/// (seconds for gusts, a minute for GPS) are far longer, and a receiver's fix comes a few
/// times a second. Moving them every step cost a fifth of a campaign's time (issue 26's
/// speed target): four normal numbers, a `ln`, two `sin_cos` and an `exp` per drone.
pub(crate) const AIR_STEP: f64 = 0.25;

/// The wind, as the fleet flies in it.
#[derive(Clone, Debug)]
pub(crate) struct WindModel {
    /// The mean wind's velocity over the ground, `[east, north]` m/s.
    pub mean: [f64; 2],
    /// The wind at 20 ft of MIL-F-8785C, m/s; `None`: no gusts.
    pub w20: Option<f64>,
    /// `k` of the drain model `P(v) = P0 (1 + k (v / max_speed)^2)`.
    pub drain: f64,
}

/// One kind of random fault on one drone: when it happens next, in seconds of the
/// drone's flight.
#[derive(Clone, Debug)]
pub(crate) struct NextFault {
    pub kind: FaultKind,
    pub rate: f64,
    pub duration: f64,
    /// Flight seconds at which it happens (infinite: never).
    pub at: f64,
    pub luck: Stream,
}

/// What the air keeps for one drone.
#[derive(Clone, Debug)]
pub(crate) struct AirDrone {
    /// The gust, along the mean wind and across it (m/s), and its stream.
    pub gust: [f64; 2],
    pub gust_luck: Option<Box<Stream>>,
    /// Dryden's (intensity, scale) and the height they are for.
    pub dryden: (f64, f64),
    pub dryden_at: f64,
    /// The wind at the drone now (mean plus gust), `[east, north]` m/s.
    pub wind: [f64; 2],
    /// The GPS error, `[east, north]` m, its 1-sigma size and its stream.
    pub gps: [f64; 2],
    pub gps_sigma: f64,
    pub gps_luck: Option<Box<Stream>>,
    /// Its capacity, as a fraction of the nominal one.
    pub capacity: f64,
    pub faults: Vec<NextFault>,
    /// Its link is down because it is out of the radio's reach.
    pub out_of_reach: bool,
    /// When a `link_loss` fault it had when it went out of reach ends (0: none): back in
    /// reach, its link stays lost until then.
    pub fault_until: f64,
    /// It carries a `wind` sensor.
    pub anemometer: bool,
}

/// Everything of `[air]` the fleet keeps.
#[derive(Clone, Debug)]
pub(crate) struct AirState {
    pub wind: Option<WindModel>,
    pub radio: Option<Radio>,
    /// Each drone's reach as a relay, if it is one (`World::relays`).
    pub relays: Vec<Option<f64>>,
    pub gps: Option<Gps>,
    pub falloff: Option<std::sync::Arc<Falloff>>,
    pub capacity_spread: Option<f64>,
    /// The simulated time of the radio's next look.
    pub next_look: f64,
    /// Seconds since the gusts and GPS errors last moved, and, in a step in which they
    /// move, the time they move by (see [`AIR_STEP`]).
    pub since: f64,
    pub span: Option<f64>,
    pub drones: Vec<AirDrone>,
    /// Whether any drone has random faults.
    pub any_faults: bool,
}

impl AirState {
    /// The air of `world`, drawn from `seed`; `None` for a world without `[air]` whose
    /// drones have no `air` table.
    pub fn of(world: &World, seed: u64) -> Option<AirState> {
        let air = &world.air;
        if air.is_still() && world.drones.iter().all(|d| d.air.is_none()) {
            return None;
        }
        let wind = air.wind.as_ref().map(|w| WindModel {
            mean: w.velocity(),
            w20: w.turbulence.filter(|&t| t > 0.0),
            drain: w.drain,
        });
        let gusty = wind.as_ref().is_some_and(|w| w.w20.is_some());
        let drones: Vec<AirDrone> = world
            .drones
            .iter()
            .map(|d| {
                let own = d.air.as_deref();
                let gps_sigma = match &air.gps {
                    Some(g) => own.and_then(|a| a.gps_error).unwrap_or(g.error),
                    None => 0.0,
                };
                let faults = FaultKind::ALL
                    .iter()
                    .filter_map(|&kind| {
                        let own = own.and_then(|a| a.faults.iter().find(|f| f.kind == kind));
                        let f = own.or_else(|| air.faults.iter().find(|f| f.kind == kind))?;
                        (f.rate > 0.0).then(|| NextFault {
                            kind,
                            rate: f.rate,
                            duration: f.duration.unwrap_or(0.0),
                            at: f64::INFINITY,
                            luck: Stream::new(seed, Purpose::RandomFault, 0),
                        })
                    })
                    .collect();
                let dummy = || Box::new(Stream::new(seed, Purpose::Gusts, 0));
                AirDrone {
                    gust: [0.0; 2],
                    gust_luck: gusty.then(dummy),
                    dryden: (0.0, 0.0),
                    dryden_at: 0.0,
                    wind: wind.as_ref().map_or([0.0; 2], |w| w.mean),
                    gps: [0.0; 2],
                    gps_sigma,
                    gps_luck: (gps_sigma > 0.0).then(dummy),
                    capacity: 1.0,
                    faults,
                    out_of_reach: false,
                    fault_until: 0.0,
                    anemometer: d.sensors.iter().any(|s| s == "wind"),
                }
            })
            .collect();
        let any_faults = drones.iter().any(|d| !d.faults.is_empty());
        let mut state = AirState {
            wind,
            radio: air.radio.clone(),
            relays: world.relays(),
            gps: air.gps.clone(),
            falloff: air.detection.clone().map(std::sync::Arc::new),
            capacity_spread: air.capacity_spread.filter(|&s| s > 0.0),
            next_look: 0.0,
            since: 0.0,
            span: None,
            drones,
            any_faults,
        };
        state.reseed(seed);
        Some(state)
    }

    /// Draws every drone's luck afresh from `seed`: its streams, its GPS error at the
    /// start (in its steady state: normal, of its size), its capacity and the first time
    /// of each of its random faults.
    pub fn reseed(&mut self, seed: u64) {
        let spread = self.capacity_spread;
        let mean = self.wind.as_ref().map_or([0.0; 2], |w| w.mean);
        (self.since, self.span) = (0.0, None);
        for (id, a) in self.drones.iter_mut().enumerate() {
            a.gust = [0.0; 2];
            a.wind = mean;
            if a.gust_luck.is_some() {
                a.gust_luck = Some(Box::new(Stream::new(seed, Purpose::Gusts, id)));
            }
            if a.gps_luck.is_some() {
                let mut luck = Stream::new(seed, Purpose::Gps, id);
                let n = luck.normals();
                a.gps = [a.gps_sigma * n[0], a.gps_sigma * n[1]];
                a.gps_luck = Some(Box::new(luck));
            }
            a.capacity = match spread {
                // Within three sigmas: no battery of no capacity.
                Some(s) => {
                    1.0 + s * Stream::new(seed, Purpose::Capacity, id).normal().clamp(-3.0, 3.0)
                }
                None => 1.0,
            };
            for f in &mut a.faults {
                let k = FaultKind::ALL.iter().position(|&k| k == f.kind).unwrap_or(0);
                f.luck = Stream::new(seed, Purpose::RandomFault, id * 8 + k);
                f.at = f.luck.exponential(f.rate) * 3600.0;
            }
        }
    }

    /// One step of `dt` of drone `id`'s gusts, at height `z` (m) and airspeed `v` (m/s):
    /// the wind at the drone afterwards.
    pub fn blow(&mut self, id: DroneId, z: f64, v: f64, dt: f64) -> Option<[f64; 2]> {
        let wind = self.wind.as_ref()?;
        let a = &mut self.drones[id.0];
        if let (Some(w20), Some(luck)) = (wind.w20, a.gust_luck.as_deref_mut()) {
            // The standard's figures change slowly with height: worked out again only
            // when the drone has climbed or descended a metre.
            if (z - a.dryden_at).abs() >= 1.0 || a.dryden.1 == 0.0 {
                a.dryden = dryden(w20, z);
                a.dryden_at = z;
            }
            let (sigma, scale) = a.dryden;
            // Taylor's frozen turbulence: the drone flies through it at its airspeed; a
            // hovering drone has the mean wind blow it past.
            let speed = v.max(hypot(wind.mean)).max(1.0);
            let r = (-speed * dt / scale).exp();
            let kick = sigma * (1.0 - r * r).sqrt();
            let n = luck.normals();
            a.gust = [r * a.gust[0] + kick * n[0], r * a.gust[1] + kick * n[1]];
        }
        // Along the mean wind and across it (to its left), back to east and north.
        let m = hypot(wind.mean);
        let (ux, uy) = if m > 0.0 { (wind.mean[0] / m, wind.mean[1] / m) } else { (1.0, 0.0) };
        a.wind = [
            wind.mean[0] + a.gust[0] * ux - a.gust[1] * uy,
            wind.mean[1] + a.gust[0] * uy + a.gust[1] * ux,
        ];
        Some(a.wind)
    }

    /// One step of `dt` of every drone's GPS error (a first-order Gauss-Markov process per
    /// axis, of correlation time `[air.gps] correlation`).
    pub fn drift_gps(&mut self, dt: f64) {
        let Some(gps) = &self.gps else { return };
        let r = (-dt / gps.correlation).exp();
        let kick = (1.0 - r * r).sqrt();
        for a in &mut self.drones {
            if let Some(luck) = a.gps_luck.as_deref_mut() {
                let s = a.gps_sigma * kick;
                let n = luck.normals();
                a.gps = [r * a.gps[0] + s * n[0], r * a.gps[1] + s * n[1]];
            }
        }
    }

    /// The factor of the drain of a drone flying at `ground` velocity in `wind`:
    /// `P(airspeed) / P(ground speed)`, so that still air drains as the endurance says.
    pub fn drain_factor(&self, id: DroneId, ground: [f64; 2], max_speed: f64) -> f64 {
        let capacity = self.drones[id.0].capacity;
        let Some(wind) = &self.wind else { return 1.0 / capacity };
        aviary_api::flight::wind_drain(ground, self.drones[id.0].wind, max_speed, wind.drain)
            / capacity
    }

    /// Who is in reach of the station, directly or through relays that are: `linked[i]`
    /// for each drone at `at[i]` (`None`: lost, neither reached nor relaying); the rule is
    /// the world's (`Radio::reach`).
    pub fn reach(&self, at: &[Option<[f64; 2]>], linked: &mut Vec<bool>) {
        match &self.radio {
            Some(radio) => radio.reach(&self.relays, at, linked),
            None => {
                linked.clear();
                linked.resize(at.len(), true);
            }
        }
    }
}

/// The Dryden model's horizontal intensity (m/s) and scale length (m) at height `z` (m),
/// for low altitude (below 1000 ft) after MIL-F-8785C (and MIL-HDBK-1797): with h in feet
/// (at least 10), `sigma_w = 0.1 W20`, `sigma_u = sigma_v = sigma_w / (0.177 + 0.000823
/// h)^0.4` and `L_u = L_v = h / (0.177 + 0.000823 h)^1.2`.
pub(crate) fn dryden(w20: f64, z: f64) -> (f64, f64) {
    let h = (z / FOOT).clamp(10.0, 1000.0);
    let base = 0.177 + 0.000823 * h;
    let sigma = 0.1 * w20 / base.powf(0.4);
    let scale = h / base.powf(1.2) * FOOT;
    (sigma, scale)
}

fn hypot(v: [f64; 2]) -> f64 {
    aviary_api::geometry::hypot(v[0], v[1])
}

impl crate::fleet::Fleet {
    /// What the air does at the start of a step that ends at `end`: the GPS errors drift,
    /// and, when it is due, the radio looks at who is in reach.
    pub(crate) fn air_before(&mut self, end: f64, dt: f64, out: &mut Vec<Report>) {
        let Some(air) = self.air.as_deref_mut() else { return };
        air.since += dt;
        air.span = (air.since >= AIR_STEP - 1e-9).then(|| std::mem::take(&mut air.since));
        if let Some(span) = air.span {
            air.drift_gps(span);
        }
        if air.radio.is_some() {
            // A `link_loss` fault that came while a drone is out of reach does not give it
            // its link back when the fault ends: the outage lasts while it is out of reach.
            for (a, d) in air.drones.iter_mut().zip(&mut self.drones) {
                if !a.out_of_reach {
                    continue;
                }
                if let Some(o) = d.rare.as_mut().and_then(|r| r.link_loss.as_mut()) {
                    if o.until.is_finite() {
                        a.fault_until = a.fault_until.max(o.until);
                        o.until = f64::INFINITY;
                    }
                }
            }
        }
        let every = match &air.radio {
            Some(r) if end + 1e-9 >= air.next_look => r.every,
            _ => return,
        };
        air.next_look += every * ((end + 1e-9 - air.next_look) / every).floor().max(0.0) + every;
        let (mut at, mut linked) = std::mem::take(&mut self.radio_scratch);
        at.clear();
        at.extend(self.drones.iter().map(|d| (d.state != FlightState::Lost).then(|| d.xy())));
        air.reach(&at, &mut linked);
        for id in 0..self.drones.len() {
            if at[id].is_none() {
                continue;
            }
            let Some(air) = self.air.as_deref_mut() else { break };
            let out_now = !linked[id];
            let a = &mut air.drones[id];
            if out_now == a.out_of_reach {
                continue;
            }
            a.out_of_reach = out_now;
            let held = std::mem::take(&mut a.fault_until);
            self.touch(DroneId(id));
            let outage = self.drones[id].rare.as_mut().and_then(|r| r.link_loss.as_mut());
            match (out_now, outage) {
                (true, Some(o)) => {
                    // Lost already (a fault): it stays lost while out of reach, and at
                    // least as long as the fault says.
                    let until = std::mem::replace(&mut o.until, f64::INFINITY);
                    if let Some(air) = self.air.as_deref_mut() {
                        air.drones[id].fault_until = until;
                    }
                }
                (true, None) => {
                    let name = &self.names[DroneId(id)];
                    let reason =
                        format!("{name}: out of radio reach of the station and every relay");
                    self.lose_link(DroneId(id), end, f64::INFINITY, reason, out);
                }
                // Back in reach: the outage ends now, or when a fault's does
                // (`ConnectionRestored`, with the faults' outages).
                (false, Some(o)) => o.until = end.max(held),
                (false, None) => {}
            }
        }
        self.radio_scratch = (at, linked);
    }

    /// Drone `id`'s gusts, in a step in which they move (see [`AIR_STEP`]), and the wind
    /// its motion flies in.
    pub(crate) fn air_wind(&mut self, id: DroneId) {
        let Some(air) = self.air.as_deref_mut() else { return };
        let d = &mut self.drones[id.0];
        if air.wind.is_none() || !d.state.airborne() {
            return;
        }
        let v = air.drones[id.0].wind;
        let wind = match air.span {
            Some(span) => {
                let airspeed = aviary_api::geometry::hypot(d.vel[0] - v[0], d.vel[1] - v[1]);
                air.blow(id, d.pos[2], airspeed, span)
            }
            None => Some(v),
        };
        if let Some(task) = d.motion.as_mut() {
            task.wind = wind;
        }
    }

    /// The drain factor of drone `id` this tick (wind and capacity) and its capacity;
    /// `None` without `[air]`.
    pub(crate) fn air_drain(&self, id: DroneId) -> Option<(f64, f64)> {
        let air = self.air.as_deref()?;
        let d = &self.drones[id.0];
        let factor = air.drain_factor(id, [d.vel[0], d.vel[1]], d.spec.max_speed);
        Some((factor, air.drones[id.0].capacity))
    }

    /// The random faults of drone `id` due by its flight time, each fired and the next
    /// of its kind drawn; `now` is the end of the step.
    pub(crate) fn air_faults(&mut self, id: DroneId, now: f64, out: &mut Vec<Report>) {
        let flown = self.drones[id.0].flight_time;
        loop {
            let Some(air) = self.air.as_deref_mut().filter(|a| a.any_faults) else { return };
            let Some(f) = air.drones[id.0].faults.iter_mut().find(|f| f.at <= flown) else {
                return;
            };
            let (kind, duration) = (f.kind, f.duration);
            f.at += f.luck.exponential(f.rate) * 3600.0;
            if self.drones[id.0].state == FlightState::Lost {
                return;
            }
            self.touch(id);
            self.fire(id, kind, now, now + duration, out);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dryden_figures_of_the_standard() {
        // At 1000 ft and above the low-altitude formulas give sigma_u = sigma_w (1.0 to
        // within rounding) and L_u = 1000 ft.
        let (sigma, scale) = dryden(10.0, 1000.0 * FOOT);
        assert!((sigma - 1.0).abs() < 1e-3, "{sigma}");
        assert!((scale - 1000.0 * FOOT).abs() < 1.0, "{scale}");
        // Lower down the gusts are stronger relative to sigma_w, and shorter.
        let (low_sigma, low_scale) = dryden(10.0, 10.0);
        assert!(low_sigma > sigma && low_scale < scale);
    }
}
