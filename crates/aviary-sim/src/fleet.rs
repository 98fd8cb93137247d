//! The physics core: every drone of the world, advanced tick by tick. Pure: no clock, no
//! channels, and no randomness but what the seed gives ([`crate::randomness`]); the same seed,
//! calls and steps give the same results bit for bit.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::sync::Arc;

use aviary_api::{CallEnd, CallId, DroneEvent, DroneId, FunctionCall, Interrupt, Telemetry};
use aviary_world::{FaultKind, Sensor, Target, World};

use crate::air::AirState;
use crate::avoid::Track;
use crate::clearance::Clearance;
use crate::drone::{SimDrone, Spec};
use crate::grid::Grid;
use crate::nearby::Nearby;
use crate::randomness::{Purpose, Stream};
use crate::step_view::Hot;
use aviary_api::Names;
use aviary_route::Airspace;

/// Something that happened during a [`Fleet::step`], in the order it happened.
#[derive(Clone, Debug, PartialEq)]
pub enum Report {
    /// A call in progress ended.
    Ended { call: CallId, end: CallEnd },
    /// A drone event for the engine.
    Event(DroneEvent),
}

/// One `ReleasePayload`: which drone let go of what, where and when (simulated seconds).
#[derive(Clone, Debug, PartialEq)]
pub struct Release {
    pub drone: DroneId,
    pub kind: String,
    pub position: [f64; 3],
    pub time: f64,
}

/// A `[[faults]]` entry of the world file, by drone index.
#[derive(Clone, Debug)]
pub(crate) struct ScheduledFault {
    pub drone: DroneId,
    pub kind: FaultKind,
    pub at: f64,
    /// `at = [earliest, latest]`: `at` is drawn from it.
    pub window: Option<[f64; 2]>,
    pub duration: f64,
    pub fired: bool,
}

/// The simulated fleet. Drones are indexed as in the world file.
#[derive(Clone, Debug)]
pub struct Fleet {
    pub(crate) drones: Vec<SimDrone>,
    pub(crate) names: Names,
    pub(crate) fence: Option<Vec<[f64; 2]>>,
    pub(crate) max_altitude: Option<f64>,
    /// The geofence and the no-fly zones, for the routes of transits (shared: the
    /// planner's graphs are made once, whoever asks first).
    pub(crate) airspace: Arc<Airspace>,
    /// `[site] min_separation`: metres kept between drones in the air (0: none).
    pub(crate) min_separation: f64,
    /// `[site] link_loss_rtl_after`: seconds without link before a drone returns on its own.
    pub(crate) link_loss_rtl_after: f64,
    /// `[site] separation_timeout`: seconds a call may be held back by separation.
    pub(crate) separation_timeout: f64,
    pub(crate) sensors: Vec<Sensor>,
    pub(crate) targets: Vec<Target>,
    pub(crate) faults: Vec<ScheduledFault>,
    /// The run's seed: every chance the world asks for is drawn from it.
    pub(crate) seed: u64,
    pub(crate) time: f64,
    pub(crate) next_call: u64,
    pub(crate) releases: Vec<Release>,
    /// The drones in an airborne state at the start of this step (the only ones that
    /// can take part in separation during it), in order.
    pub(crate) aloft: Vec<usize>,
    /// The planner's predicted tracks of drones that moved already in this step.
    pub(crate) tracks: BTreeMap<DroneId, Track>,
    /// Whether each drone is in `aloft`.
    pub(crate) in_sky: Vec<bool>,
    /// The drones of `aloft`, by where they are now (updated as each one moves), when
    /// `sky_fresh`: built in a step only once a drone needs it (see [`Fleet::fresh_sky`]).
    pub(crate) sky: Grid,
    pub(crate) sky_fresh: bool,
    /// How far apart the drones of `aloft` are, at least: answers most "anybody near?"
    /// without the sky.
    pub(crate) clearance: Clearance,
    /// At least the largest `extent` of the envelope of a drone of `aloft` during this
    /// step (from `extent_bound`): how far, beyond the usual, separation must look for one.
    pub(crate) max_extent: f64,
    /// Each drone as its last turn in a step left it (see [`crate::step_view`]).
    pub(crate) hot: Vec<Hot>,
    /// The drones with a link or GPS outage, ascending.
    pub(crate) outages: Vec<DroneId>,
    /// The largest `max_speed + climb_rate` of the fleet (the planner's reach).
    pub(crate) fastest: f64,
    /// The world's targets by where they are.
    pub(crate) target_grid: Grid,
    /// The targets near each drone's way, kept between ticks.
    /// Made for a drone when it first detects: most drones of a large fleet never do.
    pub(crate) near_targets: Vec<Option<Box<Nearby>>>,
    /// The drone of each call in progress (a call id is only ever that drone's), so that
    /// [`Fleet::interrupt`] looks at one drone, not the fleet. Entries go when the call's
    /// end is reported; one left over (a task replaced without an end) only costs a lookup.
    pub(crate) calls: HashMap<CallId, DroneId>,
    /// `[air]`: wind, radio, GPS noise, detection's falloff, capacities and random
    /// faults; `None` in a world without it, which then flies as in still air.
    pub(crate) air: Option<Box<AirState>>,
    /// Scratch for the radio's looks: where each drone is, and who is linked.
    pub(crate) radio_scratch: (Vec<Option<[f64; 2]>>, Vec<bool>),
}

