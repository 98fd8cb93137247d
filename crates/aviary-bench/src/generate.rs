//! Large, realistic missions for benchmarks and tests: [`large_mission`] writes a
//! mission of any size together with the world it runs in.
//!
//! The mission is not one line repeated. It is a sequence of *waves*; each wave runs
//! four *sectors* in parallel, and each sector has four capabilities of its own
//! (REQUIREMENTS, DEFAULTS, PERFORM, leash sections, EXCEPTIONS, API calls, handlers,
//! IF/ELSE, DOWHILE) and a block of the MISSION that uses them: nested PARALLEL and
//! SEQUENTIAL blocks, FOR blocks over groups and over single drones, `ON EVERY ... BY
//! ... WITH` handlers, signals, exception handlers, leash calls, requirements and
//! comments. Parallel branches command disjoint drones, every name is in the world,
//! every signal raised is heard and every handler can fire, so `aviary check` reports
//! nothing on it. The output is a function of `target_bytes` only.

mod front;
mod swarm;
mod w;

use std::fmt::Write;

pub use front::{chain_mission, front_world, sequential_mission};
pub use swarm::{swarm_mission, swarm_world};
pub use w::{w_mission, w_world};

/// Drones in the generated world.
pub const DRONES: usize = 200;
/// Groups of the generated world; each has `DRONES / GROUPS` members.
pub const GROUPS: usize = 20;
const PER_GROUP: usize = DRONES / GROUPS;
const LANDMARKS: usize = 100;
const ZONES: usize = 40;
const DEPOTS: usize = 4;
/// Sectors that run in parallel in one wave; each takes two groups.
const SECTORS_PER_WAVE: usize = 4;

/// A mission of at least `target_bytes` bytes (and a little more: whole waves are
/// written) and the world file it refers to, as `(mission text, world TOML)`.
pub fn large_mission(target_bytes: usize) -> (String, String) {
    let mut mission = String::with_capacity(target_bytes / 2 + 4096);
    let mut capabilities = String::with_capacity(target_bytes / 2 + 4096);
    mission.push_str(
        "// A large generated mission (aviary_bench::generate::large_mission): waves of four\n\
         // sectors in parallel; in each sector one team searches a zone while a second team\n\
         // watches, escorts, spots and marks every find with a beacon.\n\n\
         MISSION Regional_Search:\n\
         \x20   SEQUENTIAL Preflight:\n\
         \x20       PARALLEL FOR\n\
         \x20           team_00 AND\n\
         \x20           team_01\n\
         \x20           AS checker:\n\
         \x20           STARTIF checker.battery < 90%:\n\
         \x20               checker Hover WITH 5s\n",
    );
    let mut wave = 0;
    let mut sector = 0;
    loop {
        write_wave(&mut mission, wave, &mut sector, &mut capabilities);
        wave += 1;
        if mission.len() + capabilities.len() >= target_bytes {
            break;
        }
    }
    let _ = writeln!(mission, "    WAITFOR RECEIVED(Wave_{:04}_Done)", wave - 1);
    mission.push_str("    team_00 team_01 Land\n\n");
    mission.push_str(capabilities.trim_end());
    mission.push('\n');
    (mission, world())
}

/// A small deterministic generator, so that values differ from sector to sector.
struct Rng(u64);

impl Rng {
    fn new(seed: usize) -> Rng {
        Rng((seed as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0xD1B5_4A32_D192_ED03)
    }
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n as u64) as usize
    }
    fn range(&mut self, lo: usize, hi: usize) -> usize {
        lo + self.below(hi - lo + 1)
    }
}

fn write_wave(m: &mut String, wave: usize, sector: &mut usize, caps: &mut String) {
    let first = *sector;
    if wave > 0 {
        let _ = writeln!(m, "    WAITFOR RECEIVED(Wave_{:04}_Done)", wave - 1);
    }
    let _ = writeln!(m, "    PARALLEL Wave_{wave:04}:");
    let _ = writeln!(
        m,
        "        /* Wave {wave}: sectors {first} to {}, each with two teams of its own. */",
        first + SECTORS_PER_WAVE - 1
    );
    for slot in 0..SECTORS_PER_WAVE {
        let search = (2 * SECTORS_PER_WAVE * wave + 2 * slot) % GROUPS;
        let support = search + 1;
        write_sector(m, *sector, search, support);
        write_capabilities(caps, *sector);
        *sector += 1;
    }
    let _ = writeln!(m, "    SIGNAL Wave_{wave:04}_Done WITH ELAPSED");
}

