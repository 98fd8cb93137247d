//! `[imports]`: places, lines, areas and no-fly zones read from files beside the world
//! file (docs/WORLD.md). GeoJSON (RFC 7946) is read with georust's `geojson`, KML with
//! georust's `kml` (its Placemarks, in document order, named by `<name>`), a
//! QGroundControl `.plan` with serde_json (its items as places, its waypoints as a line,
//! named after the file); every
//! coordinate goes through the world's one projection, `aviary_api::geo::Origin`, as a
//! `GEO(...)` position does.
//!
//! Pure: the file's bytes come from the caller's [`WorldFiles`]. Every problem is
//! reported at the string in the world file that names the file, and says which feature
//! (by its index and name) is at fault.

use aviary_api::geo::Origin;
use aviary_diagnostics::Span;

use super::get;
use crate::node::{Node, Value};
use crate::read::{count, is_identifier, shown, Ctx};
use crate::{Area, Line, NoFly, Place, Site, WorldFiles};

const KEYS: &[&str] = &["features", "no_fly"];
const HELP: &str = "write `[imports]` followed by `features = \"fields.geojson\"` (points, lines and polygons become places, lines and areas) or `no_fly = \"airspace.geojson\"` (polygons become no-fly zones); each may be a list of files";

/// What the files of `[imports]` hold, each thing located at the string naming its file.
#[derive(Default)]
pub(super) struct Imported {
    pub places: Vec<Place>,
    pub lines: Vec<Line>,
    pub areas: Vec<Area>,
    pub no_fly: Vec<NoFly>,
}

/// Which key named a file: what its polygons become.
#[derive(Clone, Copy, PartialEq)]
enum Role {
    Features,
    NoFly,
}

pub(super) fn imports(cx: &mut Ctx, node: &Node, site: &Site, files: &dyn WorldFiles) -> Imported {
    let mut out = Imported::default();
    let Some(entries) = cx.table(&"`imports`", node, HELP) else {
        return out;
    };
    cx.known_keys(entries, KEYS, "[imports]");
    let mut named: Vec<(String, Span, Role)> = Vec::new();
    for e in entries {
        let role = match e.key.as_str() {
            "features" => Role::Features,
            "no_fly" => Role::NoFly,
            _ => continue,
        };
        let what = format!("`{}` in [imports]", e.key);
        match &e.node.value {
            Value::Str(s) => named.push((s.clone(), e.node.span, role)),
            Value::Array(items) => {
                for item in items {
                    match &item.value {
                        Value::Str(s) => named.push((s.clone(), item.span, role)),
                        _ => {
                            let msg =
                                format!("{what} must hold file names, found {}", item.describe());
                            cx.error(item.span, msg, HELP);
                        }
                    }
                }
            }
            _ => {
                let msg = format!(
                    "{what} must be a file name or a list of them, found {}",
                    e.node.describe()
                );
                cx.error(e.node.span, msg, HELP);
            }
        }
    }
    if named.is_empty() {
        return out;
    }
    let Some(o) = &site.origin else {
        let at = get(entries, "features").or_else(|| get(entries, "no_fly"));
        cx.error(
            at.map_or(node.span, |e| e.key_span),
            "files of `[imports]` hold longitudes and latitudes, which need the site's `origin` to be placed in the local frame",
            "add `origin = { lat = ..., lon = ..., alt = ... }` to [site]",
        );
        return out;
    };
    let origin = Origin { lat: o.lat, lon: o.lon, alt: o.alt };
    for (path, span, role) in named {
        let Some(kind) = kind_of(&path) else {
            let msg = format!("`{path}` is not a kind of file `[imports]` reads");
            cx.error(span, msg, "name a GeoJSON file (`.geojson` or `.json`), a KML file (`.kml`; a `.kmz` unzipped) or a QGroundControl plan (`.plan`)");
            continue;
        };
        let bytes = match files.read(&path) {
            Ok(bytes) => bytes,
            Err(why) => {
                cx.error(span, format!("cannot read `{path}`: {why}"), "name a file beside the world file, e.g. `features = \"fields.geojson\"`: the path is relative to the world file's folder");
                continue;
            }
        };
        let mut file = File { cx, path: &path, span, role, origin, out: &mut out };
        match kind {
            Kind::GeoJson => file.geojson(&bytes),
            Kind::Kml => file.kml(&bytes),
            Kind::Plan => file.plan(&bytes),
        }
    }
    out
}

enum Kind {
    GeoJson,
    Kml,
    Plan,
}

