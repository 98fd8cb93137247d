//! `aviary export-plan`: one drone's part of a mission as a QGroundControl plan file
//! (QGC's JSON `.plan`: `fileType` "Plan", version 1), for an operator who flies it from
//! QGroundControl or checks it there. The waypoints are the ends of the legs the plan
//! (`aviary check --plan`) flies the drone through, after a takeoff to the height of its
//! first leg, and it returns to launch at the end; the geofence holds the world's
//! geofence (inclusion) and no-fly zones (exclusion); the rally points are the world's
//! places. Every point is placed on the Earth by the world's one projection
//! (`aviary_api::geo::Origin`), so the world needs its `origin`.

use std::path::{Path, PathBuf};

use aviary_api::geo::Origin;
use aviary_diagnostics::{Diagnostic, SourceMap};
use aviary_mavlink::mavlink::dialects::ardupilotmega::{MavAutopilot, MavCmd, MavFrame, MavType};
use serde::Serialize;

use crate::files::{color_wanted, world_beside, DiskProvider};

pub fn run(
    mission: &Path,
    world: Option<&Path>,
    drone: &str,
    output: &Path,
    use_roots: &[PathBuf],
) -> u8 {
    match plan_file(mission, world, drone, use_roots) {
        Ok(doc) => {
            let text = serde_json::to_string_pretty(&doc).unwrap_or_default() + "\n";
            if let Err(e) = std::fs::write(output, text) {
                eprintln!("aviary: cannot write {}: {e}", output.display());
                return 2;
            }
            0
        }
        Err((code, why)) => {
            eprint!("{why}");
            code
        }
    }
}

/// The plan document, or the exit code and what to print.
fn plan_file(
    mission: &Path,
    world: Option<&Path>,
    drone: &str,
    use_roots: &[PathBuf],
) -> Result<PlanFile, (u8, String)> {
    let read = |p: &Path| {
        std::fs::read(p).map_err(|e| (2, format!("aviary: cannot read {}: {e}\n", p.display())))
    };
    let bytes = read(mission)?;
    let roots =
        crate::files::use_roots(use_roots).map_err(|why| (2, format!("aviary: {why}\n")))?;
    let provider =
        DiskProvider::new(mission, &roots).map_err(|why| (2, format!("aviary: {why}\n")))?;
    let Some(world_path) = world.map(Path::to_path_buf).or_else(|| world_beside(mission)) else {
        return Err((
            2,
            format!(
                "aviary: a plan needs the world file: put {} beside the mission, or pass --world\n",
                mission.with_extension("world.toml").display()
            ),
        ));
    };
    let world_bytes = read(&world_path)?;
    let mut sources = SourceMap::new();
    let name = mission.display().to_string();
    let mut checked = aviary_check::check_sources(
        &mut sources,
        (&name, &bytes),
        Some((&world_path.display().to_string(), &world_bytes)),
        &provider,
    );
    let verified = aviary_verify::preflight(&mut checked);
    let errors: Vec<&Diagnostic> = checked.diagnostics.iter().filter(|d| d.is_error()).collect();
    let (Some((compiled, _)), Some(world), true) =
        (verified, checked.world.as_ref(), errors.is_empty())
    else {
        let mut shown: String = errors
            .iter()
            .map(|d| aviary_diagnostics::render_text(&sources, d, color_wanted()))
            .collect();
        shown.push_str(&format!(
            "aviary: {name} has errors: no plan written (see `aviary check`)\n"
        ));
        return Err((1, shown));
    };
    let Some(index) = world.drones.iter().position(|d| d.name == drone) else {
        let names: Vec<&str> = world.drones.iter().map(|d| d.name.as_str()).take(10).collect();
        return Err((
            2,
            format!(
                "aviary: the world has no drone `{drone}`; its drones include {}\n",
                names.join(", ")
            ),
        ));
    };
    let Some(o) = &world.site.origin else {
        return Err((2, format!("aviary: a QGroundControl plan is in latitudes and longitudes: add `origin = {{ lat = ..., lon = ..., alt = ... }}` to [site] of {}\n", world_path.display())));
    };
    let origin = Origin { lat: o.lat, lon: o.lon, alt: o.alt };
    let waypoints = aviary_verify::plan::waypoints(&compiled, world);
    let d = &world.drones[index];
    Ok(document(&origin, world, d, waypoints.get(index).map_or(&[][..], |w| &w[..])))
}