fn uav(group: usize, member: usize) -> String {
    format!("uav_{:03}", group * PER_GROUP + member)
}

/// One sector of the MISSION: team `search` sweeps a zone; team `support` watches it,
/// escorts, spots landmarks and drops a beacon on every find.
fn write_sector(m: &mut String, s: usize, search: usize, support: usize) {
    let mut rng = Rng::new(s);
    let zone = format!("Zone_{:02}", rng.below(ZONES));
    let zone2 = format!("Zone_{:02}", rng.below(ZONES));
    let mark = format!("Landmark_{:03}", rng.below(LANDMARKS));
    let spot1 = format!("Landmark_{:03}", rng.below(LANDMARKS));
    let spot2 = format!("Landmark_{:03}", rng.below(LANDMARKS));
    let team = format!("team_{search:02}");
    let helpers = format!("team_{support:02}");
    let (watcher, lead, wing, beacon1, beacon2, spotter1, spotter2, spare) = (
        uav(support, 0),
        uav(support, 1),
        uav(support, 2),
        uav(support, 3),
        uav(support, 4),
        uav(support, 5),
        uav(support, 6),
        uav(support, 7),
    );
    let alt = rng.range(3, 10) * 5;
    let watch_alt = rng.range(8, 16) * 5;
    let radius = rng.range(4, 20) * 5;
    let minutes = rng.range(20, 55);
    let hover = rng.range(10, 60);
    let n = format!("{s:04}");
    let _ = write!(
        m,
        "        SEQUENTIAL Sector_{n}:
            // Sector {s}: {team} searches {zone}; {helpers} watches {mark} and marks finds.
            PARALLEL Launch_{n}:
                {team} TakeOff WITH {alt}m
                {watcher} TakeOff WITH alt={watch_alt}m
                {lead} {wing} TakeOff
            PARALLEL Work_{n}:
                {watcher} Watch_{n}-Cam WITH {mark}, radius={radius}m
                PARALLEL FOR {team} WITH {zone} AS searcher_{n} WITH area:
                    STARTIF searcher_{n}.role = \"searcher\" AND searcher_{n}.battery > 35%:
                        searcher_{n} FlyTo WITH area
                        searcher_{n} Survey_{n} WITH area, alt={alt}m
                SEQUENTIAL Support_{n}:
                    SEQUENTIAL FOR
                        {spotter1} WITH {spot1} AND
                        {spotter2} WITH {spot2}
                        AS spotter_{n} WITH spot:
                        SEQUENTIAL:
                            spotter_{n} FlyTo WITH spot
                            spotter_{n} Hover WITH {hover}s
                            spotter_{n} ReturnHome
                    IF ELAPSED < {minutes}min:
                        {lead} {wing} Escort_{n} WITH target={mark}
                    ELSE IF RECEIVED(Sector_Alert_{n}):
                        {lead} {wing} FlyTo WITH {zone2}
                    ELSE:
                        {lead} {wing} ReturnHome
                    Watch_{n}-Cam Closer WITH radius=25m
                    WAITFOR distance({watcher}.position, {mark}) < 2km
                    Watch_{n}-Cam Route
                ON EVERY Victim_Found_{n} BY searcher_{n} WITH location:
                    {beacon1} DropBeacon_{n} WITH kind=Body, position=location
                ON EVERY Hazard_Found_{n} BY searcher_{n} WITH location:
                    {beacon2} DropBeacon_{n} WITH Radiation, location
                ON Beacon_Lost_{n} WITH kind, position:
                    SIGNAL Sector_Alert_{n} WITH position
                ON EXCEPTION Survey_Failed_{n} WITH area:
                    SIGNAL Sector_Alert_{n} WITH area
            IF RECEIVED(Sector_Alert_{n}):
                PARALLEL:
                    {spare} FlyToAndPatrol WITH {zone}, radius=60m
                    {team} ReturnHome
            ELSE:
                Watch_{n}-Cam ABORT
                {team} {helpers} ReturnHome
"
    );
}

