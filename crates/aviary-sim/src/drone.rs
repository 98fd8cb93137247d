//! One simulated drone: what the world file says of it, and its state.

use std::hash::{Hash, Hasher};
use std::sync::Arc;

use aviary_api::geometry::hypot;
use aviary_api::{CallId, FlightState, Telemetry};
use aviary_world::Drone;

use crate::avoid::Yield;
use crate::motion::{Leg, MotionTask};
use crate::sensors::Activation;

/// `LoadPayload` in progress.
#[derive(Clone, Debug)]
pub(crate) struct Loading {
    pub call: CallId,
    pub kind: String,
    /// Seconds to go.
    pub left: f64,
    pub paused: bool,
}

/// A fault with a duration (link or GPS loss) in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Outage {
    /// Simulated time at which it began.
    pub since: f64,
    /// Simulated time at which it ends.
    pub until: f64,
    /// Whether the drone has already decided on its own return to launch (link loss).
    pub returned: bool,
}

/// What the world file says of a drone's make: shared by the drones that agree on it
/// (a large fleet is mostly of one make), so that each carries a pointer, not 64 bytes
/// and two lists.
#[derive(Debug, PartialEq)]
pub(crate) struct Spec {
    pub max_speed: f64,
    /// Its fastest through the air: what a wind leaves of it over the ground.
    pub max_airspeed: f64,
    pub climb_rate: f64,
    pub accel: f64,
    pub endurance: f64,
    pub descent: aviary_api::flight::Descent,
    pub return_altitude: f64,
    pub return_loiter: f64,
    pub takeoff_speed: f64,
    pub return_speed: f64,
    /// `Drone::fastest`: what separation and avoidance plan with.
    pub fastest: f64,
    pub sensors: Box<[String]>,
    pub payload_kinds: Box<[String]>,
}

impl Spec {
    pub fn of(d: &Drone) -> Spec {
        Spec {
            max_speed: d.max_speed,
            max_airspeed: d.max_airspeed,
            climb_rate: d.climb_rate,
            accel: d.acceleration,
            endurance: d.endurance,
            descent: d.descent(),
            return_altitude: d.return_altitude,
            return_loiter: d.return_loiter,
            takeoff_speed: d.takeoff_speed,
            return_speed: d.return_speed,
            fastest: d.fastest(),
            sensors: d.sensors.clone(),
            payload_kinds: d.payload.clone(),
        }
    }
}

// The world's numbers are finite (it refuses others), so bitwise equality is equality.
impl Eq for Spec {}

impl Hash for Spec {
    fn hash<H: Hasher>(&self, h: &mut H) {
        let figures = [
            self.max_speed,
            self.max_airspeed,
            self.climb_rate,
            self.accel,
            self.endurance,
            self.return_altitude,
            self.return_loiter,
            self.takeoff_speed,
            self.return_speed,
        ];
        let descent = [self.descent.rate, self.descent.land_speed, self.descent.slow_below];
        for x in figures.into_iter().chain(descent) {
            x.to_bits().hash(h);
        }
        self.sensors.hash(h);
        self.payload_kinds.hash(h);
    }
}

/// The states a drone is seldom in: boxed together, so that a drone in none of them
/// (most of a large fleet, most of the time) carries 8 bytes for them all.
#[derive(Clone, Debug, Default)]
pub(crate) struct Rare {
    pub loading: Option<Loading>,
    pub carrying: Option<String>,
    pub detections: Vec<Activation>,
    pub link_loss: Option<Outage>,
    pub gps_loss: Option<Outage>,
    /// Why the drone takes no more commands (a motor failure).
    pub disabled: Option<String>,
    /// The drone's stream for its sensors' chances, made at its first draw.
    pub luck: Option<Box<crate::randomness::Stream>>,
    /// Paused motion calls set aside for a newer motion call, the last one on top
    /// ([`SimDrone::set_aside`]).
    pub aside: Vec<Aside>,
    /// Where its last `Sweep` or `FollowPath` stopped, when it ended early
    /// (`Backend::stopped`); forgotten when its next motion call starts.
    pub stopped: Option<aviary_api::Progress>,
}