fn kind_of(path: &str) -> Option<Kind> {
    let ext = path.rsplit_once('.').map(|(_, e)| e.to_ascii_lowercase())?;
    match ext.as_str() {
        "geojson" | "json" => Some(Kind::GeoJson),
        "kml" => Some(Kind::Kml),
        "plan" => Some(Kind::Plan),
        _ => None,
    }
}

/// One imported file being read.
struct File<'c, 'x, 'o> {
    cx: &'c mut Ctx<'x>,
    path: &'o str,
    span: Span,
    role: Role,
    origin: Origin,
    out: &'o mut Imported,
}

/// A feature as the file gives it: its shape in degrees (longitude, latitude).
enum Shape {
    Point([f64; 2]),
    Line(Vec<[f64; 2]>),
    /// The outer ring.
    Polygon(Vec<[f64; 2]>),
}

impl File<'_, '_, '_> {
    fn error(&mut self, message: String, help: &str) {
        self.cx.error(self.span, message, help);
    }

    fn geojson(&mut self, bytes: &[u8]) {
        let Ok(text) = std::str::from_utf8(bytes) else {
            let msg = format!("`{}` is not GeoJSON: it is not UTF-8 text", self.path);
            self.error(msg, "name a GeoJSON file, as saved by QGIS, geojson.io or another GIS");
            return;
        };
        let features = match text.parse::<geojson::GeoJson>() {
            Ok(geojson::GeoJson::FeatureCollection(c)) => c.features,
            Ok(geojson::GeoJson::Feature(f)) => vec![f],
            Ok(geojson::GeoJson::Geometry(_)) => {
                let msg = format!("`{}` holds a bare geometry, with no name", self.path);
                self.error(msg, "save it as a Feature (or a FeatureCollection) with a `name` property for each, the name missions use");
                return;
            }
            Err(e) => {
                let msg = format!("`{}` is not valid GeoJSON: {e}", self.path);
                self.error(msg, "save it again from the GIS that made it, as GeoJSON (RFC 7946)");
                return;
            }
        };
        for (index, f) in features.into_iter().enumerate() {
            let name = match f.properties.as_ref().and_then(|p| p.get("name")) {
                Some(geojson::JsonValue::String(s)) => Some(s.clone()),
                _ => None,
            };
            let up_to = match f.properties.as_ref().and_then(|p| p.get("up_to")) {
                Some(v) => match v.as_f64() {
                    Some(u) if u > 0.0 && u.is_finite() => Some(Some(u)),
                    _ => None,
                },
                None => Some(None),
            };
            let shape = match f.geometry.map(|g| g.value) {
                Some(geojson::GeometryValue::Point { coordinates }) => {
                    degrees(&coordinates).map(Shape::Point)
                }
                Some(geojson::GeometryValue::LineString { coordinates }) => {
                    coordinates.iter().map(degrees).collect::<Result<_, _>>().map(Shape::Line)
                }
                Some(geojson::GeometryValue::Polygon { coordinates }) => {
                    let outer = coordinates.first().map_or(&[][..], |r| &r[..]);
                    outer.iter().map(degrees).collect::<Result<_, _>>().map(Shape::Polygon)
                }
                Some(other) => Err(format!(
                    "is a {}, which is none of Point, LineString and Polygon",
                    other.type_name()
                )),
                None => Err("has no geometry".to_owned()),
            };
            let feature = Feature { noun: "feature", index, name: name.as_deref(), up_to };
            match shape {
                Ok(shape) => self.feature(&feature, shape),
                Err(why) => {
                    let msg = format!("{} of `{}` {why}", feature.shown(), self.path);
                    self.error(msg, "give each feature one Point, LineString or Polygon (split a Multi... geometry into features of their own)");
                }
            }
        }
    }

    fn kml(&mut self, bytes: &[u8]) {
        let Ok(text) = std::str::from_utf8(bytes) else {
            let msg = format!("`{}` is not KML: it is not UTF-8 text", self.path);
            self.error(msg, "name a KML file, as saved by Google Earth, QGIS or another GIS");
            return;
        };
        if let Err(why) = well_formed(text) {
            let msg = format!("`{}` is not valid KML: {why}", self.path);
            self.error(msg, "save it again from the program that made it, as KML");
            return;
        }
        let root = match text.parse::<kml::Kml<f64>>() {
            Ok(root) => root,
            Err(e) => {
                let msg = format!("`{}` is not valid KML: {e}", self.path);
                self.error(msg, "save it again from the program that made it, as KML");
                return;
            }
        };
        // Placemarks in document order, through documents and folders, without recursion.
        let mut stack = vec![root];
        let mut index = 0;
        while let Some(element) = stack.pop() {
            let placemark = match element {
                kml::Kml::KmlDocument(d) => {
                    stack.extend(d.elements.into_iter().rev());
                    continue;
                }
                kml::Kml::Document { elements, .. } => {
                    stack.extend(elements.into_iter().rev());
                    continue;
                }
                kml::Kml::Folder(f) => {
                    stack.extend(f.elements.into_iter().rev());
                    continue;
                }
                kml::Kml::Placemark(p) => p,
                _ => continue,
            };
            let feature = Feature {
                noun: "placemark",
                index,
                name: placemark.name.as_deref(),
                up_to: Some(None),
            };
            index += 1;
            let ring = |coords: &[kml::types::Coord<f64>]| {
                coords.iter().map(|c| lon_lat(c.x, c.y)).collect::<Result<Vec<_>, _>>()
            };
            let shape = match &placemark.geometry {
                Some(kml::types::Geometry::Point(p)) => {
                    lon_lat(p.coord.x, p.coord.y).map(Shape::Point)
                }
                Some(kml::types::Geometry::LineString(l)) => ring(&l.coords).map(Shape::Line),
                Some(kml::types::Geometry::LinearRing(r)) => ring(&r.coords).map(Shape::Polygon),
                Some(kml::types::Geometry::Polygon(p)) => ring(&p.outer.coords).map(Shape::Polygon),
                Some(kml::types::Geometry::MultiGeometry(_)) => {
                    Err("is a MultiGeometry, which is none of Point, LineString and Polygon"
                        .to_owned())
                }
                Some(_) => {
                    Err("is a model, which is none of Point, LineString and Polygon".to_owned())
                }
                None => Err("has no geometry".to_owned()),
            };
            match shape {
                Ok(shape) => self.feature(&feature, shape),
                Err(why) => {
                    let msg = format!("{} of `{}` {why}", feature.shown(), self.path);
                    self.error(msg, "give each placemark one Point, LineString or Polygon (split a MultiGeometry into placemarks of their own)");
                }
            }
        }
    }

    /// QGroundControl's plan: with `features`, each mission item with a position a place
    /// `STEM_N` (N its `doJumpId`) and each rally point `STEM_rally_N`, and the navigation
    /// items (takeoff, waypoints, loiters, land) in order the line `STEM`; with `no_fly`,
    /// each exclusion polygon of its geofence a zone `STEM_fence_N`.
    fn plan(&mut self, bytes: &[u8]) {
        let path = self.path;
        let help = "save it again from QGroundControl (Plan View, File, Save)";
        let doc: serde_json::Value = match serde_json::from_slice(bytes) {
            Ok(doc) => doc,
            Err(e) => {
                self.error(format!("`{path}` is not a QGroundControl plan: {e}"), help);
                return;
            }
        };
        if doc["fileType"] != "Plan" {
            let msg =
                format!("`{path}` is not a QGroundControl plan: its `fileType` is not \"Plan\"");
            self.error(msg, help);
            return;
        }
        let file_name = path.rsplit(['/', '\\']).next().unwrap_or(path);
        let stem = file_name.rsplit_once('.').map_or(file_name, |(s, _)| s);
        if !is_identifier(stem) {
            let msg = format!("the things of `{path}` are named after the file, and `{stem}` is not a name mission code could refer to");
            self.error(
                msg,
                "rename the file: letters, digits and `_`, not starting with a digit, then `.plan`",
            );
            return;
        }
        let span = self.span;
        if self.role == Role::NoFly {
            let polygons = doc["geoFence"]["polygons"].as_array().map_or(&[][..], |p| &p[..]);
            for (n, p) in polygons.iter().enumerate() {
                if p["inclusion"].as_bool() != Some(false) {
                    continue;
                }
                let name = format!("{stem}_fence_{}", n + 1);
                let corners: Option<Vec<[f64; 2]>> = p["polygon"]
                    .as_array()
                    .and_then(|cs| cs.iter().map(|c| lat_lon_of(&c[0], &c[1])).collect());
                let Some(corners) = corners.filter(|c| c.len() >= 3) else {
                    let msg = format!("geofence polygon {n} of `{path}` is not a list of at least 3 [latitude, longitude] corners");
                    self.error(msg, help);
                    continue;
                };
                let polygon: Vec<[f64; 2]> =
                    corners.iter().map(|c| self.origin.to_local(c[1], c[0])).collect();
                let what = format!("geofence polygon {n} of `{path}`");
                if self.cx.outline_at(&what, span, &polygon) {
                    self.out.no_fly.push(NoFly { name, polygon, up_to: None, span });
                }
            }
            return;
        }
        let Some(items) = doc["mission"]["items"].as_array() else {
            self.error(format!("`{path}` has no `mission.items`"), help);
            return;
        };
        let mut line = Vec::new();
        for (index, item) in items.iter().enumerate() {
            // Complex items (surveys, corridor scans) and items without a position (a
            // speed change, a return to launch) are not read.
            if item["type"] != "SimpleItem" {
                continue;
            }
            let params = item["params"].as_array().map_or(&[][..], |p| &p[..]);
            let (Some(lat), Some(lon)) = (params.get(4), params.get(5)) else { continue };
            let (Some(lat), Some(lon)) = (lat.as_f64(), lon.as_f64()) else { continue };
            let at = match lon_lat(lon, lat) {
                Ok(lon_lat) => lon_lat,
                Err(why) => {
                    let msg = format!("mission item {index} of `{path}` {why}");
                    self.error(msg, help);
                    continue;
                }
            };
            if at == [0.0, 0.0] {
                continue;
            }
            let [x, y] = self.origin.to_local(at[1], at[0]);
            let alt = params.get(6).and_then(serde_json::Value::as_f64);
            // Heights above home (3) or the terrain (10) are the world's; above sea level
            // (0) less the origin's altitude; any other frame, none.
            let z = match (item["frame"].as_u64(), alt) {
                (Some(3 | 10), Some(a)) => Some(a),
                (Some(0), Some(a)) => Some(a - self.origin.alt),
                _ => None,
            };
            let z = z.filter(|z| *z >= 0.0 && z.is_finite());
            let id = item["doJumpId"].as_u64().unwrap_or(index as u64 + 1);
            let name = format!("{stem}_{id}");
            let point = ([x, y, z.unwrap_or(0.0)], z.is_some());
            self.out.places.push(Place { name, at: point.0, has_z: point.1, span });
            // MAV_CMD_NAV_WAYPOINT, LOITER_UNLIM, LOITER_TURNS, LOITER_TIME, LAND,
            // TAKEOFF, SPLINE_WAYPOINT: where the vehicle flies.
            if matches!(item["command"].as_u64(), Some(16..=19 | 21 | 22 | 82)) {
                line.push(point);
            }
        }
        let rally = doc["rallyPoints"]["points"].as_array().map_or(&[][..], |p| &p[..]);
        for (n, p) in rally.iter().enumerate() {
            if let Some(at) = lat_lon_of(&p[0], &p[1]) {
                let [x, y] = self.origin.to_local(at[1], at[0]);
                let name = format!("{stem}_rally_{}", n + 1);
                self.out.places.push(Place { name, at: [x, y, 0.0], has_z: false, span });
            }
        }
        if line.len() >= 2 {
            self.out.lines.push(Line { name: stem.to_owned(), points: line, span });
        }
    }

    /// One feature, named and shaped, into the world.
    fn feature(&mut self, f: &Feature, shape: Shape) {
        let path = self.path;
        let Some(name) = f.name.filter(|n| !n.is_empty()) else {
            let (msg, help) = match f.noun {
                "placemark" => (
                    format!("{} of `{path}` has no `<name>`", f.shown()),
                    "give every placemark a `<name>` (its name in Google Earth or the GIS): the name missions use for it",
                ),
                _ => (
                    format!("{} of `{path}` has no `name` property", f.shown()),
                    "give every feature a `name` property (in the GIS's attribute table): the name missions use for it",
                ),
            };
            self.error(msg, help);
            return;
        };
        if self.role == Role::NoFly && !matches!(shape, Shape::Polygon(_)) {
            let msg = format!(
                "{} of `{path}` is not a polygon, and `no_fly` in [imports] reads only polygons",
                f.shown()
            );
            self.error(
                msg,
                "import its points and lines with `features`, or remove them from the file",
            );
            return;
        }
        if self.role == Role::Features && !is_identifier(name) {
            let msg = format!(
                "{} of `{path}` has the name `{name}`, which mission code could not refer to",
                f.shown()
            );
            self.error(
                msg,
                "rename it in the file: letters, digits and `_`, not starting with a digit",
            );
            return;
        }
        let local = |p: &[f64; 2]| self.origin.to_local(p[1], p[0]);
        let span = self.span;
        match shape {
            Shape::Point(p) => {
                let [x, y] = local(&p);
                self.out.places.push(Place {
                    name: name.into(),
                    at: [x, y, 0.0],
                    has_z: false,
                    span,
                });
            }
            Shape::Line(points) => {
                if points.len() < 2 {
                    let msg = format!(
                        "{} of `{path}` has {}; a line needs at least 2",
                        f.shown(),
                        count(points.len(), "point")
                    );
                    self.error(msg, "draw the line with at least two points");
                    return;
                }
                let points = points
                    .iter()
                    .map(|p| {
                        let [x, y] = local(p);
                        ([x, y, 0.0], false)
                    })
                    .collect();
                self.out.lines.push(Line { name: name.into(), points, span });
            }
            Shape::Polygon(mut ring) => {
                // GeoJSON closes a ring by repeating its first corner; the world does not.
                if ring.len() > 1 && ring.first() == ring.last() {
                    ring.pop();
                }
                let polygon: Vec<[f64; 2]> = ring.iter().map(local).collect();
                if polygon.len() < 3 {
                    let msg = format!(
                        "{} of `{path}` has {}; a polygon needs at least 3",
                        f.shown(),
                        count(polygon.len(), "corner")
                    );
                    self.error(msg, "draw the polygon with at least three corners");
                    return;
                }
                let what = format!("{} of `{path}`", f.shown());
                if !self.cx.outline_at(&what, span, &polygon) {
                    return;
                }
                if self.role == Role::NoFly {
                    let Some(up_to) = f.up_to else {
                        let msg = format!(
                            "the `up_to` property of {what} must be a number of metres above 0"
                        );
                        self.error(msg, "write `\"up_to\": 60` in the feature's properties, or leave it out for a zone at every height");
                        return;
                    };
                    self.out.no_fly.push(NoFly { name: name.into(), polygon, up_to, span });
                } else {
                    self.out.areas.push(Area { name: name.into(), polygon, span });
                }
            }
        }
    }
}

