//! `aviary test --html OUT`: a campaign's report (`aviary_campaign::Report`) as one
//! self-contained HTML file, in the style of `aviary report`: the success rate and its
//! interval, the expectations, the outcomes, the distributions, the worst runs, and SVG
//! plots drawn by plotters: the histogram of mission time, each drone's lowest battery,
//! and a map of where the failures happened. No script, nothing loaded from elsewhere.

use std::fmt::Write as _;

use aviary_campaign::stats::Distribution;
use aviary_campaign::Report;
use plotters::prelude::*;

use crate::report::{colour, escape, square_frame, world_layers, Drawn, STYLE};

fn percent(x: f64) -> String {
    format!("{:.1} %", x * 100.0)
}

/// The report as a page.
pub fn render(report: &Report, world: Option<&aviary_world::World>) -> Result<String, String> {
    let f = &report.flew;
    let mut html = String::new();
    let title = format!("Campaign of {}", escape(&f.mission));
    let _ = write!(
        html,
        "<!doctype html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>{title}</title><style>{STYLE}{EXTRA}</style></head><body><h1>{title}</h1>"
    );
    let last = report.seeds.first + (report.seeds.runs - 1);
    let shard = report.shard.map(|s| format!(", shard {s}")).unwrap_or_default();
    let _ = write!(
        html,
        "<p class=\"meta\"><code>{}</code> in <code>{}</code>; seeds {} to {}{shard}: {} runs</p>",
        escape(&f.mission_file),
        escape(&f.world_file),
        report.seeds.first,
        last,
        report.runs
    );
    match report.success_rate {
        Some(rate) => {
            let _ = write!(
                html,
                "<p class=\"rate\">{} of {} runs succeeded: <b>{}</b> (95 % interval {} to {}, Wilson)</p>",
                report.succeeded,
                report.runs,
                percent(rate),
                percent(report.interval95[0]),
                percent(report.interval95[1])
            );
        }
        None => html.push_str("<p class=\"rate\">No runs in this shard.</p>"),
    }
    if !report.expectations.is_empty() {
        html.push_str("<h2>Expectations</h2><table><tr><th>expectation</th><th>met in</th></tr>");
        for m in &report.expectations {
            let _ = write!(
                html,
                "<tr><td>{}</td><td>{} of {} runs</td></tr>",
                escape(&m.expectation),
                m.met,
                report.runs
            );
        }
        html.push_str("</table>");
    }
    html.push_str("<h2>Outcomes</h2><table><tr><th>runs</th><th>outcome</th><th>drone</th><th>statement</th><th>seeds</th></tr>");
    for o in &report.outcomes {
        let seeds: Vec<String> = o.seeds.iter().map(u64::to_string).collect();
        let more = if o.runs as usize > o.seeds.len() { ", …" } else { "" };
        let class = if o.outcome == "ok" { "ok" } else { "bad" };
        let _ = write!(
            html,
            "<tr class=\"{class}\"><td>{}</td><td>{}</td><td>{}</td><td><code>{}</code></td><td>{}{more}</td></tr>",
            o.runs,
            escape(&o.outcome),
            escape(o.drone.as_deref().unwrap_or("–")),
            escape(o.statement.as_deref().unwrap_or("–")),
            seeds.join(", ")
        );
    }
    html.push_str("</table>");

    html.push_str("<h2>Distributions</h2><table><tr><th></th><th>min</th><th>median</th><th>p95</th><th>max</th></tr>");
    let row =
        |html: &mut String, what: &str, d: &Option<Distribution>, shown: &dyn Fn(f64) -> String| {
            let cells = match d {
                Some(d) => [d.min, d.median, d.p95, d.max]
                    .map(|x| format!("<td>{}</td>", shown(x)))
                    .concat(),
                None => "<td colspan=\"4\">–</td>".into(),
            };
            let _ = write!(html, "<tr><td>{}</td>{cells}</tr>", escape(what));
        };
    row(&mut html, "mission time (s)", &report.time, &|x| format!("{x:.1}"));
    for d in &report.lowest_battery {
        row(&mut html, &format!("lowest battery, {}", d.drone), &d.lowest, &percent);
    }
    row(&mut html, &format!("targets found (of {})", f.targets), &report.found, &|x| {
        format!("{x:.0}")
    });
    html.push_str("</table><div class=\"plots\">");
    if let Some(time) = &report.time {
        html.push_str(&histogram(time, "mission time", "s")?);
    }
    if let Some(found) = &report.found {
        html.push_str(&histogram(found, "targets found", "")?);
    }
    html.push_str(&batteries(report)?);
    html.push_str("</div>");

    html.push_str("<h2>Where runs failed</h2>");
    html.push_str(&failures(report, world)?);
    html.push_str("<p class=\"note\">Each cross is a failed run, where its drone was when the exception that failed it was raised; a colour per kind of outcome (the legend). Failures without a drone (a <code>THROW</code> at mission level, a drone that did not come down) are not on the map.</p>");

    if !report.worst.is_empty() {
        html.push_str("<h2>Worst runs</h2><table><tr><th>seed</th><th>outcome</th><th>time</th><th>lowest battery</th><th>fly it again</th></tr>");
        for w in &report.worst {
            let _ = write!(
                html,
                "<tr><td>{}</td><td>{}</td><td>{:.1} s</td><td>{}</td><td><code>{}</code></td></tr>",
                w.seed,
                escape(&w.outcome),
                w.time,
                percent(w.lowest_battery),
                escape(&w.command)
            );
        }
        html.push_str("</table>");
    }
    html.push_str("</body></html>\n");
    Ok(html)
}