/// Metres on a side of a cell of [`Fleet::sky`]: about the planner's reach.
const SKY_CELL: f64 = 400.0;
/// Metres on a side of a cell of [`Fleet::target_grid`], at least: about a sensor's range.
const TARGET_CELL: f64 = 50.0;

/// The world's targets in cells of [`TARGET_CELL`], or larger where targets are sparse:
/// about one cell per target over the box they cover, so that the cells fit the grid's
/// array (a query looks at a few cells, whose lists it filters exactly: the cell size
/// changes the cost, not the answer).
fn target_grid(targets: &[Target]) -> Grid {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for t in targets {
        (lo, hi) =
            ([lo[0].min(t.at[0]), lo[1].min(t.at[1])], [hi[0].max(t.at[0]), hi[1].max(t.at[1])]);
    }
    let area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
    let size = match (area / targets.len() as f64).sqrt() {
        s if s.is_finite() && s > TARGET_CELL => s,
        _ => TARGET_CELL,
    };
    let mut g = Grid::new(size);
    g.reframe(lo, hi, targets.len());
    for (i, t) in targets.iter().enumerate() {
        g.put(i, [t.at[0], t.at[1]]);
    }
    g
}

/// One `Spec` per make of drone, shared; neighbours in the file are mostly of one make.
#[derive(Default)]
struct Specs {
    all: HashSet<Arc<Spec>>,
    last: Option<Arc<Spec>>,
}

impl Specs {
    fn of(&mut self, d: &aviary_world::Drone) -> Arc<Spec> {
        let spec = Spec::of(d);
        let shared = match &self.last {
            Some(last) if **last == spec => last.clone(),
            _ => match self.all.get(&spec) {
                Some(shared) => shared.clone(),
                None => {
                    let shared = Arc::new(spec);
                    self.all.insert(shared.clone());
                    shared
                }
            },
        };
        self.last = Some(shared.clone());
        shared
    }
}

impl Fleet {
    /// Every drone of the world, landed and disarmed at its home (at ground level), with
    /// the world's start charge.
    pub fn new(world: &World) -> Fleet {
        let mut specs = Specs::default();
        let drones = world.drones.iter().map(|d| SimDrone::new(d, specs.of(d))).collect();
        Fleet { drones, ..Fleet::around(world) }
    }

    /// As [`Fleet::new`], taking the world: each drone of the world becomes the fleet's
    /// where it lies. A `SimDrone` is no larger than a world's `Drone`, so collecting
    /// them reuses the world's allocation (`Vec`'s in-place collect), and what each world
    /// drone holds is freed as it goes: a large world and its fleet are never held whole
    /// at once (docs/BENCHMARKS.md).
    pub fn from_world(mut world: World) -> Fleet {
        let fleet = Fleet::around(&world);
        let mut specs = Specs::default();
        let drones = std::mem::take(&mut world.drones)
            .into_iter()
            .map(|d| SimDrone::new(&d, specs.of(&d)))
            .collect();
        Fleet { drones, ..fleet }
    }

