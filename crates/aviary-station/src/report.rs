//! `aviary report`: one self-contained HTML file for the record after a mission, from its
//! trace (and its world, for the map): the summary, a map of every track, area, find and
//! alarm, per-drone plots of altitude, speed and battery over time, and the timeline of
//! blocks, signals, exceptions and operator actions. No script and nothing loaded from
//! elsewhere: it opens offline and prints to PDF from the browser. The pictures are SVG
//! drawn by plotters.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use aviary_api::trace::{CallStatus, Event};
use aviary_api::Function;
use plotters::prelude::*;

/// What the trace says of one drone.
#[derive(Default)]
struct Drone {
    /// (t, position, battery, airborne)
    samples: Vec<(f64, [f64; 3], f64, bool)>,
    exceptions: Vec<(f64, String)>,
    last_state: String,
}

#[derive(Default)]
struct Mission {
    name: String,
    status: String,
    reason: Option<String>,
    end: f64,
    drones: BTreeMap<String, Drone>,
    finds: Vec<(f64, String, String, [f64; 3])>,
    /// (t, what, kind): signals, exceptions, leashes, operator actions.
    marks: Vec<(f64, String, &'static str)>,
    /// block name → (start, end)
    blocks: Vec<(String, f64, Option<f64>)>,
}

pub(crate) fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn read(name: &str, trace: &str) -> Result<Mission, String> {
    let mut m = Mission::default();
    crate::replay::records(name, trace, |record| {
        let t = record.t;
        m.end = m.end.max(t);
        match record.event {
            Event::MissionStart { mission, .. } => m.name = mission.into_owned(),
            Event::MissionEnd { status, reason } => {
                m.status = status.as_str().to_string();
                m.reason = reason.map(|r| r.into_owned());
            }
            Event::BlockStart { block } => m.blocks.push((block.into_owned(), t, None)),
            Event::BlockEnd { block, .. } => {
                if let Some(b) = m.blocks.iter_mut().rev().find(|b| b.0 == block && b.2.is_none()) {
                    b.2 = Some(t);
                }
            }
            Event::Telemetry { actor, position, battery, state } => {
                let d = m.drones.entry(actor.into_owned()).or_default();
                let airborne = !matches!(state.as_str(), "Landed" | "Lost");
                d.samples.push((t, position, battery, airborne));
                d.last_state = state.as_str().to_string();
            }
            Event::Detection { actor, kind, location } => {
                m.marks.push((t, format!("{kind} found by {actor}"), "find"));
                m.finds.push((t, actor.into_owned(), kind.into_owned(), location));
            }
            Event::Signal { name, actor, .. } => {
                let by = actor.map(|a| format!(" from {a}")).unwrap_or_default();
                m.marks.push((t, format!("{name}{by}"), "signal"));
            }
            Event::Exception { name, actor, handled, .. } => {
                let by = actor.as_deref().map(|a| format!(" on {a}")).unwrap_or_default();
                let how = if handled { "" } else { " (unhandled)" };
                m.marks.push((t, format!("{name}{by}{how}"), "exception"));
                if let Some(a) = actor {
                    m.drones
                        .entry(a.into_owned())
                        .or_default()
                        .exceptions
                        .push((t, name.into_owned()));
                }
            }
            Event::Leash { capability, action, block: true, .. } => {
                m.marks.push((t, format!("{capability} {action}"), "operator"));
            }
            Event::Leash { capability, tag, action, .. } => {
                m.marks.push((t, format!("{capability}-{tag} {action}"), "operator"));
            }
            Event::Operator { action, drone } => {
                let of = drone.map(|d| format!(" {d}")).unwrap_or_default();
                m.marks.push((t, format!("operator: {}{of}", action.as_str()), "operator"));
            }
            Event::Autopilot { reason, .. } => {
                m.marks.push((t, format!("autopilot: {reason}"), "exception"));
            }
            Event::ApiDone { actor, position, function, status, .. } => {
                // Where a call left a drone: the only positions of a trace without telemetry,
                // and the end of a landing, which may fall between two samples.
                let d = m.drones.entry(actor.into_owned()).or_default();
                let landed = matches!(function, Function::Land | Function::ReturnToLaunch);
                if landed && status == CallStatus::Ok {
                    d.last_state = "Landed".into();
                }
                let battery = d.samples.last().map(|s| s.2).unwrap_or(f64::NAN);
                if d.samples.last().is_none_or(|s| s.0 < t) {
                    d.samples.push((t, position, battery, position[2] > 0.05));
                }
            }
            _ => {}
        }
    })?;
    if m.name.is_empty() {
        return Err(format!("{name}: the trace has no mission_start: is it a whole trace?"));
    }
    Ok(m)
}

const PALETTE: [RGBColor; 8] = [
    RGBColor(28, 100, 209),
    RGBColor(31, 138, 76),
    RGBColor(201, 138, 0),
    RGBColor(123, 75, 196),
    RGBColor(194, 53, 43),
    RGBColor(0, 140, 150),
    RGBColor(120, 120, 120),
    RGBColor(180, 70, 140),
];

pub(crate) fn colour(i: usize) -> RGBColor {
    PALETTE[i % PALETTE.len()]
}

pub(crate) type Drawn = Result<(), Box<dyn std::error::Error>>;

/// The world's no-fly zones: red, filled half-transparent, each named at its centre (with
/// its height, when it holds only up to one).
fn no_fly_zones<DB: DrawingBackend>(
    chart: &mut ChartContext<
        '_,
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    w: &aviary_world::World,
) -> Drawn
where
    DB::ErrorType: 'static,
{
    let red = RGBColor(194, 53, 43);
    for z in &w.no_fly {
        let polygon: Vec<(f64, f64)> = z.polygon.iter().map(|p| (p[0], p[1])).collect();
        chart.draw_series(std::iter::once(Polygon::new(polygon.clone(), red.mix(0.3))))?;
        let mut closed = polygon;
        closed.push(closed[0]);
        chart.draw_series(std::iter::once(PathElement::new(closed, red.stroke_width(2))))?;
        let c = aviary_api::centroid(&z.polygon);
        let name = match z.up_to {
            Some(top) => format!("no-fly: {} (up to {} m)", z.name, aviary_api::show::number(top)),
            None => format!("no-fly: {}", z.name),
        };
        chart.draw_series(std::iter::once(Text::new(
            escape(&name),
            (c[0], c[1]),
            ("sans-serif", 12).into_font().color(&red),
        )))?;
    }
    Ok(())
}

/// The chart of a map in local metres.
pub(crate) type MapChart<'a, DB> = ChartContext<
    'a,
    DB,
    Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
>;

/// The world on a map: its areas, lines, no-fly zones, geofence, places and the drones'
/// homes.
pub(crate) fn world_layers<DB: DrawingBackend>(
    chart: &mut MapChart<'_, DB>,
    w: &aviary_world::World,
) -> Drawn
where
    DB::ErrorType: 'static,
{
    for a in &w.areas {
        let polygon: Vec<(f64, f64)> = a.polygon.iter().map(|p| (p[0], p[1])).collect();
        chart.draw_series(std::iter::once(Polygon::new(
            polygon.clone(),
            RGBColor(28, 100, 209).mix(0.08),
        )))?;
        let mut closed = polygon;
        closed.push(closed[0]);
        chart.draw_series(std::iter::once(PathElement::new(
            closed,
            RGBColor(28, 100, 209).mix(0.6),
        )))?;
        let c = a.centroid();
        chart.draw_series(std::iter::once(Text::new(
            escape(&a.name),
            (c[0], c[1]),
            ("sans-serif", 12).into_font().color(&RGBColor(28, 100, 209)),
        )))?;
    }
    // Lines (a pipeline, a road, a river): a path in teal, named at its first point.
    let teal = RGBColor(15, 138, 126);
    for l in &w.lines {
        let path: Vec<(f64, f64)> = l.ground().iter().map(|p| (p[0], p[1])).collect();
        let Some(&first) = path.first() else { continue };
        chart.draw_series(std::iter::once(PathElement::new(path, teal.stroke_width(3))))?;
        chart.draw_series(std::iter::once(Text::new(
            escape(&format!("line: {}", l.name)),
            first,
            ("sans-serif", 12).into_font().color(&teal),
        )))?;
    }
    no_fly_zones(chart, w)?;
    if let Some(fence) = &w.site.geofence {
        let mut closed: Vec<(f64, f64)> = fence.iter().map(|p| (p[0], p[1])).collect();
        closed.push(closed[0]);
        chart.draw_series(std::iter::once(PathElement::new(closed, RED.stroke_width(2))))?;
    }
    for p in &w.places {
        chart.draw_series(std::iter::once(Circle::new((p.at[0], p.at[1]), 3, BLACK.filled())))?;
        chart.draw_series(std::iter::once(Text::new(
            escape(&p.name),
            (p.at[0], p.at[1]),
            ("sans-serif", 11).into_font(),
        )))?;
    }
    for d in &w.drones {
        chart.draw_series(std::iter::once(Rectangle::new(
            [(d.home[0] - 2.0, d.home[1] - 2.0), (d.home[0] + 2.0, d.home[1] + 2.0)],
            RGBColor(107, 115, 133).filled(),
        )))?;
    }
    Ok(())
}

/// The map: the world's geofence, areas, places and homes when known, every drone's
/// track, the finds (circles) and where exceptions were raised (crosses).
fn map(m: &Mission, world: Option<&aviary_world::World>) -> Result<String, String> {
    let mut points: Vec<[f64; 2]> = Vec::new();
    for d in m.drones.values() {
        points.extend(d.samples.iter().map(|s| [s.1[0], s.1[1]]));
    }
    if let Some(w) = world {
        points.extend(w.site.geofence.iter().flatten().copied());
        points.extend(w.areas.iter().flat_map(|a| a.polygon.iter().copied()));
        points.extend(w.no_fly.iter().flat_map(|z| z.polygon.iter().copied()));
        points.extend(w.lines.iter().flat_map(|l| l.ground()));
        points.extend(w.places.iter().map(|p| [p.at[0], p.at[1]]));
    }
    points.extend(m.finds.iter().map(|f| [f.3[0], f.3[1]]));
    if points.is_empty() {
        return Ok("<p>No positions in the trace.</p>".into());
    }
    let (x0, x1, y0, y1) = square_frame(&points);
    let mut svg = String::new();
    let drawn: Drawn = (|| {
        let root = SVGBackend::with_string(&mut svg, (760, 760)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(10)
            .x_label_area_size(30)
            .y_label_area_size(50)
            .build_cartesian_2d(x0..x1, y0..y1)?;
        chart
            .configure_mesh()
            .x_desc("east (m)")
            .y_desc("north (m)")
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
        if let Some(w) = world {
            world_layers(&mut chart, w)?;
        }
        for (i, (name, d)) in m.drones.iter().enumerate() {
            let track = d.samples.iter().map(|s| (s.1[0], s.1[1]));
            chart
                .draw_series(LineSeries::new(track, colour(i).stroke_width(2)))?
                .label(escape(name))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 16, y)], colour(i).stroke_width(2))
                });
            for (t, _) in &d.exceptions {
                if let Some(s) = d.samples.iter().rev().find(|s| s.0 <= *t).or(d.samples.first()) {
                    chart.draw_series(std::iter::once(Cross::new(
                        (s.1[0], s.1[1]),
                        6,
                        RED.stroke_width(2),
                    )))?;
                }
            }
        }
        for f in &m.finds {
            chart.draw_series(std::iter::once(Circle::new(
                (f.3[0], f.3[1]),
                7,
                RED.stroke_width(2),
            )))?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK.mix(0.3))
            .position(SeriesLabelPosition::UpperRight)
            .draw()?;
        root.present()?;
        Ok(())
    })();
    drawn.map_err(|e| format!("cannot draw the map: {e}"))?;
    Ok(svg)
}