/// A paused motion call set aside while another motion call flies the drone (a leash
/// section runs while the activity's body is held): where the drone was when it was set
/// aside, to fly back there before it goes on.
#[derive(Clone, Debug)]
pub(crate) struct Aside {
    pub task: Box<MotionTask>,
    pub at: [f64; 3],
}

/// Every drone's state; its name is the fleet's ([`aviary_api::Names`]).
#[derive(Clone, Debug)]
pub(crate) struct SimDrone {
    pub home: [f64; 2],
    pub spec: Arc<Spec>,

    pub pos: [f64; 3],
    /// Instantaneous velocity, m/s.
    pub vel: [f64; 3],
    /// The horizontal velocity of the last step in which the drone moved over the
    /// ground: its heading, worked out only when read ([`SimDrone::heading`]; an `atan2`
    /// per drone and step was a fiftieth of a campaign). North until it first moves.
    pub facing: [f64; 2],
    /// Fraction of a full battery.
    pub battery: f64,
    pub state: FlightState,
    pub armed: bool,
    /// Boxed: 120 bytes that a drone of a large fleet at rest would carry for nothing.
    pub motion: Option<Box<MotionTask>>,
    /// How the drone yields to another one, if it does (see [`crate::avoid`]).
    pub avoid: Option<Yield>,
    /// Seconds the safety filter has held the drone back without a break.
    pub stalled: f64,
    /// Whether the drone, after such a standstill, gives way to every drone until its
    /// yield is over.
    pub humble: bool,
    pub streaming: bool,
    pub low_sent: bool,
    pub critical_sent: bool,
    pub rare: Option<Box<Rare>>,
    /// Metres flown (along the way, climbs included).
    pub odometer: f64,
    /// Seconds in the air.
    pub flight_time: f64,
}

impl SimDrone {
    pub fn new(d: &Drone, spec: Arc<Spec>) -> SimDrone {
        SimDrone {
            home: [d.home[0], d.home[1]],
            spec,
            pos: [d.home[0], d.home[1], 0.0],
            vel: [0.0; 3],
            facing: [0.0, 1.0],
            battery: d.battery / 100.0,
            state: FlightState::Landed,
            armed: false,
            motion: None,
            avoid: None,
            stalled: 0.0,
            humble: false,
            streaming: false,
            low_sent: false,
            critical_sent: false,
            rare: None,
            odometer: 0.0,
            flight_time: 0.0,
        }
    }

    /// The rare states, made on first use.
    pub fn rare_mut(&mut self) -> &mut Rare {
        self.rare.get_or_insert_with(Box::default)
    }

    pub fn loading(&self) -> Option<&Loading> {
        self.rare.as_ref()?.loading.as_ref()
    }
    pub fn carrying(&self) -> Option<&String> {
        self.rare.as_ref()?.carrying.as_ref()
    }
    pub fn detections(&self) -> &[Activation] {
        self.rare.as_ref().map_or(&[], |r| &r.detections)
    }
    pub fn link_loss(&self) -> Option<&Outage> {
        self.rare.as_ref()?.link_loss.as_ref()
    }
    pub fn gps_loss(&self) -> Option<&Outage> {
        self.rare.as_ref()?.gps_loss.as_ref()
    }
    pub fn disabled(&self) -> Option<&String> {
        self.rare.as_ref()?.disabled.as_ref()
    }

    /// Degrees clockwise from north of where it last flew.
    pub fn heading(&self) -> f64 {
        crate::geom::heading(self.facing[0], self.facing[1])
    }

    pub fn xy(&self) -> [f64; 2] {
        [self.pos[0], self.pos[1]]
    }

    /// The altitude the drone flies at: where it is, or, while it is displaced up or down
    /// to let another drone pass, where it came from.
    pub fn level(&self) -> f64 {
        match self.avoid {
            Some(Yield { alt: Some(_), back_to, .. }) => back_to,
            _ => self.pos[2],
        }
    }

    pub fn telemetry(&self) -> Telemetry {
        Telemetry {
            position: self.pos,
            speed: hypot(self.vel[0], self.vel[1]),
            heading: self.heading(),
            battery: self.battery,
            state: self.state,
            link: self.link_loss().is_none(),
            gps_position: self.pos,
            wind: None,
        }
    }