/// QGC's plan document for the drone `d` flying through `points` (local `[x, y, z]`).
fn document(
    origin: &Origin,
    world: &aviary_world::World,
    d: &aviary_world::Drone,
    points: &[[f64; 3]],
) -> PlanFile {
    let lat_lon = |x: f64, y: f64| {
        let (lat, lon) = origin.to_geodetic(x, y);
        [round(lat, 1e7), round(lon, 1e7)]
    };
    let mut items: Vec<SimpleItem> = Vec::new();
    let mut item = |command: MavCmd, frame: MavFrame, at: Option<([f64; 2], f64)>| {
        let (params, placed) = match at {
            Some(([lat, lon], alt)) => {
                let params =
                    [Some(0.0), Some(0.0), Some(0.0), None, Some(lat), Some(lon), Some(alt)];
                (
                    params,
                    Some(Placed { amsl_alt_above_terrain: None, altitude: alt, altitude_mode: 1 }),
                )
            }
            None => ([Some(0.0); 7], None),
        };
        items.push(SimpleItem {
            kind: "SimpleItem",
            auto_continue: true,
            command: command as u16,
            do_jump_id: items.len() + 1,
            frame: frame as u8,
            params,
            placed,
        });
    };
    // Points on the ground are landings (the way home ends there): the return to launch
    // stands for them. Consecutive repeats (a climb where the drone stands, the takeoff's
    // point) are one waypoint.
    let first_alt = points.iter().find(|p| p[2] > 0.01).map_or(10.0, |p| p[2]);
    let mut way: Vec<[f64; 3]> = Vec::with_capacity(points.len());
    let mut last = [d.home[0], d.home[1], first_alt];
    for p in points.iter().filter(|p| p[2] > 0.01) {
        if (0..3).any(|i| (p[i] - last[i]).abs() > 0.01) {
            way.push(*p);
            last = *p;
        }
    }
    let relative = MavFrame::MAV_FRAME_GLOBAL_RELATIVE_ALT;
    let home = lat_lon(d.home[0], d.home[1]);
    item(MavCmd::MAV_CMD_NAV_TAKEOFF, relative, Some((home, round(first_alt, 100.0))));
    for p in &way {
        let alt = round(p[2], 100.0);
        item(MavCmd::MAV_CMD_NAV_WAYPOINT, relative, Some((lat_lon(p[0], p[1]), alt)));
    }
    item(MavCmd::MAV_CMD_NAV_RETURN_TO_LAUNCH, MavFrame::MAV_FRAME_MISSION, None);
    let polygon = |inclusion: bool, corners: &[[f64; 2]]| FencePolygon {
        inclusion,
        polygon: corners.iter().map(|c| lat_lon(c[0], c[1])).collect(),
        version: 1,
    };
    let mut polygons = Vec::new();
    if let Some(fence) = &world.site.geofence {
        polygons.push(polygon(true, fence));
    }
    polygons.extend(world.no_fly.iter().map(|z| polygon(false, &z.polygon)));
    let rally = world
        .places
        .iter()
        .map(|p| {
            let [lat, lon] = lat_lon(p.at[0], p.at[1]);
            [lat, lon, round(p.at[2], 100.0)]
        })
        .collect();
    PlanFile {
        file_type: "Plan",
        version: 1,
        ground_station: "Aviary",
        mission: PlanMission {
            version: 2,
            firmware_type: MavAutopilot::MAV_AUTOPILOT_ARDUPILOTMEGA as u8,
            vehicle_type: MavType::MAV_TYPE_QUADROTOR as u8,
            cruise_speed: d.max_speed,
            hover_speed: d.max_speed,
            global_plan_altitude_mode: 1,
            planned_home_position: [home[0], home[1], round(origin.alt + d.home[2], 100.0)],
            items,
        },
        geo_fence: GeoFence { version: 2, circles: [], polygons },
        rally_points: RallyPoints { version: 2, points: rally },
    }
}

/// QGroundControl's `.plan` file, as QGC writes one (its keys and versions).
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct PlanFile {
    file_type: &'static str,
    version: u8,
    ground_station: &'static str,
    mission: PlanMission,
    geo_fence: GeoFence,
    rally_points: RallyPoints,
}

#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct PlanMission {
    version: u8,
    /// MAV_AUTOPILOT: ArduPilot.
    firmware_type: u8,
    /// MAV_TYPE: a multicopter.
    vehicle_type: u8,
    cruise_speed: f64,
    hover_speed: f64,
    global_plan_altitude_mode: u8,
    planned_home_position: [f64; 3],
    items: Vec<SimpleItem>,
}

/// One command of the mission: MAV_CMD, its frame and its seven parameters.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct SimpleItem {
    #[serde(rename = "type")]
    kind: &'static str,
    auto_continue: bool,
    command: u16,
    do_jump_id: usize,
    frame: u8,
    params: [Option<f64>; 7],
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    placed: Option<Placed>,
}

/// What QGC adds to an item at a place: its altitude, above home (mode 1).
#[derive(Serialize)]
struct Placed {
    #[serde(rename = "AMSLAltAboveTerrain")]
    amsl_alt_above_terrain: Option<f64>,
    #[serde(rename = "Altitude")]
    altitude: f64,
    #[serde(rename = "AltitudeMode")]
    altitude_mode: u8,
}

#[derive(Serialize)]
struct GeoFence {
    version: u8,
    circles: [(); 0],
    polygons: Vec<FencePolygon>,
}

#[derive(Serialize)]
struct FencePolygon {
    inclusion: bool,
    polygon: Vec<[f64; 2]>,
    version: u8,
}

#[derive(Serialize)]
struct RallyPoints {
    version: u8,
    points: Vec<[f64; 3]>,
}

/// `v` to the nearest 1/`scale`.
fn round(v: f64, scale: f64) -> f64 {
    (v * scale).round() / scale
}
