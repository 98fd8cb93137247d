//! What each middle-layer function does when called (docs/LANGUAGE.md, section 19).

use aviary_api::{show, CallId, DroneId, Failure, FlightState, Function, FunctionCall, Resource};

use crate::args::{failed, Limits};
use crate::drone::Loading;
use crate::fleet::{Fleet, Release};
use crate::legs::{hover_legs, Mover};
use crate::motion::{Leg, MotionTask, PathTrack};
use crate::sensors::{detection_range, Activation};

use aviary_api::flight::{LOAD_MAX_ALTITUDE, LOAD_TIME};

/// How a call that was not refused goes on.
enum Start {
    Done,
    /// The legs to fly, and for a `Sweep` or `FollowPath` the points of its path.
    Moves(Vec<Leg>, Option<Vec<[f64; 3]>>),
    Pending,
}

impl Fleet {
    fn limits(&self) -> Limits<'_> {
        Limits {
            fence: self.fence.as_deref(),
            max_altitude: self.max_altitude,
            airspace: &self.airspace,
        }
    }

    /// Starts a call; `Ok(true)` when it is in progress, `Ok(false)` when already done.
    pub(crate) fn start(
        &mut self,
        id: DroneId,
        call: CallId,
        function: &FunctionCall,
    ) -> Result<bool, Failure> {
        let motion = function.function().resource() == Resource::Motion;
        if motion {
            // A motion call forgets where the last path call stopped (`Backend::stopped`),
            // before anything can refuse it: a refused call has not moved.
            if let Some(rare) = self.drones.get_mut(id.0).and_then(|d| d.rare.as_deref_mut()) {
                rare.stopped = None;
            }
        }
        let d = self
            .drones
            .get(id.0)
            .ok_or_else(|| failed(format!("there is no drone number {id}")))?;
        if d.state == FlightState::Lost {
            return Err(failed(format!("{} is lost", &self.names[id])));
        }
        if d.link_loss().is_some() {
            return Err(failed(format!("no link to {}", &self.names[id])));
        }
        if let Some(why) = d.disabled() {
            return Err(failed(why.clone()));
        }
        // A return the drone started on its own (after a link loss) gives way to a command.
        let own_return = d.motion.as_ref().is_some_and(|t| t.call.is_none());
        // A motion call the engine paused (its activity's body, held while a leash section
        // flies the drone) gives way to a newer one: it is set aside, and comes back when
        // that one ends (`SimDrone::bring_back`).
        let aside = motion && d.paused_call();
        if motion && d.motion.is_some() && !own_return && !aside {
            return Err(failed(format!("{} is busy with another motion call", &self.names[id])));
        }
        if motion && d.gps_loss().is_some() {
            return Err(failed(format!("{} has no position fix", &self.names[id])));
        }
        let d = &mut self.drones[id.0];
        if aside {
            d.set_aside();
        }
        let start = self.begin(id, call, function);
        if aside && !matches!(start, Ok(Start::Moves(..))) {
            // Refused, or nothing to fly: the paused call is back at once, as it was.
            self.drones[id.0].bring_back();
        }
        match start? {
            Start::Done => Ok(false),
            Start::Pending => Ok(true),
            Start::Moves(legs, path) => {
                let d = &mut self.drones[id.0];
                if d.motion.take().is_some() {
                    d.settle();
                }
                let mut task = MotionTask::new(Some(call), legs);
                task.path = path.map(PathTrack::new);
                d.motion = Some(Box::new(task));
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
        function: &FunctionCall,
    ) -> Result<Start, Failure> {
        let m = Mover { d: &self.drones[id.0], name: &self.names[id], limits: self.limits() };
        let mut path = None;
        let legs = match function {
            FunctionCall::Arm => return self.arm(id, Function::Arm),
            FunctionCall::Disarm => return self.arm(id, Function::Disarm),
            FunctionCall::TakeOff { alt } => m.take_off(*alt)?,
            FunctionCall::Land => m.land()?,
            FunctionCall::ReturnToLaunch => m.return_home()?,
            FunctionCall::FlyToPosition { pos, speed } => m.fly_to(pos, *speed)?,
            FunctionCall::DescendTo { alt } | FunctionCall::AscendTo { alt } => {
                m.to_altitude(*alt)?
            }
            FunctionCall::Hover { duration } => hover_legs(*duration)?,
            FunctionCall::Orbit { center, radius, laps } => m.orbit(center, *radius, *laps)?,
            FunctionCall::Sweep { area, spacing } => {
                let (legs, points) = m.sweep(area, *spacing)?;
                path = Some(points);
                legs
            }
            FunctionCall::FollowPath { points, speed } => {
                let (legs, points) = m.follow_path(points, *speed)?;
                path = Some(points);
                legs
            }
            FunctionCall::StartStreaming => return self.stream(id, true),
            FunctionCall::StopStreaming => return self.stream(id, false),
            FunctionCall::StartDetection { kind } => return self.detect(id, true, kind),
            FunctionCall::StopDetection { kind } => return self.detect(id, false, kind),
            FunctionCall::LoadPayload { kind } => return self.load(id, call, kind),
            FunctionCall::ReleasePayload => return self.release(id),
        };
        Ok(if legs.is_empty() { Start::Done } else { Start::Moves(legs, path) })
    }

    /// `Arm` and `Disarm`, on the ground only.
    fn arm(&mut self, id: DroneId, function: Function) -> Result<Start, Failure> {
        if self.drones[id.0].state != FlightState::Landed {
            return Err(failed(format!(
                "{} can only {} on the ground",
                &self.names[id],
                function.name().to_lowercase()
            )));
        }
        self.drones[id.0].armed = function == Function::Arm;
        Ok(Start::Done)
    }

    fn stream(&mut self, id: DroneId, on: bool) -> Result<Start, Failure> {
        let d = &mut self.drones[id.0];
        if !d.spec.sensors.iter().any(|s| s == "camera") {
            return Err(failed(format!("{} has no camera", &self.names[id])));
        }
        d.streaming = on;
        Ok(Start::Done)
    }

    fn detect(&mut self, id: DroneId, start: bool, kind: &str) -> Result<Start, Failure> {
        let d = &mut self.drones[id.0];
        let kind = kind.to_owned();
        let Some((range, probability)) = detection_range(&self.sensors, &d.spec.sensors, &kind)
        else {
            return Err(failed(format!("{} has no sensor that detects {kind}", &self.names[id])));
        };
        let detections = &mut d.rare_mut().detections;
        detections.retain(|a| a.kind != kind);
        if start {
            let falloff = self.air.as_ref().and_then(|a| a.falloff.clone());
            let d = &mut self.drones[id.0];
            let detections = &mut d.rare_mut().detections;
            detections.push(Activation {
                kind,
                range,
                probability,
                found: Vec::new(),
                falloff,
                pending: Vec::new(),
            });
        }
        Ok(Start::Done)
    }

    fn load(&mut self, id: DroneId, call: CallId, kind: &str) -> Result<Start, Failure> {
        let d = &mut self.drones[id.0];
        let kind = kind.to_owned();
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
        let d = &mut self.drones[id.0];
        let Some(kind) = d.rare.as_mut().and_then(|r| r.carrying.take()) else {
            return Err(failed(format!("{} carries nothing to release", &self.names[id])));
        };
        self.releases.push(Release { drone: id, kind, position: d.pos, time });
        Ok(Start::Done)
    }
}