    /// Starts bringing into the cache what a tick reads behind this drone's pointers (its
    /// motion task, its detections): in a large fleet these are cache misses in turn,
    /// which a loop can overlap by warming a few drones ahead. A hint: nothing is read.
    pub fn warm(&self) {
        if let Some(task) = &self.motion {
            // A task spans two cache lines.
            let at = &**task as *const MotionTask;
            prefetch(at);
            prefetch(at.cast::<u8>().wrapping_add(64));
        }
        if !self.detections().is_empty() {
            prefetch(self.detections().as_ptr());
        }
    }

    /// Starts bringing in the current leg (best once [`SimDrone::warm`] brought the task).
    pub fn warm_leg(&self) {
        if let Some(leg) = self.motion.as_ref().and_then(|t| t.legs.front()) {
            prefetch(leg as *const Leg);
        }
    }

    /// Stops every move at once: the drone holds where it is.
    pub fn hold(&mut self) {
        self.vel = [0.0; 3];
        if let Some(task) = &mut self.motion {
            task.rest();
        }
    }

    /// After a move was cut short: hover if in the air, stay landed on the ground.
    pub fn settle(&mut self) {
        self.vel = [0.0; 3];
        if matches!(self.state, FlightState::TakingOff | FlightState::Landing) {
            self.state = if self.pos[2] > 0.01 { FlightState::Flying } else { FlightState::Landed };
        }
    }

    /// Notes where the motion task in progress stops, when it is a path call about to end
    /// early: the point of its path it is flying to, and where the drone is.
    pub fn note_stop(&mut self) {
        let Some(next) = self.motion.as_ref().and_then(|t| Some(t.path.as_ref()?.next())) else {
            return;
        };
        let at = self.pos;
        self.rare_mut().stopped = Some(aviary_api::Progress { next, at });
    }

    /// Ends every call in progress (motion and loading), for a fault; returns their ids in
    /// a fixed order (motion first, then those set aside, the latest first).
    pub fn cut_calls(&mut self) -> Vec<CallId> {
        let mut ended = Vec::new();
        self.note_stop();
        if let Some(task) = self.motion.take() {
            ended.extend(task.call);
        }
        if let Some(rare) = self.rare.as_mut() {
            ended.extend(rare.aside.drain(..).rev().filter_map(|a| a.task.call));
        }
        if let Some(load) = self.rare.as_mut().and_then(|r| r.loading.take()) {
            ended.push(load.call);
        }
        self.settle();
        ended
    }

    /// Whether the motion in progress is a call the engine paused: a newer motion call
    /// may then set it aside instead of being refused.
    pub fn paused_call(&self) -> bool {
        self.motion.as_ref().is_some_and(|t| t.paused && t.call.is_some())
    }

    /// Sets the paused motion call aside, where the drone is, for a newer one. An arc
    /// begun is cut where the drone stands, so that it goes on from there, not from its
    /// start, when the call is brought back.
    pub fn set_aside(&mut self) {
        let Some(mut task) = self.motion.take() else { return };
        if let Some(Leg::Arc { start, total, .. }) = task.legs.front_mut() {
            *start -= task.arc_done;
            *total -= task.arc_done;
        }
        task.arc_done = 0.0;
        task.rest();
        let at = self.pos;
        self.rare_mut().aside.push(Aside { task, at });
    }

    /// Once no motion is in progress, brings back the last call set aside: it first flies
    /// back to where it was set aside (at the drone's top speed), then goes on, paused
    /// until the engine resumes it.
    pub fn bring_back(&mut self) {
        if self.motion.is_some() {
            return;
        }
        let Some(Aside { mut task, at }) = self.rare.as_mut().and_then(|r| r.aside.pop()) else {
            return;
        };
        let off = [self.pos[0] - at[0], self.pos[1] - at[1], self.pos[2] - at[2]];
        if hypot(hypot(off[0], off[1]), off[2]) > 1e-6 {
            let back = Leg::Move { to: at, speed: self.spec.max_speed, state: FlightState::Flying };
            task.legs.push_front(back);
        }
        self.motion = Some(task);
        self.begin_leg();
    }
}

/// Asks the CPU to start loading the cache line at `p`; never faults, reads nothing.
#[inline]
#[allow(unsafe_code)] // the intrinsic is `unsafe`; a prefetch touches no memory
fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch is a hint; it does not access memory (any address is allowed).
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
