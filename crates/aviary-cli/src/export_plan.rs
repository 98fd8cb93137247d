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
use serde_json::{json, Value};

use crate::files::{color_wanted, world_beside, DiskProvider};

/// MAVLink's commands and frames, as QGC writes them.
const MAV_CMD_NAV_WAYPOINT: u16 = 16;
const MAV_CMD_NAV_RETURN_TO_LAUNCH: u16 = 20;
const MAV_CMD_NAV_TAKEOFF: u16 = 22;
const MAV_FRAME_MISSION: u8 = 2;
const MAV_FRAME_GLOBAL_RELATIVE_ALT: u8 = 3;
/// A multicopter (MAV_TYPE_QUADROTOR), on ArduPilot (MAV_AUTOPILOT_ARDUPILOTMEGA).
const VEHICLE_TYPE: u8 = 2;
const FIRMWARE_TYPE: u8 = 3;

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
) -> Result<Value, (u8, String)> {
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
) -> Value {
    let lat_lon = |x: f64, y: f64| {
        let (lat, lon) = origin.to_geodetic(x, y);
        [round(lat, 1e7), round(lon, 1e7)]
    };
    let mut items = Vec::new();
    let mut item = |command: u16, frame: u8, at: Option<([f64; 2], f64)>| {
        let params = match at {
            Some(([lat, lon], alt)) => json!([0, 0, 0, null, lat, lon, alt]),
            None => json!([0, 0, 0, 0, 0, 0, 0]),
        };
        let mut it = json!({
            "type": "SimpleItem",
            "autoContinue": true,
            "command": command,
            "doJumpId": items.len() + 1,
            "frame": frame,
            "params": params,
        });
        if let Some((_, alt)) = at {
            it["AMSLAltAboveTerrain"] = Value::Null;
            it["Altitude"] = json!(alt);
            it["AltitudeMode"] = json!(1);
        }
        items.push(it);
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
    let home = lat_lon(d.home[0], d.home[1]);
    item(MAV_CMD_NAV_TAKEOFF, MAV_FRAME_GLOBAL_RELATIVE_ALT, Some((home, round(first_alt, 100.0))));
    for p in &way {
        let alt = round(p[2], 100.0);
        item(MAV_CMD_NAV_WAYPOINT, MAV_FRAME_GLOBAL_RELATIVE_ALT, Some((lat_lon(p[0], p[1]), alt)));
    }
    item(MAV_CMD_NAV_RETURN_TO_LAUNCH, MAV_FRAME_MISSION, None);
    let polygon = |corners: &[[f64; 2]]| -> Vec<[f64; 2]> {
        corners.iter().map(|c| lat_lon(c[0], c[1])).collect()
    };
    let mut polygons = Vec::new();
    if let Some(fence) = &world.site.geofence {
        polygons.push(json!({ "inclusion": true, "polygon": polygon(fence), "version": 1 }));
    }
    for z in &world.no_fly {
        polygons.push(json!({ "inclusion": false, "polygon": polygon(&z.polygon), "version": 1 }));
    }
    let rally: Vec<Value> = world
        .places
        .iter()
        .map(|p| {
            let [lat, lon] = lat_lon(p.at[0], p.at[1]);
            json!([lat, lon, round(p.at[2], 100.0)])
        })
        .collect();
    json!({
        "fileType": "Plan",
        "version": 1,
        "groundStation": "Aviary",
        "mission": {
            "version": 2,
            "firmwareType": FIRMWARE_TYPE,
            "vehicleType": VEHICLE_TYPE,
            "cruiseSpeed": d.max_speed,
            "hoverSpeed": d.max_speed,
            "globalPlanAltitudeMode": 1,
            "plannedHomePosition": [home[0], home[1], round(origin.alt + d.home[2], 100.0)],
            "items": items,
        },
        "geoFence": { "version": 2, "circles": [], "polygons": polygons },
        "rallyPoints": { "version": 2, "points": rally },
    })
}

/// `v` to the nearest 1/`scale`.
fn round(v: f64, scale: f64) -> f64 {
    (v * scale).round() / scale
}