/// The four capabilities of sector `s`.
fn write_capabilities(c: &mut String, s: usize) {
    let mut rng = Rng::new(s ^ 0x5A5A);
    let n = format!("{s:04}");
    let spacing = rng.range(4, 12) * 5;
    let survey_alt = rng.range(6, 14) * 5;
    let low = rng.range(20, 35);
    let depot = format!("Depot_{}", rng.below(DEPOTS));
    let gap = rng.range(2, 6) * 5;
    let (x1, y1, x2, y2) = (
        rng.range(0, 4000) as i64 - 2000,
        rng.range(0, 4000) as i64 - 2000,
        rng.range(0, 4000) as i64 - 2000,
        rng.range(0, 4000) as i64 - 2000,
    );
    let laps = rng.range(1, 4);
    let lat = 46.60 + rng.below(100) as f64 / 10_000.0;
    let lon = 14.26 + rng.below(100) as f64 / 10_000.0;
    let _ = write!(
        c,
        "// Sector {s}: a thermal and radiation sweep of one zone.
CAPABILITY Survey_{n} BY drone WITH area, spacing, alt:
    REQUIREMENTS:
        drone.battery > {low}%
        drone.state != Lost
    DEFAULTS:
        spacing: {spacing}m
        alt: {survey_alt}m
    PERFORM:
        ON EVERY Detected BY drone WITH kind, location:
            IF kind = Body:
                SIGNAL Victim_Found_{n} WITH location
            ELSE IF kind = Radiation:
                SIGNAL Hazard_Found_{n} WITH location
        drone.AscendTo(alt)
        drone.StartDetection(Body)
        drone.StartDetection(Radiation)
        drone.Sweep(area, spacing)
        drone.StopDetection(Radiation)
        drone.StopDetection(Body)
    PERFORM Widen:
        drone.Sweep(area, 2km)
    EXCEPTIONS:
        ON EXCEPTION BatteryCritical:
            drone.ReturnToLaunch()
        ON EXCEPTION PositionLost:
            drone.Hover(10s)
            THROW EXCEPTION Survey_Failed_{n} WITH area

/* Drops a beacon of the given kind; beacons are loaded at {depot}. */
CAPABILITY DropBeacon_{n} BY drone WITH kind, position:
    REQUIREMENTS:
        drone.battery > 25%
    DEFAULTS:
        kind: Body
    PERFORM:
        drone FlyTo WITH {depot}
        drone.DescendTo(3m)
        drone.LoadPayload(kind)
        drone.FlyToPosition(position, 12m/s)
        drone.DescendTo(5m)
        drone.ReleasePayload()
        drone ReturnHome
    EXCEPTIONS:
        ON EXCEPTION ConnectionLost:
            SIGNAL Beacon_Lost_{n} WITH kind, position

CAPABILITY Escort_{n} BY lead, wing WITH target, gap:
    DEFAULTS:
        gap: {gap}m
    PERFORM:
        PARALLEL:
            lead FlyTo WITH target
            wing FlyTo WITH target
        PARALLEL Escort_Orbit:
            lead.Orbit(target, gap, {laps})
            wing.Orbit(target, gap, {laps})
        IF lead.battery < 30% OR wing.battery < 30%:
            lead wing ReturnHome

CAPABILITY Watch_{n} BY drone WITH center, radius, laps:
    DEFAULTS:
        radius: 80m
        laps: 2
    PERFORM:
        drone FlyTo WITH center
        drone.StartStreaming()
        DOWHILE drone.battery > 40% AND ELAPSED < 50min:
            drone.Orbit(center, radius, laps)
        drone.StopStreaming()
    PERFORM Closer:
        drone.Orbit(center, radius, 1)
    PERFORM Route:
        drone.FollowPath(({x1}, {y1}), ({x2}, {y2}, 40), GEO({lat:.4}, {lon:.4}))

"
    );
}