const EXTRA: &str = ".rate{font-size:16px}tr.bad td{color:#c2352b}";

/// A histogram of `d`'s bins.
fn histogram(d: &Distribution, title: &str, unit: &str) -> Result<String, String> {
    let top = d.histogram.iter().map(|b| b.runs).max().unwrap_or(1).max(1) as f64 * 1.1;
    let (x0, x1) = match (d.histogram.first(), d.histogram.last()) {
        (Some(a), Some(b)) if b.to > a.from => (a.from, b.to),
        _ => (d.min - 0.5, d.max + 0.5),
    };
    let mut svg = String::new();
    let drawn: Drawn = (|| {
        let root = SVGBackend::with_string(&mut svg, (460, 220)).into_drawing_area();
        root.fill(&WHITE)?;
        let caption = if unit.is_empty() { title.to_owned() } else { format!("{title} ({unit})") };
        let mut chart = ChartBuilder::on(&root)
            .caption(caption, ("sans-serif", 13))
            .margin(8)
            .x_label_area_size(24)
            .y_label_area_size(40)
            .build_cartesian_2d(x0..x1.max(x0 + 1.0), 0.0..top)?;
        chart
            .configure_mesh()
            .x_labels(6)
            .y_labels(5)
            .y_desc("runs")
            .light_line_style(WHITE.mix(0.0))
            .draw()?;
        let single = d.histogram.len() == 1;
        chart.draw_series(d.histogram.iter().map(|b| {
            // A bin of one value (a count, or all runs alike) is drawn one unit wide.
            let (from, to) = if single || b.to <= b.from {
                (b.from - 0.4, b.from + 0.4)
            } else {
                (b.from, b.to)
            };
            Rectangle::new([(from, 0.0), (to, b.runs as f64)], colour(0).mix(0.8).filled())
        }))?;
        root.present()?;
        Ok(())
    })();
    drawn.map_err(|e| format!("cannot draw a histogram: {e}"))?;
    Ok(svg)
}

/// Each drone's lowest battery over the runs: its range (min to max), its median and 95th
/// percentile, one row per drone.
fn batteries(report: &Report) -> Result<String, String> {
    let rows = report.lowest_battery.len().max(1);
    let height = 50 + 30 * rows as u32;
    let mut svg = String::new();
    let drawn: Drawn = (|| {
        let root = SVGBackend::with_string(&mut svg, (460, height)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(
                "lowest battery per drone (%): range, median (dot), p95 (bar)",
                ("sans-serif", 13),
            )
            .margin(8)
            .x_label_area_size(24)
            .y_label_area_size(10)
            .build_cartesian_2d(0.0..100.0, 0.0..rows as f64)?;
        chart.configure_mesh().x_labels(6).y_labels(0).light_line_style(WHITE.mix(0.0)).draw()?;
        for (i, d) in report.lowest_battery.iter().enumerate() {
            let y = rows as f64 - i as f64 - 0.6;
            // The drone's name above its row, at the left.
            chart.draw_series(std::iter::once(Text::new(
                escape(&d.drone),
                (1.0, y + 0.45),
                ("sans-serif", 11).into_font(),
            )))?;
            let Some(l) = &d.lowest else { continue };
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(l.min * 100.0, y), (l.max * 100.0, y)],
                colour(i).stroke_width(3),
            )))?;
            chart.draw_series(std::iter::once(Circle::new(
                (l.median * 100.0, y),
                5,
                colour(i).filled(),
            )))?;
            chart.draw_series(std::iter::once(PathElement::new(
                vec![(l.p95 * 100.0, y - 0.3), (l.p95 * 100.0, y + 0.3)],
                BLACK.stroke_width(2),
            )))?;
        }
        root.present()?;
        Ok(())
    })();
    drawn.map_err(|e| format!("cannot draw the batteries: {e}"))?;
    Ok(svg)
}

