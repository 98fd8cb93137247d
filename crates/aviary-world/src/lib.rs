//! The world file: the site, places, areas, drones, sensors and (for the simulator)
//! targets and faults that a mission runs in. Every key is in docs/WORLD.md.
//!
//! Invariants:
//! - Pure: this crate does no IO. [`parse_world`] takes the text; the CLI reads the file.
//! - Every problem is located: each diagnostic (code E119) carries the byte span of the
//!   key or value at fault in that text, and says what to write instead.
//! - One pass reports every problem; a [`World`] is returned only when there is none.
//! - No input makes it panic.
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

mod build;
#[cfg(test)]
mod fleet_tests;
mod hash;
mod node;
#[cfg(test)]
mod place_tests;
mod read;
#[cfg(test)]
mod tests;

use std::sync::Arc;

use aviary_diagnostics::{Diagnostic, FileId, Span};
use serde::Serialize;

/// Sensor kinds a drone may list without a `[sensors.KIND]` table: the video camera,
/// which streams and detects nothing,
/// and the anemometer, `wind`, with which a drone reads the wind (`drone.wind`).
pub const BUILTIN_SENSORS: &[&str] = &["camera", "wind"];

/// Reads a world file. Returns the world only when there are no errors; the diagnostics
/// are sorted by position.
pub fn parse_world(file: FileId, text: &str) -> (Option<World>, Vec<Diagnostic>) {
    build::parse(file, text, &NoWorldFiles)
}

/// [`parse_world`] with the files that `[imports]` names, served by `files`.
pub fn parse_world_with(
    file: FileId,
    text: &str,
    files: &dyn WorldFiles,
) -> (Option<World>, Vec<Diagnostic>) {
    build::parse(file, text, files)
}

/// Whether `name` may name an agent (`mavlink = "agent:NAME"`, `aviary agent --name`): one
/// Zenoh key chunk of letters, digits, `-`, `_` and `.`, so that it is found by name alone.
pub fn agent_name(name: &str) -> Result<(), String> {
    if name.is_empty() {
        return Err("an agent's name is empty".into());
    }
    match name.chars().find(|c| !(c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))) {
        Some(c) => Err(format!(
            "an agent's name holds only letters, digits, `-`, `_` and `.`, and `{name}` holds `{c}`"
        )),
        None => Ok(()),
    }
}

/// Supplies the files a world file's `[imports]` names (GeoJSON), as
/// `aviary_check::SourceProvider` supplies the files a mission `USE`s: the crate reads
/// none itself. The CLI's reads the disk beside the world file.
pub trait WorldFiles {
    /// The bytes of the file `path`, as written in the world file (relative to its
    /// folder), or why it cannot be read or may not be.
    fn read(&self, path: &str) -> Result<Vec<u8>, String>;
}

/// The files of a world read alone, held in memory: none, so every import is an error.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoWorldFiles;