/// A feature as messages name it: its place in the file, and its name if it has one.
struct Feature<'n> {
    /// "feature" (GeoJSON) or "placemark" (KML).
    noun: &'static str,
    index: usize,
    name: Option<&'n str>,
    /// `None`: a property `up_to` that is not a positive number.
    up_to: Option<Option<f64>>,
}

impl Feature<'_> {
    fn shown(&self) -> String {
        match self.name {
            Some(n) => format!("{} {} (`{n}`)", self.noun, self.index),
            None => format!("{} {}", self.noun, self.index),
        }
    }
}

/// Whether `text` is XML whose elements are all closed, each by its own end tag: kml 0.15
/// reads a Placemark until its end tag and, with none, forever (at the end of the text it
/// is handed end after end). Its own reader, quick-xml, checks the names of end tags.
fn well_formed(text: &str) -> Result<(), String> {
    let mut reader = quick_xml::Reader::from_str(text);
    let mut open = 0usize;
    loop {
        match reader.read_event() {
            Ok(quick_xml::events::Event::Start(_)) => open += 1,
            Ok(quick_xml::events::Event::End(_)) => open = open.saturating_sub(1),
            Ok(quick_xml::events::Event::Eof) if open == 0 => return Ok(()),
            Ok(quick_xml::events::Event::Eof) => {
                return Err(format!(
                    "it ends with {} not closed (is the file cut short?)",
                    count(open, "element")
                ))
            }
            Ok(_) => {}
            Err(e) => {
                return Err(format!("{e} (at byte {})", reader.error_position()));
            }
        }
    }
}

/// A plan's latitude and longitude (in that order, as QGC writes them) as
/// `[longitude, latitude]`, when both are numbers in range.
fn lat_lon_of(lat: &serde_json::Value, lon: &serde_json::Value) -> Option<[f64; 2]> {
    let (lat, lon) = (lat.as_f64()?, lon.as_f64()?);
    lon_lat(lon, lat).ok()
}

/// A GeoJSON position's longitude and latitude, in range.
fn degrees(p: &geojson::Position) -> Result<[f64; 2], String> {
    match p.as_slice() {
        [lon, lat, ..] => lon_lat(*lon, *lat),
        _ => Err("has a position with fewer than 2 numbers".to_owned()),
    }
}

/// A longitude and a latitude, in range.
fn lon_lat(lon: f64, lat: f64) -> Result<[f64; 2], String> {
    if (-180.0..=180.0).contains(&lon) && (-90.0..=90.0).contains(&lat) {
        return Ok([lon, lat]);
    }
    Err(format!(
        "has the position {} outside the Earth's degrees (GeoJSON and KML write longitude first, then latitude)",
        shown([lon, lat])
    ))
}
