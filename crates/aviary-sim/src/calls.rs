//! What each middle-layer function does when called (docs/LANGUAGE.md, section 19).

use aviary_api::{show, CallId, DroneId, Failure, FlightState, Function, Resource, Value};

use crate::args::{failed, kind, number, opt_number, point, point_value, polygon, Limits};
use crate::drone::{Loading, SimDrone};
use crate::fleet::{Fleet, Release};
use crate::geom::dist;
use crate::motion::{orbit_legs, Leg, MotionTask};
use crate::sensors::{detection_range, Activation};
use crate::sweep::lawnmower;

use aviary_api::flight::{LOAD_MAX_ALTITUDE, LOAD_TIME};
/// A landed drone this close to home (metres) is home.
const AT_HOME: f64 = 0.5;

/// How a call that was not refused goes on.
enum Start {
    Done,
    Moves(Vec<Leg>),
    Pending,
}

impl Fleet {
    fn limits(&self) -> Limits<'_> {
        Limits { fence: self.fence.as_deref(), max_altitude: self.max_altitude }
    }

    /// Starts a call; `Ok(true)` when it is in progress, `Ok(false)` when already done.
    pub(crate) fn start(
        &mut self,
        id: DroneId,
        call: CallId,
        function: Function,
        args: &[Value],
    ) -> Result<bool, Failure> {
        let d =
            self.drones.get(id).ok_or_else(|| failed(format!("there is no drone number {id}")))?;
        if d.state == FlightState::Lost {
            return Err(failed(format!("{} is lost", &self.names[id])));
        }
        if d.link_loss().is_some() {
            return Err(failed(format!("no link to {}", &self.names[id])));
        }
        if let Some(why) = d.disabled() {
            return Err(failed(why.clone()));
        }
        let motion = function.resource() == Resource::Motion;
        // A return the drone started on its own (after a link loss) gives way to a command.
        let own_return = d.motion.as_ref().is_some_and(|t| t.call.is_none());
        if motion && d.motion.is_some() && !own_return {
            return Err(failed(format!("{} is busy with another motion call", &self.names[id])));
        }
        if motion && d.gps_loss().is_some() {
            return Err(failed(format!("{} has no position fix", &self.names[id])));
        }
        let start = self.begin(id, call, function, args)?;
        match start {
            Start::Done => Ok(false),
            Start::Pending => Ok(true),
            Start::Moves(legs) => {
                let d = &mut self.drones[id];
                if d.motion.take().is_some() {
                    d.settle();
                }
                d.motion = Some(Box::new(MotionTask::new(Some(call), legs)));
                d.begin_leg();
                Ok(true)
            }
        }
    }

    /// What the call does, once it may start.
    fn begin(
        &mut self,
        id: DroneId,
        call: CallId,
        function: Function,
        args: &[Value],
    ) -> Result<Start, Failure> {
        let limits = self.limits();
        let d = &self.drones[id];
        let here = d.pos;
        // The altitude a move without one keeps (not a detour around another drone).
        let level = d.level();
        let landed = d.state == FlightState::Landed;
        let in_air = || {
            if landed {
                Err(failed(format!("{} is on the ground: take off first", &self.names[id])))
            } else {
                Ok(())
            }
        };
        let fly = |to: [f64; 3], speed: f64| Leg::Move { to, speed, state: FlightState::Flying };
        let legs = match function {
            Function::Arm | Function::Disarm => {
                if !landed {
                    return Err(failed(format!(
                        "{} can only {} on the ground",
                        &self.names[id],
                        function.name().to_lowercase()
                    )));
                }
                self.drones[id].armed = function == Function::Arm;
                return Ok(Start::Done);
            }
            Function::TakeOff => {
                let alt = number(args, 0, "alt")?;
                if alt <= 0.0 {
                    return Err(failed(format!(
                        "take-off altitude must be above 0 m, not {alt} m"
                    )));
                }
                limits.altitude(alt)?;
                let to = [here[0], here[1], alt];
                if !landed {
                    vec![fly(to, d.spec.max_speed)]
                } else if !d.armed {
                    return Err(failed(format!(
                        "{} is not armed: call Arm() before TakeOff",
                        &self.names[id]
                    )));
                } else {
                    vec![Leg::Move { to, speed: d.spec.max_speed, state: FlightState::TakingOff }]
                }
            }
            Function::Land => {
                if landed {
                    return Ok(Start::Done);
                }
                landing_legs(d, [here[0], here[1]])
            }
            Function::ReturnToLaunch => {
                return_legs(d, &self.names[id], landed, limits.max_altitude)?
            }
            Function::FlyToPosition => {
                in_air()?;
                let p = point(args, 0, "pos")?;
                let speed = match opt_number(args, 1, "speed")? {
                    Some(s) if s <= 0.0 => {
                        return Err(failed(format!(
                            "speed must be above 0 m/s, not {} m/s",
                            show::number(s)
                        )))
                    }
                    Some(s) => s.min(d.spec.max_speed),
                    None => d.spec.max_speed,
                };
                let to = [p.x, p.y, p.z.unwrap_or(level)];
                if to[2] < 0.0 {
                    return Err(failed(format!(
                        "altitude {} m is below the ground",
                        show::number(to[2])
                    )));
                }
                limits.path(here, &[to])?;
                vec![fly(to, speed)]
            }
            Function::DescendTo | Function::AscendTo => {
                in_air()?;
                let alt = number(args, 0, "alt")?;
                if alt < 0.0 {
                    return Err(failed(format!(
                        "altitude {} m is below the ground",
                        show::number(alt)
                    )));
                }
                limits.altitude(alt)?;
                vec![fly([here[0], here[1], alt], d.spec.max_speed)]
            }
            Function::Hover => {
                let duration = number(args, 0, "duration")?;
                if duration < 0.0 {
                    return Err(failed(format!(
                        "a hover cannot last {} s",
                        show::number(duration)
                    )));
                }
                vec![Leg::Hold { left: duration }]
            }
            Function::Orbit => {
                in_air()?;
                let c = point(args, 0, "center")?;
                let radius = number(args, 1, "radius")?;
                let laps = opt_number(args, 2, "laps")?.unwrap_or(1.0);
                if radius <= 0.0 || laps <= 0.0 {
                    return Err(failed(format!(
                        "an orbit needs a radius and laps above 0 (got {radius} m, {laps})"
                    )));
                }
                let legs = orbit_legs(d, [c.x, c.y], radius, laps);
                if let Some(Leg::Move { to, .. }) = legs.first() {
                    limits.path(here, &[*to])?;
                }
                limits.circle([c.x, c.y], radius)?;
                legs
            }
            Function::Sweep => {
                in_air()?;
                let area = polygon(args, 0, "area")?;
                let spacing = number(args, 1, "spacing")?;
                if spacing <= 0.0 {
                    return Err(failed(format!(
                        "sweep spacing must be above 0 m, not {spacing} m"
                    )));
                }
                let path: Vec<[f64; 3]> =
                    lawnmower(&area, spacing).into_iter().map(|p| [p[0], p[1], level]).collect();
                limits.path(here, &path)?;
                path.into_iter().map(|to| fly(to, d.spec.max_speed)).collect()
            }
            Function::FollowPath => {
                in_air()?;
                let mut z = level;
                let mut path = Vec::new();
                for (i, v) in args.iter().enumerate() {
                    let p = point_value(v, &format!("points[{i}]"))?;
                    z = p.z.unwrap_or(z);
                    if z < 0.0 {
                        return Err(failed(format!(
                            "altitude {} m is below the ground",
                            show::number(z)
                        )));
                    }
                    path.push([p.x, p.y, z]);
                }
                limits.path(here, &path)?;
                path.into_iter().map(|to| fly(to, d.spec.max_speed)).collect()
            }
            Function::StartStreaming | Function::StopStreaming => {
                return self.stream(id, function == Function::StartStreaming)
            }
            Function::StartDetection | Function::StopDetection => {
                return self.detect(id, function == Function::StartDetection, args)
            }
            Function::LoadPayload => return self.load(id, call, args),
            Function::ReleasePayload => return self.release(id),
        };
        Ok(if legs.is_empty() { Start::Done } else { Start::Moves(legs) })
    }

    fn stream(&mut self, id: DroneId, on: bool) -> Result<Start, Failure> {
        let d = &mut self.drones[id];
        if !d.spec.sensors.iter().any(|s| s == "camera") {
            return Err(failed(format!("{} has no camera", &self.names[id])));
        }
        d.streaming = on;
        Ok(Start::Done)
    }

    fn detect(&mut self, id: DroneId, start: bool, args: &[Value]) -> Result<Start, Failure> {
        let d = &mut self.drones[id];
        let kind = kind(args, 0, "kind")?;
        let Some((range, probability)) = detection_range(&self.sensors, &d.spec.sensors, &kind)
        else {
            return Err(failed(format!("{} has no sensor that detects {kind}", &self.names[id])));
        };
        let detections = &mut d.rare_mut().detections;
        detections.retain(|a| a.kind != kind);
        if start {
            detections.push(Activation { kind, range, probability, found: Vec::new() });
        }
        Ok(Start::Done)
    }

    fn load(&mut self, id: DroneId, call: CallId, args: &[Value]) -> Result<Start, Failure> {
        let d = &mut self.drones[id];
        let kind = kind(args, 0, "kind")?;
        if !d.spec.payload_kinds.contains(&kind) {
            let can = if d.spec.payload_kinds.is_empty() {
                "nothing".to_owned()
            } else {
                d.spec.payload_kinds.join(", ")
            };
            return Err(failed(format!(
                "{} cannot carry {kind} (it can carry: {can})",
                &self.names[id]
            )));
        }
        if let Some(held) = d.carrying().or(d.loading().map(|l| &l.kind)) {
            return Err(failed(format!(
                "{} already carries {held}: release it first",
                &self.names[id]
            )));
        }
        if d.state != FlightState::Landed && d.pos[2] >= LOAD_MAX_ALTITUDE {
            return Err(failed(format!(
                "{} is at {} m: load while landed or below {LOAD_MAX_ALTITUDE} m",
                &self.names[id],
                show::fixed(d.pos[2], 1)
            )));
        }
        d.rare_mut().loading = Some(Loading { call, kind, left: LOAD_TIME, paused: false });
        Ok(Start::Pending)
    }

    fn release(&mut self, id: DroneId) -> Result<Start, Failure> {
        let time = self.time;
        let d = &mut self.drones[id];
        let Some(kind) = d.rare.as_mut().and_then(|r| r.carrying.take()) else {
            return Err(failed(format!("{} carries nothing to release", &self.names[id])));
        };
        self.releases.push(Release { drone: id, kind, position: d.pos, time });
        Ok(Start::Done)
    }
}

/// `ReturnToLaunch`: up to the return altitude, home, and down.
pub(crate) fn return_legs(
    d: &SimDrone,
    name: &str,
    landed: bool,
    max_altitude: Option<f64>,
) -> Result<Vec<Leg>, Failure> {
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
        legs.push(Leg::Move {
            to: [d.home[0], d.home[1], safe],
            speed: d.spec.max_speed,
            state: FlightState::Flying,
        });
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