impl WorldFiles for NoWorldFiles {
    fn read(&self, _path: &str) -> Result<Vec<u8>, String> {
        Err("the world file is read here without the files beside it".into())
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct World {
    pub site: Site,
    /// In file order.
    pub places: Vec<Place>,
    /// In file order.
    pub areas: Vec<Area>,
    /// `[lines]`, in file order: paths on the ground (a pipeline, a road, a river) that
    /// `FollowPath` flies through.
    pub lines: Vec<Line>,
    /// `[no_fly.NAME]`, in file order: where no drone may fly (docs/WORLD.md).
    pub no_fly: Vec<NoFly>,
    /// In file order: a group expands to its members in this order.
    pub drones: Vec<Drone>,
    /// From the drones' `group` keys, in order of first appearance.
    pub groups: Vec<Group>,
    /// `[sensors.KIND]`, in file order.
    pub sensors: Vec<Sensor>,
    pub targets: Vec<Target>,
    pub faults: Vec<Fault>,
    /// `[air]`: the simulator's wind, radio, GPS noise, detection curve, battery spread
    /// and random faults, each off unless declared (docs/WORLD.md).
    pub air: Air,
    /// `[expect]`, in file order: what success means beyond "no unhandled exception".
    pub expect: Vec<Expectation>,
}

/// One line of `[expect]` (docs/CAMPAIGNS.md): a run meets it or not.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, serde::Deserialize)]
#[serde(tag = "expect", content = "value", rename_all = "snake_case")]
pub enum Expectation {
    /// `all_found = true`: every `[[targets]]` found by some drone.
    AllFound,
    /// `min_found = K`: at least K of the targets found.
    MinFound(u64),
    /// `max_time = S`: the mission ended (its fleet home) within S seconds.
    MaxTime(f64),
    /// `min_battery = F`: no drone's battery went under the fraction F.
    MinBattery(f64),
}

impl std::fmt::Display for Expectation {
    /// As the reports say it: `all targets found`, `time <= 1200 s`, `battery >= 25%`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use aviary_api::show::number;
        match self {
            Expectation::AllFound => write!(f, "all targets found"),
            Expectation::MinFound(k) => write!(f, "at least {k} found"),
            Expectation::MaxTime(s) => write!(f, "time <= {} s", number(*s)),
            Expectation::MinBattery(b) => write!(f, "battery >= {}%", number(b * 100.0)),
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Site {
    pub name: Option<String>,
    /// The geodetic anchor of the local frame (x east, y north, z up, metres).
    pub origin: Option<Geo>,
    /// A polygon in local metres.
    pub geofence: Option<Vec<[f64; 2]>>,
    pub max_altitude: Option<f64>,
    /// Metres; default 5.
    pub min_separation: f64,
    /// Seconds a simulated drone holds after losing its link before it returns to launch
    /// on its own; default 10.
    pub link_loss_rtl_after: f64,
    /// Seconds a simulated drone's motion call may be held back by separation (no
    /// progress towards its target) before it ends with `Timeout`; default 30.
    pub separation_timeout: f64,
    /// A base map for the ground station and the report: an XYZ tile server's URL
    /// (`https://tile.example.org/{z}/{x}/{y}.png`); only with an `origin`.
    pub tiles: Option<String>,
    /// What the tiles' licence asks to be shown with them.
    pub tiles_attribution: Option<String>,
}

impl Default for Site {
    fn default() -> Site {
        Site {
            name: None,
            origin: None,
            geofence: None,
            max_altitude: None,
            min_separation: 5.0,
            link_loss_rtl_after: 10.0,
            separation_timeout: 30.0,
            tiles: None,
            tiles_attribution: None,
        }
    }
}

impl Site {
    /// Whether a ground point lies inside the geofence (always, when there is none).
    pub fn in_geofence(&self, p: [f64; 2]) -> bool {
        match &self.geofence {
            Some(fence) => contains(fence, p),
            None => true,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Geo {
    pub lat: f64,
    pub lon: f64,
    /// Metres; default 0.
    pub alt: f64,
}

impl Geo {
    /// As the projection between local metres and the Earth takes it.
    pub fn origin(&self) -> aviary_api::geo::Origin {
        aviary_api::geo::Origin { lat: self.lat, lon: self.lon, alt: self.alt }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Place {
    pub name: String,
    /// z = 0 when only `[x, y]` was written.
    pub at: [f64; 3],
    pub has_z: bool,
    /// The name's key.
    #[serde(skip)]
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Area {
    pub name: String,
    pub polygon: Vec<[f64; 2]>,
    /// The name's key.
    #[serde(skip)]
    pub span: Span,
}

impl Area {
    /// The polygon's area centroid; the mean of its corners when it encloses no area.
    pub fn centroid(&self) -> [f64; 2] {
        aviary_api::centroid(&self.polygon)
    }

    /// Whether a ground point lies inside the polygon.
    pub fn contains(&self, p: [f64; 2]) -> bool {
        contains(&self.polygon, p)
    }
}

/// One line of `[lines]`: points in order, at least two, each `[x, y]` (flown at the
/// drone's altitude) or `[x, y, z]`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Line {
    pub name: String,
    /// Each point and whether its height was written (z = 0 when it was not).
    pub points: Vec<([f64; 3], bool)>,
    /// The name's key.
    #[serde(skip)]
    pub span: Span,
}

impl Line {
    /// The points a `FollowPath` of the line flies through, in order.
    pub fn path(&self) -> Vec<aviary_api::Point> {
        let point = |&(p, has_z): &([f64; 3], bool)| aviary_api::Point {
            x: p[0],
            y: p[1],
            z: has_z.then_some(p[2]),
        };
        self.points.iter().map(point).collect()
    }

    /// Its points on the ground.
    pub fn ground(&self) -> Vec<[f64; 2]> {
        self.points.iter().map(|(p, _)| [p[0], p[1]]).collect()
    }
}

/// One `[no_fly.NAME]`: a polygon no drone may enter, from the ground up to `up_to`
/// (at every height without it). Missions do not name zones; the name is for people.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NoFly {
    pub name: String,
    pub polygon: Vec<[f64; 2]>,
    /// Metres above the ground; `None`: the zone holds at every height.
    pub up_to: Option<f64>,
    /// The name's key.
    #[serde(skip)]
    pub span: Span,
}

impl NoFly {
    /// Whether the zone holds at height `z` (metres above the ground): a flight at
    /// `up_to` or lower is in it, one above it is not.
    pub fn holds_at(&self, z: f64) -> bool {
        self.up_to.is_none_or(|top| z <= top)
    }
}

/// One `[drones.NAME]`. A world may have a great many, all alive while a mission runs: what
/// most drones leave empty or share (a group's name, attribute keys, a MAVLink link) costs
/// them a pointer at most.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Drone {
    pub name: String,
    pub home: [f64; 3],
    /// Shared with the other members of the group.
    pub group: Option<Arc<str>>,
    pub sensors: Box<[String]>,
    pub payload: Box<[String]>,
    /// m/s, default 10.
    pub max_speed: f64,
    /// m/s, default 3.
    pub climb_rate: f64,
    /// m/s², default 3.
    pub acceleration: f64,
    /// Start charge in %, default 100.
    pub battery: f64,
    /// Seconds of flight on a full battery, default 1800; when both `battery_capacity`
    /// and `flight_current` are given, their quotient instead.
    pub endurance: f64,
    /// m/s down, default `climb_rate`.
    pub descent_rate: f64,
    /// m/s down in the last `land_speed_below` metres of a landing, default `descent_rate`
    /// (autopilots land slowly: ArduCopter's LAND_SPEED is 0.5 m/s).
    pub land_speed: f64,
    /// m, default 10 (ArduCopter's LAND_ALT_LOW).
    pub land_speed_below: f64,
    /// m, default 10: `ReturnToLaunch` flies home at least this high (ArduCopter's RTL_ALT).
    pub return_altitude: f64,
    /// s, default 0: `ReturnToLaunch` waits this long above home before it lands
    /// (ArduCopter's RTL_LOIT_TIME).
    pub return_loiter: f64,
    /// m/s up, default `climb_rate`: how fast `TakeOff` climbs from the ground (PX4's
    /// MPC_TKO_SPEED, 1.5 m/s, is half its climb rate).
    pub takeoff_speed: f64,
    /// m/s, default `max_speed`: the fastest it flies through the air. In a wind
    /// (`[air.wind]`) the speed over the ground along a track is what this airspeed
    /// leaves (the wind triangle), at most `max_speed`: an autopilot holds its ground
    /// speed into a head wind as far as its tilt allows (ArduCopter SITL: 13.6 m/s
    /// through the air for a WPNAV_SPEED of 10 m/s).
    pub max_airspeed: f64,
    /// m/s, default `max_speed`: `ReturnToLaunch`'s speed over the ground on its way home
    /// (the autopilot's own, PX4's MPC_XY_CRUISE).
    pub return_speed: f64,
    /// mAh, if known (a MAVLink vehicle reports its own: BATT_CAPACITY).
    pub battery_capacity: Option<f64>,
    /// A drawn in flight on average, if known.
    pub flight_current: Option<f64>,
    pub backend: Backend,
    /// Every other key, in file order: readable as `d.key`. Keys are shared by the
    /// drones that have them.
    pub attributes: Box<[(Arc<str>, AttributeValue)]>,
    /// The drone's own `air` table: what it changes of `[air]` for this drone (a relay,
    /// its GPS, its fault rates); `None` for most drones.
    pub air: Option<Box<DroneAir>>,
    /// The `NAME` of `[drones.NAME]`.
    #[serde(skip)]
    pub span: Span,
}

impl Drone {
    /// The endurance that capacity and draw give, when both are known.
    pub fn endurance_from_battery(capacity: Option<f64>, current: Option<f64>) -> Option<f64> {
        match (capacity, current) {
            (Some(mah), Some(amps)) if mah > 0.0 && amps > 0.0 => {
                Some(mah / 1000.0 / amps * 3600.0)
            }
            _ => None,
        }
    }

    /// The most it can move in a second, over the ground plus up or down, whatever it
    /// does: what the simulator's separation and avoidance plan with.
    pub fn fastest(&self) -> f64 {
        self.max_speed.max(self.return_speed) + self.climb_rate.max(self.takeoff_speed)
    }

    /// How the drone comes down.
    pub fn descent(&self) -> aviary_api::flight::Descent {
        aviary_api::flight::Descent {
            rate: self.descent_rate,
            land_speed: self.land_speed,
            slow_below: self.land_speed_below,
        }
    }

    pub fn attribute(&self, key: &str) -> Option<&AttributeValue> {
        self.attributes.iter().find(|(k, _)| &**k == key).map(|(_, v)| v)
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Backend {
    Sim,
    /// Boxed: a simulated drone then spends 8 bytes on its backend.
    Mavlink(Box<Mavlink>),
}

/// How to reach a drone over MAVLink.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Mavlink {
    pub address: String,
    pub system_id: Option<u8>,
    pub signing_key: Option<String>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum AttributeValue {
    Number(f64),
    Text(String),
    Bool(bool),
    /// The TOML text of a list, table or date.
    Other(String),
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Group {
    pub name: String,
    /// Indices into [`World::drones`], in the drones' file order.
    pub members: Vec<usize>,
    /// Every `group = "NAME"` string that names it, quotes included, in file order: one
    /// per drone, or one for a fleet's drones (the editor's rename edits each).
    #[serde(skip)]
    pub spans: Vec<Span>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensor {
    pub kind: String,
    pub detects: Vec<String>,
    /// Metres from the drone's ground point.
    pub range: f64,
    /// The chance, from 0 to 1, that the simulator's sensor finds a target of its kinds
    /// that comes within range (once per target and detection): 1 by default, when it
    /// always does and no chance is drawn.
    pub probability: f64,
    /// The `KIND` of `[sensors.KIND]`.
    #[serde(skip)]
    pub span: Span,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Target {
    pub kind: String,
    pub at: [f64; 3],
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fault {
    pub drone: String,
    /// Mission seconds; the earliest, when `latest` is given.
    pub at: f64,
    /// With `at = [earliest, latest]`: the latest. The simulator draws the fault's time
    /// uniformly from that range, from the run's seed.
    pub latest: Option<f64>,
    pub kind: FaultKind,
    /// Seconds; given exactly for `link_loss` and `gps_loss`.
    pub duration: Option<f64>,
    /// The `[[faults]]` header (or the inline table).
    #[serde(skip)]
    pub span: Span,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    BatteryCritical,
    LinkLoss,
    Crash,
    GpsLoss,
    MotorFailure,
}

impl FaultKind {
    pub const ALL: &'static [FaultKind] = &[
        FaultKind::BatteryCritical,
        FaultKind::LinkLoss,
        FaultKind::Crash,
        FaultKind::GpsLoss,
        FaultKind::MotorFailure,
    ];

    /// As written in the world file.
    pub fn as_str(self) -> &'static str {
        match self {
            FaultKind::BatteryCritical => "battery_critical",
            FaultKind::LinkLoss => "link_loss",
            FaultKind::Crash => "crash",
            FaultKind::GpsLoss => "gps_loss",
            FaultKind::MotorFailure => "motor_failure",
        }
    }

    pub fn from_name(name: &str) -> Option<FaultKind> {
        FaultKind::ALL.iter().copied().find(|k| k.as_str() == name)
    }

    /// Whether the fault lasts a while (and so needs a `duration`).
    pub fn has_duration(self) -> bool {
        matches!(self, FaultKind::LinkLoss | FaultKind::GpsLoss)
    }
}

/// `[air]`: the air a simulated mission flies in. Every part is off (`None`, empty)
/// unless the world declares it; a world without `[air]` flies as in still, perfect air.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Air {
    pub wind: Option<Wind>,
    pub radio: Option<Radio>,
    pub gps: Option<Gps>,
    pub detection: Option<Falloff>,
    /// `[air.battery] capacity_spread`: the 1-sigma spread of a drone's capacity, as a
    /// fraction of its nominal capacity.
    pub capacity_spread: Option<f64>,
    /// `[air.faults]`: each kind's rate per flight hour, in `FaultKind::ALL` order.
    pub faults: Vec<RandomFault>,
}

impl Air {
    /// Whether the world declares any part of the air.
    pub fn is_still(&self) -> bool {
        *self == Air::default()
    }
}

/// `[air.wind]`: a mean wind, the same everywhere and at every height, and optional
/// Dryden turbulence (MIL-F-8785C).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Wind {
    /// Mean speed, m/s.
    pub speed: f64,
    /// Where it blows from, degrees clockwise from north (meteorology's convention: a
    /// wind `from = 270` is a west wind, blowing east).
    pub from: f64,
    /// The turbulence's wind speed at 20 ft (W20 of MIL-F-8785C), m/s; `None`: no gusts.
    pub turbulence: Option<f64>,
    /// How much the drain grows with airspeed: power is `P(v) = P0 (1 + k (v / max_speed)^2)`.
    pub drain: f64,
    /// The `speed` value.
    #[serde(skip)]
    pub span: Span,
}

impl Wind {
    /// The mean wind's velocity over the ground, `[east, north]` m/s (where it blows to).
    pub fn velocity(&self) -> [f64; 2] {
        let rad = self.from.to_radians();
        [-self.speed * rad.sin(), -self.speed * rad.cos()]
    }
}

/// `[air.radio]`: the ground station's radio.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Radio {
    /// Where the station stands, `[x, y]` m.
    pub station: [f64; 2],
    /// How far it reaches, over the ground, m.
    pub range: f64,
    /// Seconds between two looks at who is in reach.
    pub every: f64,
}

impl Radio {
    /// Who is in reach: `linked[i]` for the drone at `at[i]` (`None`: lost, neither
    /// reached nor relaying), in reach of the station or of a relay that is itself linked
    /// (relays chain); `relays[i]` is drone i's reach as a relay, if it is one
    /// ([`World::relays`]). The one rule the simulator flies and `aviary check` warns by.
    pub fn reach(&self, relays: &[Option<f64>], at: &[Option<[f64; 2]>], linked: &mut Vec<bool>) {
        let near = |a: [f64; 2], b: [f64; 2], r: f64| (a[0] - b[0]).hypot(a[1] - b[1]) <= r;
        linked.clear();
        linked.extend(at.iter().map(|p| p.is_some_and(|p| near(p, self.station, self.range))));
        // Each pass links the drones in reach of the relays linked so far: a chain of n
        // relays takes n passes.
        let mut changed = relays.iter().any(Option::is_some);
        while changed {
            changed = false;
            for j in 0..at.len() {
                let (Some(q), Some(Some(r)), true) = (at[j], relays.get(j), linked[j]) else {
                    continue;
                };
                for i in 0..at.len() {
                    if !linked[i] && at[i].is_some_and(|p| near(p, q, *r)) {
                        linked[i] = true;
                        changed = true;
                    }
                }
            }
        }
    }
}

/// `[air.gps]`: the error of the position a mission reads, a first-order Gauss-Markov
/// process per horizontal axis.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Gps {
    /// 1-sigma error per axis, m.
    pub error: f64,
    /// The error's correlation time, s.
    pub correlation: f64,
}

/// `[air.detection] falloff`: how a sensor's chance falls from its `probability` at 0 m
/// to its range.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Falloff {
    /// From `probability` at 0 m to 0 at the range.
    Linear,
    /// `[[fraction of the range, factor of the probability], ...]`, straight between the
    /// points: fractions rising from 0 to 1, factors from 1 never rising.
    Curve(Vec<[f64; 2]>),
}

impl Falloff {
    /// The factor of the probability at `fraction` of the range (0 beyond it).
    pub fn factor(&self, fraction: f64) -> f64 {
        if !(0.0..=1.0).contains(&fraction) {
            return if fraction < 0.0 { 1.0 } else { 0.0 };
        }
        match self {
            Falloff::Linear => 1.0 - fraction,
            Falloff::Curve(points) => {
                for w in points.windows(2) {
                    let ([x0, y0], [x1, y1]) = (w[0], w[1]);
                    if fraction <= x1 {
                        let t = if x1 > x0 { (fraction - x0) / (x1 - x0) } else { 1.0 };
                        return y0 + t * (y1 - y0);
                    }
                }
                points.last().map_or(0.0, |p| p[1])
            }
        }
    }

    /// The largest fraction of the range at which the factor is still above `level`
    /// (`None`: nowhere): a target is found within it.
    pub fn reach(&self, level: f64) -> Option<f64> {
        if self.factor(0.0) <= level {
            return None;
        }
        match self {
            Falloff::Linear => Some(1.0 - level),
            Falloff::Curve(points) => {
                let mut last = 0.0;
                for w in points.windows(2) {
                    let ([x0, y0], [x1, y1]) = (w[0], w[1]);
                    if y1 > level {
                        last = x1;
                        continue;
                    }
                    // y0 > level >= y1: where the segment crosses the level.
                    return Some(if y0 > y1 {
                        x0 + (y0 - level) / (y0 - y1) * (x1 - x0)
                    } else {
                        x0
                    });
                }
                Some(last)
            }
        }
    }
}

/// One kind of `[air.faults]`: how often it happens, per hour of flight.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RandomFault {
    pub kind: FaultKind,
    /// Per flight hour.
    pub rate: f64,
    /// Seconds, for `link_loss` and `gps_loss`.
    pub duration: Option<f64>,
}

/// A drone's own `air` table.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct DroneAir {
    /// It relays the station's link to drones in its reach.
    pub relay: bool,
    /// Its radio's reach as a relay, m; `None`: the station's.
    pub range: Option<f64>,
    /// Its GPS's 1-sigma error, m, instead of `[air.gps] error`.
    pub gps_error: Option<f64>,
    /// Its fault rates, instead of those of `[air.faults]` for these kinds.
    pub faults: Vec<RandomFault>,
}

impl World {
    /// Each drone's reach as a relay of the station's radio (`air = { relay = true }`,
    /// its own `range`, else the station's), or `None`.
    pub fn relays(&self) -> Vec<Option<f64>> {
        let station = self.air.radio.as_ref().map(|r| r.range);
        self.drones
            .iter()
            .map(|d| {
                d.air.as_deref().filter(|a| a.relay).map(|a| a.range.or(station).unwrap_or(0.0))
            })
            .collect()
    }

    pub fn drone(&self, name: &str) -> Option<&Drone> {
        self.drones.iter().find(|d| d.name == name)
    }
    pub fn group(&self, name: &str) -> Option<&Group> {
        self.groups.iter().find(|g| g.name == name)
    }
    pub fn place(&self, name: &str) -> Option<&Place> {
        self.places.iter().find(|p| p.name == name)
    }
    pub fn area(&self, name: &str) -> Option<&Area> {
        self.areas.iter().find(|a| a.name == name)
    }
    pub fn line(&self, name: &str) -> Option<&Line> {
        self.lines.iter().find(|l| l.name == name)
    }
    pub fn sensor(&self, kind: &str) -> Option<&Sensor> {
        self.sensors.iter().find(|s| s.kind == kind)
    }
    /// Every name a mission may use (drones, groups, places, areas, lines), for "did you
    /// mean".
    pub fn names(&self) -> impl Iterator<Item = &str> {
        let drones = self.drones.iter().map(|d| d.name.as_str());
        let groups = self.groups.iter().map(|g| g.name.as_str());
        let places = self.places.iter().map(|p| p.name.as_str());
        let areas = self.areas.iter().map(|a| a.name.as_str());
        let lines = self.lines.iter().map(|l| l.name.as_str());
        drones.chain(groups).chain(places).chain(areas).chain(lines)
    }
}

impl Default for World {
    /// The empty world: what an empty file gives.
    fn default() -> World {
        World {
            site: Site::default(),
            places: Vec::new(),
            areas: Vec::new(),
            lines: Vec::new(),
            no_fly: Vec::new(),
            drones: Vec::new(),
            groups: Vec::new(),
            sensors: Vec::new(),
            targets: Vec::new(),
            faults: Vec::new(),
            air: Air::default(),
            expect: Vec::new(),
        }
    }
}

/// Even-odd point-in-polygon test.
fn contains(polygon: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    for (i, a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}