/// One small plot over the mission's time: `value` of each sample.
fn plot(
    d: &Drone,
    end: f64,
    title: &str,
    unit: &str,
    value: &dyn Fn(usize) -> Option<f64>,
    i: usize,
) -> Result<String, String> {
    let values: Vec<(f64, f64)> =
        (0..d.samples.len()).filter_map(|k| value(k).map(|v| (d.samples[k].0, v))).collect();
    let top = values.iter().map(|v| v.1).fold(0.0_f64, f64::max).max(1.0) * 1.1;
    let mut svg = String::new();
    let drawn: Drawn = (|| {
        let root = SVGBackend::with_string(&mut svg, (300, 150)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(format!("{title} ({unit})"), ("sans-serif", 13))
            .margin(6)
            .x_label_area_size(22)
            .y_label_area_size(38)
            .build_cartesian_2d(0.0..end.max(1.0), 0.0..top)?;
        chart.configure_mesh().x_labels(5).y_labels(4).light_line_style(WHITE.mix(0.0)).draw()?;
        chart.draw_series(LineSeries::new(values.iter().copied(), colour(i).stroke_width(2)))?;
        root.present()?;
        Ok(())
    })();
    drawn.map_err(|e| format!("cannot draw a plot: {e}"))?;
    Ok(svg)
}

/// The report of the trace `bytes` (JSON Lines, each line read once), named `name`.
pub fn render(
    name: &str,
    bytes: Vec<u8>,
    world: Option<&aviary_world::World>,
) -> Result<String, String> {
    let trace = crate::replay::text(name, bytes)?;
    let m = read(name, &trace)?;
    let mut html = String::new();
    let title = format!("Mission {} — {}", escape(&m.name), escape(&m.status));
    let _ = write!(
        html,
        "<!doctype html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>{title}</title><style>{STYLE}</style></head><body>"
    );
    let _ = write!(
        html,
        "<h1>{title}</h1><p class=\"meta\">from <code>{}</code>; {:.1} s of mission time",
        escape(name),
        m.end
    );
    if let Some(reason) = &m.reason {
        let _ = write!(html, "; {}", escape(reason));
    }
    let _ = write!(html, "</p>");

    // The summary.
    let _ = write!(html, "<h2>Summary</h2><table><tr><th>drone</th><th>distance</th><th>in the air</th><th>battery</th><th>at the end</th><th>exceptions</th></tr>");
    for (name, d) in &m.drones {
        let mut distance = 0.0;
        let mut airborne = 0.0;
        for w in d.samples.windows(2) {
            let (a, b) = (w[0].1, w[1].1);
            distance +=
                ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt();
            if w[0].3 {
                airborne += w[1].0 - w[0].0;
            }
        }
        let mut known = d.samples.iter().map(|s| s.2).filter(|b| b.is_finite());
        let battery = match (known.next(), known.next_back()) {
            (Some(a), Some(b)) => format!("{:.0} % → {:.0} %", a * 100.0, b * 100.0),
            (Some(a), None) => format!("{:.0} %", a * 100.0),
            _ => "–".into(),
        };
        let exceptions: Vec<String> =
            d.exceptions.iter().map(|(t, e)| format!("{} at {t:.1} s", escape(e))).collect();
        let _ = write!(
            html,
            "<tr><td>{}</td><td>{distance:.0} m</td><td>{airborne:.0} s</td><td>{battery}</td><td>{}</td><td>{}</td></tr>",
            escape(name),
            escape(&d.last_state),
            if exceptions.is_empty() { "–".into() } else { exceptions.join(", ") }
        );
    }
    let _ = write!(html, "</table><p class=\"note\">Distances and times from the trace's telemetry (or, without it, from where each call ended): a trace recorded with a higher <code>--telemetry-hz</code> gives closer figures.</p>");

    // The map.
    let _ = write!(html, "<h2>Map</h2><div class=\"map\">{}</div>", map(&m, world)?);
    let _ = write!(html, "<p class=\"note\">Tracks per drone; red circles: finds ({}); red crosses: exceptions; grey squares: homes; red outline: the geofence; red, filled: no-fly zones.</p>", m.finds.len());

    // The timeline.
    let end = m.end.max(1.0);
    let _ = write!(html, "<h2>Timeline</h2><div class=\"timeline\">");
    for (block, start, stop) in &m.blocks {
        let stop = stop.unwrap_or(m.end);
        let _ = write!(
            html,
            "<div class=\"lane\"><span class=\"who\">{}</span><span class=\"bar\"><i style=\"left:{:.2}%;width:{:.2}%\"></i></span><span class=\"when\">{start:.0}–{stop:.0} s</span></div>",
            escape(block),
            100.0 * start / end,
            (100.0 * (stop - start) / end).max(0.3)
        );
    }
    let _ = write!(html, "</div><table class=\"events\"><tr><th>t</th><th>what</th></tr>");
    for (t, what, kind) in &m.marks {
        let _ =
            write!(html, "<tr class=\"{kind}\"><td>{t:.1} s</td><td>{}</td></tr>", escape(what));
    }
    let _ = write!(html, "</table>");

    // Per drone.
    let _ = write!(html, "<h2>Drones</h2>");
    for (i, (name, d)) in m.drones.iter().enumerate() {
        let speed = |k: usize| {
            (k > 0).then(|| {
                let (a, b) = (&d.samples[k - 1], &d.samples[k]);
                let dt = b.0 - a.0;
                let dist = ((b.1[0] - a.1[0]).powi(2)
                    + (b.1[1] - a.1[1]).powi(2)
                    + (b.1[2] - a.1[2]).powi(2))
                .sqrt();
                if dt > 0.0 {
                    dist / dt
                } else {
                    0.0
                }
            })
        };
        let altitude = |k: usize| Some(d.samples[k].1[2]);
        let battery = |k: usize| Some(d.samples[k].2 * 100.0).filter(|b| b.is_finite());
        let _ = write!(
            html,
            "<section class=\"drone\"><h3>{}</h3><div class=\"plots\">{}{}{}</div></section>",
            escape(name),
            plot(d, m.end, "altitude", "m", &altitude, i)?,
            plot(d, m.end, "speed", "m/s", &speed, i)?,
            plot(d, m.end, "battery", "%", &battery, i)?,
        );
    }
    html.push_str("</body></html>\n");
    Ok(html)
}

pub(crate) const STYLE: &str = "body{font:14px/1.4 system-ui,sans-serif;color:#1d2330;margin:24px auto;max-width:1000px;padding:0 16px}\
h1{font-size:22px}h2{font-size:17px;margin-top:28px;border-bottom:1px solid #d9dde5}h3{font-size:14px;margin:10px 0 4px}\
table{border-collapse:collapse;font-variant-numeric:tabular-nums}td,th{padding:3px 10px;border-bottom:1px solid #eef0f4;text-align:left}\
.meta,.note{color:#6b7385;font-size:12px}.map svg{max-width:100%;height:auto}\
.timeline .lane{display:flex;gap:8px;align-items:center;font-size:12px}.timeline .who{width:220px;overflow:hidden;text-overflow:ellipsis;white-space:nowrap}\
.timeline .bar{position:relative;flex:1;height:12px;background:#eef1f5}.timeline .bar i{position:absolute;top:1px;bottom:1px;background:#1c64d1}\
.timeline .when{width:90px;text-align:right;color:#6b7385}.events{font-size:12px;margin-top:10px}.events .exception td{color:#c2352b}\
.events .operator td{color:#7b4bc4}.events .find td{color:#1f8a4c}.plots{display:flex;flex-wrap:wrap;gap:6px}\
section.drone{break-inside:avoid}@media print{body{margin:0}h2{break-after:avoid}}";

/// A map's frame around `points` (not empty): equal scales on both axes, at least 10 m
/// across, with a margin of a tenth; `(x0, x1, y0, y1)`.
pub(crate) fn square_frame(points: &[[f64; 2]]) -> (f64, f64, f64, f64) {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in points {
        x0 = x0.min(p[0]);
        x1 = x1.max(p[0]);
        y0 = y0.min(p[1]);
        y1 = y1.max(p[1]);
    }
    let span = (x1 - x0).max(y1 - y0).max(10.0) * 1.1;
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    (cx - span / 2.0, cx + span / 2.0, cy - span / 2.0, cy + span / 2.0)
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_report_and_the_station_map_draw_the_world_lines() {
        let text =
            "[lines]\nPipeline = [[0, 0], [100, 0, 30], [100, 80]]\n[drones.a]\nhome = [0, 0]\n";
        let (world, diags) = aviary_world::parse_world(aviary_diagnostics::FileId(0), text);
        let world = world.unwrap_or_else(|| panic!("{diags:?}"));
        let trace = concat!(
            "{\"t\":0.0,\"event\":\"mission_start\",\"mission\":\"M\"}\n",
            "{\"t\":1.0,\"event\":\"mission_end\",\"status\":\"ok\",\"reason\":null}\n",
        );
        let html = super::render("t.jsonl", trace.as_bytes().to_vec(), Some(&world)).unwrap();
        assert!(html.contains("line: Pipeline"), "{html}");
        let map = crate::checking::map_of(&world);
        assert_eq!(
            map["lines"],
            serde_json::json!([{"name": "Pipeline", "points": [[0.0, 0.0], [100.0, 0.0], [100.0, 80.0]]}])
        );
    }
}