/// The world of every generated mission: 200 drones in 20 teams, landmarks, depots
/// and zones inside a 10 km geofence.
fn world() -> String {
    let mut w = String::new();
    w.push_str(
        "# The world of aviary_bench::generate::large_mission.\n\
         [site]\n\
         name = \"Generated region\"\n\
         origin = { lat = 46.6000, lon = 14.2600, alt = 440.0 }\n\
         geofence = [[-5000, -5000], [5000, -5000], [5000, 5000], [-5000, 5000]]\n\
         max_altitude = 120.0\n\n[places]\n",
    );
    let mut rng = Rng::new(7);
    for d in 0..DEPOTS {
        let _ = writeln!(
            w,
            "Depot_{d} = [{}, {}]",
            (d as i64 % 2) * 200 - 100,
            (d as i64 / 2) * 200 - 100
        );
    }
    for l in 0..LANDMARKS {
        let _ = writeln!(
            w,
            "Landmark_{l:03} = [{}, {}]",
            rng.range(0, 8000) as i64 - 4000,
            rng.range(0, 8000) as i64 - 4000
        );
    }
    w.push_str("\n[areas]\n");
    for z in 0..ZONES {
        let (x, y) = (rng.range(0, 7000) as i64 - 3500, rng.range(0, 7000) as i64 - 3500);
        let (dx, dy) = (rng.range(200, 800) as i64, rng.range(200, 800) as i64);
        let _ = writeln!(
            w,
            "Zone_{z:02} = [[{x}, {y}], [{}, {y}], [{}, {}], [{x}, {}]]",
            x + dx,
            x + dx,
            y + dy,
            y + dy
        );
    }
    for i in 0..DRONES {
        let group = i / PER_GROUP;
        let member = i % PER_GROUP;
        let _ = write!(
            w,
            "\n[drones.uav_{i:03}]\nhome = [{}, {}]\ngroup = \"team_{group:02}\"\n",
            (group as i64 - 10) * 40,
            member as i64 * 10 - 50
        );
        // Even teams search (write_wave gives them the zones), odd ones support them.
        match group % 2 {
            0 => w.push_str(
                "sensors = [\"thermal\", \"radiation\", \"camera\"]\nrole = \"searcher\"\n",
            ),
            _ => w.push_str(
                "sensors = [\"camera\"]\npayload = [\"Body\", \"Radiation\"]\nrole = \"support\"\n",
            ),
        }
    }
    w.push_str(
        "\n[sensors.thermal]\ndetects = [\"Body\"]\nrange = 20.0\n\n\
         [sensors.radiation]\ndetects = [\"Radiation\"]\nrange = 25.0\n",
    );
    w
}

#[cfg(test)]
mod tests {
    use aviary_diagnostics::{FileId, SourceMap};

    use super::*;
    use aviary_check::NoFiles;

    #[test]
    fn a_generated_mission_checks_clean() {
        let (mission, world_text) = large_mission(200_000);
        assert!(mission.len() >= 200_000 && mission.len() < 260_000, "{} bytes", mission.len());
        let mut sources = SourceMap::new();
        let wid = sources.add("generated.world.toml", world_text);
        let (world, wdiags) = aviary_world::parse_world(wid, sources.text(wid));
        assert!(wdiags.is_empty(), "world: {wdiags:#?}");
        let world = world.expect("a world");
        assert_eq!(world.drones.len(), DRONES);
        assert_eq!(world.groups.len(), GROUPS);
        let root = sources.add("generated.mission", mission);
        let (program, diagnostics) =
            aviary_check::check(&mut sources, root, Some(&world), &NoFiles);
        let shown: Vec<String> = diagnostics
            .iter()
            .take(10)
            .map(|d| format!("{} {} at {:?}", d.code, d.message, d.primary.span))
            .collect();
        assert!(diagnostics.is_empty(), "{} diagnostics, first: {shown:#?}", diagnostics.len());
        assert!(program.mission().is_some());
    }

    #[test]
    fn generation_is_deterministic_and_grows() {
        assert_eq!(large_mission(50_000), large_mission(50_000));
        assert!(large_mission(120_000).0.len() > large_mission(50_000).0.len());
        let (text, _) = large_mission(1);
        let parse = aviary_syntax::parse(FileId(0), &text);
        assert!(parse.diagnostics.is_empty());
    }
}