    /// The fleet, with `seed` the run's seed, from which every chance the world asks for
    /// is drawn (a fault's time within its range, and with `[air]` each drone's capacity,
    /// first GPS error and first random fault times, now; a sensor's detections, gusts,
    /// GPS drift and later faults as the drones fly). Without it, a fleet's seed is 0. A world that asks for no chance runs the same
    /// whatever the seed.
    pub fn seeded(mut self, seed: u64) -> Fleet {
        self.seed = seed;
        if let Some(air) = self.air.as_deref_mut() {
            air.reseed(seed);
        }
        for (j, f) in self.faults.iter_mut().enumerate() {
            if let Some([earliest, latest]) = f.window {
                let u = Stream::new(seed, Purpose::FaultTime, j).uniform();
                f.at = (earliest + u * (latest - earliest)).min(latest);
            }
        }
        self
    }

    /// Everything of a fleet but its drones.
    fn around(world: &World) -> Fleet {
        let faults = world
            .faults
            .iter()
            .filter_map(|f| {
                let drone = world.drones.iter().position(|d| d.name == f.drone)?;
                Some(ScheduledFault {
                    drone: DroneId(drone),
                    kind: f.kind,
                    at: f.at,
                    window: f.latest.map(|latest| [f.at, latest]),
                    duration: f.duration.unwrap_or(0.0),
                    fired: false,
                })
            })
            .collect();
        let fleet = Fleet {
            drones: Vec::new(),
            names: Names::new(world.drones.iter().map(|d| d.name.as_str())),
            fence: world.site.geofence.clone(),
            max_altitude: world.site.max_altitude,
            airspace: Arc::new(Airspace::of(world)),
            min_separation: world.site.min_separation,
            link_loss_rtl_after: world.site.link_loss_rtl_after,
            separation_timeout: world.site.separation_timeout,
            sensors: world.sensors.clone(),
            targets: world.targets.clone(),
            faults,
            time: 0.0,
            next_call: 1,
            releases: Vec::new(),
            aloft: Vec::new(),
            tracks: BTreeMap::new(),
            in_sky: vec![false; world.drones.len()],
            sky: Grid::new(SKY_CELL),
            sky_fresh: false,
            clearance: Clearance::new(world.drones.len()),
            max_extent: 0.0,
            hot: vec![Hot::UNKNOWN; world.drones.len()],
            outages: Vec::new(),
            fastest: world.drones.iter().map(|d| d.fastest()).fold(0.0, f64::max),
            target_grid: target_grid(&world.targets),
            near_targets: vec![None; world.drones.len()],
            calls: HashMap::new(),
            seed: 0,
            air: AirState::of(world, 0).map(Box::new),
            radio_scratch: (Vec::new(), Vec::new()),
        };
        fleet.seeded(0)
    }

    /// Simulated seconds since the fleet was made (the sum of the steps).
    pub fn time(&self) -> f64 {
        self.time
    }

    pub fn len(&self) -> usize {
        self.drones.len()
    }

    pub fn is_empty(&self) -> bool {
        self.drones.is_empty()
    }

    /// The drone's state now; `None` for an index the world does not have.
    pub fn telemetry(&self, drone: DroneId) -> Option<Telemetry> {
        let mut t = self.drones.get(drone.0).map(SimDrone::telemetry)?;
        if let Some(a) = self.air.as_deref().and_then(|air| air.drones.get(drone.0)) {
            t.gps_position[0] += a.gps[0];
            t.gps_position[1] += a.gps[1];
            if a.anemometer && self.air.as_ref().is_some_and(|air| air.wind.is_some()) {
                // On the ground it reads the mean wind; in the air, with the gusts.
                t.wind = Some(a.wind);
            }
        }
        Some(t)
    }

    /// The wind a drone flies in now (`[east, north]` m/s, mean and gusts), with
    /// `[air.wind]`.
    pub fn wind(&self, drone: DroneId) -> Option<[f64; 2]> {
        let air = self.air.as_deref()?;
        air.wind.as_ref()?;
        air.drones.get(drone.0).map(|a| a.wind)
    }

    /// The fraction of its nominal capacity that the drone's battery holds
    /// (`[air.battery] capacity_spread`; 1 without it).
    pub fn capacity(&self, drone: DroneId) -> f64 {
        self.air.as_deref().and_then(|a| a.drones.get(drone.0)).map_or(1.0, |a| a.capacity)
    }

    /// (metres flown, seconds in the air) of the drone so far; zeros for an index the
    /// world does not have.
    pub fn odometry(&self, drone: DroneId) -> (f64, f64) {
        self.drones.get(drone.0).map_or((0.0, 0.0), |d| (d.odometer, d.flight_time))
    }

