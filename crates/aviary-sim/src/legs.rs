//! The legs a motion call flies, and the refusals it can meet before it starts: each
//! function's arguments read, and its path held to the site's limits.

use aviary_api::{show, Failure, FlightState, Place, Region, Waypoint};

use crate::args::{failed, finite, opt_finite, point, polygon, Limits};
use crate::drone::SimDrone;
use crate::geom::dist;
use crate::motion::{orbit_legs, Leg};
use aviary_api::{coverage, sweep};

/// A landed drone this close to home (metres) is home.
const AT_HOME: f64 = 0.5;

/// The drone a motion call is for, as its legs are planned: its name for the refusals,
/// and the limits its path must keep.
pub(crate) struct Mover<'a> {
    pub d: &'a SimDrone,
    pub name: &'a str,
    pub limits: Limits<'a>,
}

/// A straight leg flown in the air.
fn fly(to: [f64; 3], speed: f64) -> Leg {
    Leg::Move { to, speed, state: FlightState::Flying }
}

impl Mover<'_> {
    fn landed(&self) -> bool {
        self.d.state == FlightState::Landed
    }

    /// Refuses a call that needs the drone in the air.
    fn in_air(&self) -> Result<(), Failure> {
        if self.landed() {
            Err(failed(format!("{} is on the ground: take off first", self.name)))
        } else {
            Ok(())
        }
    }

    /// `TakeOff`: straight up from the ground, or to the altitude when in the air already.
    pub fn take_off(&self, alt: f64) -> Result<Vec<Leg>, Failure> {
        let d = self.d;
        let here = d.pos;
        let alt = finite(alt, "alt")?;
        if alt <= 0.0 {
            return Err(failed(format!("take-off altitude must be above 0 m, not {alt} m")));
        }
        self.limits.altitude(alt)?;
        self.limits.vertical(here, alt)?;
        let to = [here[0], here[1], alt];
        if !self.landed() {
            Ok(vec![fly(to, d.spec.max_speed)])
        } else if !d.armed {
            Err(failed(format!("{} is not armed: call Arm() before TakeOff", self.name)))
        } else {
            Ok(vec![Leg::Move { to, speed: d.spec.max_speed, state: FlightState::TakingOff }])
        }
    }

    /// `Land`: straight down; nothing on the ground. Refused over a no-fly zone (every
    /// zone holds at the ground).
    pub fn land(&self) -> Result<Vec<Leg>, Failure> {
        if self.landed() {
            return Ok(Vec::new());
        }
        let here = self.d.pos;
        self.limits.vertical(here, 0.0)?;
        Ok(landing_legs(self.d, [here[0], here[1]]))
    }

    /// The legs of a transit from where the drone is to `to`, at up to `speed`: around the
    /// no-fly zones ([`Limits::route`]), each point at `to`'s height; one straight leg
    /// when nothing is in the way.
    fn transit(&self, from: [f64; 3], to: [f64; 3], speed: f64) -> Result<Vec<Leg>, Failure> {
        let way = self.limits.route(from, to)?;
        Ok(way.into_iter().map(|p| fly([p[0], p[1], to[2]], speed)).collect())
    }

    /// The points of a list of legs, for the limits' checks.
    fn points(legs: &[Leg]) -> Vec<[f64; 3]> {
        legs.iter()
            .filter_map(|leg| match leg {
                Leg::Move { to, .. } => Some(*to),
                _ => None,
            })
            .collect()
    }

    /// `ReturnToLaunch`.
    pub fn return_home(&self) -> Result<Vec<Leg>, Failure> {
        return_legs(self.d, self.name, self.landed(), &self.limits)
    }

    /// `FlyToPosition`: a transit, at the altitude kept when the position has none.
    pub fn fly_to(&self, pos: &Place, speed: Option<f64>) -> Result<Vec<Leg>, Failure> {
        let d = self.d;
        self.in_air()?;
        let p = point(pos, "pos")?;
        let speed = match opt_finite(speed, "speed")? {
            Some(s) if s <= 0.0 => {
                return Err(failed(format!(
                    "speed must be above 0 m/s, not {} m/s",
                    show::number(s)
                )))
            }
            Some(s) => s.min(d.spec.max_speed),
            None => d.spec.max_speed,
        };
        let to = [p.x, p.y, p.z.unwrap_or(d.level())];
        if to[2] < 0.0 {
            return Err(failed(format!("altitude {} m is below the ground", show::number(to[2]))));
        }
        let legs = self.transit(d.pos, to, speed)?;
        self.limits.path(d.pos, &Self::points(&legs))?;
        Ok(legs)
    }

    /// `DescendTo` and `AscendTo`: straight up or down.
    pub fn to_altitude(&self, alt: f64) -> Result<Vec<Leg>, Failure> {
        let d = self.d;
        self.in_air()?;
        let alt = finite(alt, "alt")?;
        if alt < 0.0 {
            return Err(failed(format!("altitude {} m is below the ground", show::number(alt))));
        }
        self.limits.altitude(alt)?;
        self.limits.vertical(d.pos, alt)?;
        Ok(vec![fly([d.pos[0], d.pos[1], alt], d.spec.max_speed)])
    }

    /// `Orbit`: to the circle (a transit), then round it (its own path, which must keep
    /// out of the zones).
    pub fn orbit(
        &self,
        center: &Place,
        radius: f64,
        laps: Option<f64>,
    ) -> Result<Vec<Leg>, Failure> {
        self.in_air()?;
        let c = point(center, "center")?;
        let radius = finite(radius, "radius")?;
        let laps = opt_finite(laps, "laps")?.unwrap_or(1.0);
        if radius <= 0.0 || laps <= 0.0 {
            return Err(failed(format!(
                "an orbit needs a radius and laps above 0 (got {radius} m, {laps})"
            )));
        }
        // The circle first: a circle through a zone is said as such, not as a way there.
        self.limits.orbit_clear([c.x, c.y], radius, self.d.level())?;
        let mut legs = orbit_legs(self.d, [c.x, c.y], radius, laps);
        if let Some(Leg::Move { to, speed, .. }) = legs.first().cloned() {
            let way = self.transit(self.d.pos, to, speed)?;
            self.limits.path(self.d.pos, &Self::points(&way))?;
            legs.splice(0..1, way);
        }
        self.limits.circle([c.x, c.y], radius)?;
        Ok(legs)
    }

    /// `Sweep`: to the area's lawnmower path, or to the lanes a remainder left (a transit
    /// around the no-fly zones), then along it (the contract's path, `aviary_api::coverage`,
    /// which must keep out of the zones), at the altitude kept. With the legs, the path's
    /// points, which [`crate::motion::PathTrack`] follows for where a cut sweep stopped.
    pub fn sweep(&self, area: &Region, spacing: f64) -> Result<(Vec<Leg>, Vec<[f64; 3]>), Failure> {
        let d = self.d;
        self.in_air()?;
        let (area, lanes) = match area {
            Region::Left(_) => {
                let spacing = finite(spacing, "spacing")?;
                (Vec::new(), coverage::sweep_lanes(area, spacing).map_err(failed)?)
            }
            Region::Area(corners) => {
                let area = polygon(corners, "area")?;
                let spacing = finite(spacing, "spacing")?;
                if spacing <= 0.0 {
                    return Err(failed(format!(
                        "sweep spacing must be above 0 m, not {spacing} m"
                    )));
                }
                let lanes = sweep::lanes(&area, spacing);
                (area, lanes)
            }
        };
        let level = d.level();
        let flat = sweep::path(&lanes);
        // A remainder has no area: its lanes alone must keep out of the zones.
        self.limits.sweep_clear(&area, &flat, level)?;
        let path: Vec<[f64; 3]> = flat.into_iter().map(|p| [p[0], p[1], level]).collect();
        let mut legs = Vec::new();
        if let Some((&first, rest)) = path.split_first() {
            legs = self.transit(d.pos, first, d.spec.max_speed)?;
            legs.extend(rest.iter().map(|&to| fly(to, d.spec.max_speed)));
        }
        self.limits.path(d.pos, &Self::points(&legs))?;
        Ok((legs, path))
    }

    /// `FollowPath`: through the points (a remainder's in its place), each a transit from
    /// the one before (around the zones); one without an altitude keeps the one before.
    /// At the speed asked for (its last argument), at most the drone's, as `FlyToPosition`.
    /// With the legs, the points, as for `Sweep`.
    pub fn follow_path(
        &self,
        points: &[Waypoint],
        speed: Option<f64>,
    ) -> Result<(Vec<Leg>, Vec<[f64; 3]>), Failure> {
        let d = self.d;
        self.in_air()?;
        let speed = coverage::follow_speed(speed).map_err(failed)?;
        let speed = speed.map_or(d.spec.max_speed, |s| s.min(d.spec.max_speed));
        let mut z = d.level();
        let mut path = Vec::new();
        for p in coverage::follow_points(points).map_err(failed)? {
            z = p.z.unwrap_or(z);
            if z < 0.0 {
                return Err(failed(format!("altitude {} m is below the ground", show::number(z))));
            }
            path.push([p.x, p.y, z]);
        }
        let mut legs = Vec::new();
        let mut from = d.pos;
        for &to in &path {
            legs.extend(self.transit(from, to, speed)?);
            from = to;
        }
        self.limits.path(d.pos, &Self::points(&legs))?;
        Ok((legs, path))
    }
}