/// The map of where runs failed, over the world when it is known.
fn failures(report: &Report, world: Option<&aviary_world::World>) -> Result<String, String> {
    let mut kinds: Vec<String> = Vec::new();
    let mut crosses: Vec<(usize, [f64; 3])> = Vec::new();
    for r in &report.records {
        let Some(p) = r.failure.as_ref().and_then(|f| f.position) else { continue };
        let kind = aviary_campaign::report::outcome_of(r, &report.flew.expectations);
        let i = match kinds.iter().position(|k| *k == kind) {
            Some(i) => i,
            None => {
                kinds.push(kind);
                kinds.len() - 1
            }
        };
        crosses.push((i, p));
    }
    let mut points: Vec<[f64; 2]> = crosses.iter().map(|(_, p)| [p[0], p[1]]).collect();
    if let Some(w) = world {
        points.extend(w.site.geofence.iter().flatten().copied());
        points.extend(w.areas.iter().flat_map(|a| a.polygon.iter().copied()));
        points.extend(w.lines.iter().flat_map(|l| l.ground()));
        points.extend(w.places.iter().map(|p| [p.at[0], p.at[1]]));
        points.extend(w.drones.iter().map(|d| [d.home[0], d.home[1]]));
    }
    if points.is_empty() {
        return Ok("<p>No run failed where a drone was.</p>".into());
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
        for (k, kind) in kinds.iter().enumerate() {
            // Red first, then the palette's other colours.
            let c = colour(k + 4);
            chart
                .draw_series(
                    crosses
                        .iter()
                        .filter(|(i, _)| *i == k)
                        .map(|(_, p)| Cross::new((p[0], p[1]), 5, c.stroke_width(2))),
                )?
                .label(escape(kind))
                .legend(move |(x, y)| Cross::new((x + 8, y), 5, c.stroke_width(2)));
        }
        if !kinds.is_empty() {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK.mix(0.3))
                .position(SeriesLabelPosition::UpperRight)
                .draw()?;
        }
        root.present()?;
        Ok(())
    })();
    drawn.map_err(|e| format!("cannot draw the map of failures: {e}"))?;
    Ok(svg)
}

/// The most runs a campaign started from the page may have: enough for a figure to
/// trust (the interval at 10,000 runs is within a percent), few enough that the station
/// stays the operator's (the command line has no such bound).
pub const MOST_RUNS: u64 = 10_000;

/// A campaign of `runs` seeds from `seed` on the mission and world the page has open,
/// with the files it `USE`s read by `files`, on every core: the report's text and its
/// page. Refused with the reason for a mission that does not fly or a count out of bounds.
pub fn fly(
    mission: &crate::checking::Text,
    world: &crate::checking::Text,
    files: &dyn aviary_check::SourceProvider,
    runs: u64,
    seed: u64,
) -> Result<(String, String), String> {
    use aviary_campaign::report::Flew;
    use aviary_campaign::{Campaign, Seeds};
    use aviary_pipeline::pipeline::{NotFlown, Source, Texts};
    if !(1..=MOST_RUNS).contains(&runs) {
        return Err(format!("a campaign from the station has 1 to {MOST_RUNS} runs, not {runs}"));
    }
    let seeds = Seeds::new(seed, runs)?;
    let texts = Texts {
        mission: Source { name: &mission.path, bytes: mission.text.clone().into_bytes() },
        world: Source { name: &world.path, bytes: world.text.clone().into_bytes() },
        files,
    };
    let campaign = Campaign::prepare(texts).map_err(|e| match e {
        NotFlown::Errors { .. } => "the mission cannot fly: fix the errors the check shows".into(),
        NotFlown::NoMission => format!("{} has no MISSION to run", mission.path),
        NotFlown::Speed => {
            "a campaign flies simulated drones only: the world has MAVLink drones".into()
        }
        NotFlown::Failed(why) => why,
    })?;
    let jobs = std::thread::available_parallelism().map_or(1, |n| n.get());
    let records = campaign.run(&seeds.of(None), jobs, &|_| {})?;
    let report = aviary_campaign::Report::new(Flew::of(&campaign), seeds, None, records);
    let page = render(&report, Some(&campaign.prepared.world))?;
    Ok((report.text(), page))
}