    /// Every `ReleasePayload` so far, in order.
    pub fn releases(&self) -> &[Release] {
        &self.releases
    }

    /// What the drone carries.
    /// Where `drone`'s last `Sweep` or `FollowPath` stopped, when it ended early.
    pub fn stopped(&self, drone: DroneId) -> Option<aviary_api::Progress> {
        self.drones.get(drone.0)?.rare.as_ref()?.stopped
    }

    pub fn carrying(&self, drone: DroneId) -> Option<&str> {
        self.drones.get(drone.0)?.carrying().map(String::as_str)
    }

    /// Whether the drone's video stream is on.
    pub fn streaming(&self, drone: DroneId) -> bool {
        self.drones.get(drone.0).is_some_and(|d| d.streaming)
    }

    /// The kinds the drone is detecting, in the order detection started.
    pub fn detecting(&self, drone: DroneId) -> Vec<String> {
        self.drones
            .get(drone.0)
            .map(|d| d.detections().iter().map(|a| a.kind.clone()).collect())
            .unwrap_or_default()
    }

    /// Starts `call` on `drone`. Returns the call's id and, when the call is already
    /// over (an instant function, or a refusal), how it ended; otherwise the end comes in a
    /// later [`Fleet::step`] (or [`Fleet::interrupt`]).
    pub fn call(&mut self, drone: DroneId, call: &FunctionCall) -> (CallId, Option<CallEnd>) {
        let id = CallId(self.next_call);
        self.next_call += 1;
        self.touch(drone);
        let end = match self.start(drone, id, call) {
            Ok(true) => {
                self.calls.insert(id, drone);
                None
            }
            Ok(false) => Some(CallEnd::Done),
            Err(failure) => Some(CallEnd::Failed(failure)),
        };
        (id, end)
    }

    /// Aborts, pauses or resumes a call in progress. Returns the call's end when that
    /// ends it (an abort). A call that is not in progress is left alone.
    pub fn interrupt(&mut self, call: CallId, how: Interrupt) -> Option<CallEnd> {
        let end = self.interrupt_on(call, how);
        if end.is_some() {
            self.calls.remove(&call);
        }
        end
    }

    fn interrupt_on(&mut self, call: CallId, how: Interrupt) -> Option<CallEnd> {
        // Only the call's own drone can have it in progress.
        let &drone = self.calls.get(&call)?;
        self.touch(drone);
        if let Some(d) = self.drones.get_mut(drone.0) {
            if d.motion.as_ref().is_some_and(|t| t.call == Some(call)) {
                match how {
                    Interrupt::Abort => {
                        d.note_stop();
                        d.motion = None;
                        d.settle();
                        d.bring_back();
                        return Some(CallEnd::Interrupted);
                    }
                    Interrupt::Pause => {
                        if let Some(task) = d.motion.as_mut() {
                            task.paused = true;
                        }
                        d.hold();
                    }
                    Interrupt::Resume => {
                        if let Some(task) = d.motion.as_mut() {
                            task.paused = false;
                        }
                    }
                }
                return None;
            }
            // A paused call set aside for a newer one: it waits there, paused or not.
            if let Some(rare) = d.rare.as_deref_mut() {
                if let Some(at) = rare.aside.iter().position(|a| a.task.call == Some(call)) {
                    match how {
                        Interrupt::Abort => {
                            rare.aside.remove(at);
                            return Some(CallEnd::Interrupted);
                        }
                        Interrupt::Pause => rare.aside[at].task.paused = true,
                        Interrupt::Resume => rare.aside[at].task.paused = false,
                    }
                    return None;
                }
            }
            let rare = d.rare.as_deref_mut();
            if let Some(rare) = rare.filter(|r| r.loading.as_ref().is_some_and(|l| l.call == call))
            {
                match how {
                    Interrupt::Abort => {
                        rare.loading = None;
                        return Some(CallEnd::Interrupted);
                    }
                    Interrupt::Pause => rare.loading.iter_mut().for_each(|l| l.paused = true),
                    Interrupt::Resume => rare.loading.iter_mut().for_each(|l| l.paused = false),
                }
                return None;
            }
        }
        None
    }

    /// Forgets what the fleet keeps about drone `id` between steps (it may have changed).
    pub(crate) fn touch(&mut self, id: DroneId) {
        if let Some(h) = self.hot.get_mut(id.0) {
            h.known = false;
        }
    }
}