/// `Hover`: a hold where the drone is, in the air or on the ground.
pub(crate) fn hover_legs(duration: f64) -> Result<Vec<Leg>, Failure> {
    let duration = finite(duration, "duration")?;
    if duration < 0.0 {
        return Err(failed(format!("a hover cannot last {} s", show::number(duration))));
    }
    Ok(vec![Leg::Hold { left: duration }])
}

/// `ReturnToLaunch`: up to the return altitude, home (around the no-fly zones), and down.
pub(crate) fn return_legs(
    d: &SimDrone,
    name: &str,
    landed: bool,
    limits: &Limits,
) -> Result<Vec<Leg>, Failure> {
    let max_altitude = limits.max_altitude;
    let home_dist = dist(d.xy(), d.home);
    if landed {
        if home_dist <= AT_HOME {
            return Ok(Vec::new());
        }
        return Err(failed(format!("{name} is on the ground away from home: take off first")));
    }
    let z = d.pos[2];
    let safe = aviary_api::flight::return_height(z, d.spec.return_altitude, max_altitude);
    let mut legs = Vec::new();
    if safe > z {
        legs.push(Leg::Move {
            to: [d.pos[0], d.pos[1], safe],
            speed: d.spec.max_speed,
            state: FlightState::Flying,
        });
    }
    if home_dist > 0.0 {
        let way = limits.route([d.pos[0], d.pos[1], safe], [d.home[0], d.home[1], safe])?;
        legs.extend(way.into_iter().map(|p| Leg::Move {
            to: [p[0], p[1], safe],
            speed: d.spec.return_speed,
            state: FlightState::Flying,
        }));
    }
    if d.spec.return_loiter > 0.0 {
        legs.push(Leg::Hold { left: d.spec.return_loiter });
    }
    legs.extend(landing_legs_from(d, d.home, safe));
    Ok(legs)
}

/// A landing straight down from where the drone is.
fn landing_legs(d: &SimDrone, here: [f64; 2]) -> Vec<Leg> {
    landing_legs_from(d, here, d.pos[2])
}

/// Down to the ground at `at` from `height`: at the descent rate, and, when the drone
/// lands slower than it descends, first to `slow_below` and from there at the landing
/// speed (the motion's rule for a landing leg low enough), as an autopilot lands.
fn landing_legs_from(d: &SimDrone, at: [f64; 2], height: f64) -> Vec<Leg> {
    let down = |z: f64| Leg::Move {
        to: [at[0], at[1], z],
        speed: d.spec.max_speed,
        state: FlightState::Landing,
    };
    let descent = d.spec.descent;
    if descent.slows(height) && height > descent.slow_below {
        vec![down(descent.slow_below), down(0.0)]
    } else {
        vec![down(0.0)]
    }
}
