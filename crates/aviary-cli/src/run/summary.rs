//! What `aviary run` shows as the mission flies and once it has ended: the progress
//! line, and the summary (per drone, the signals, detections and exceptions).

use aviary_api::trace::{Event, Record};
use aviary_api::Backend;
use indicatif::{ProgressBar, ProgressStyle};

pub(super) fn progress_bar(quiet: bool) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar
}

/// What the summary counts, from the trace as it is written.
#[derive(Default)]
pub(super) struct Stats {
    running: i64,
    signals: Vec<(String, usize)>,
    exceptions: Vec<(String, bool)>,
    detections: usize,
    last_shown: f64,
}

impl Stats {
    pub(super) fn observe(
        &mut self,
        record: &Record,
        progress: &ProgressBar,
        backend: &dyn Backend,
        drones: usize,
    ) {
        match &record.event {
            Event::CapabilityStart { .. } => self.running += 1,
            Event::CapabilityEnd { .. } => self.running -= 1,
            Event::Detection { .. } => self.detections += 1,
            Event::Signal { name, .. } => match self.signals.iter_mut().find(|(n, _)| n == name) {
                Some((_, count)) => *count += 1,
                None => self.signals.push((name.to_string(), 1)),
            },
            Event::Exception { name, handled, .. } => {
                self.exceptions.push((name.to_string(), *handled))
            }
            _ => {}
        }
        let t = if record.t.is_finite() { record.t } else { 0.0 };
        let ended = matches!(record.event, Event::MissionEnd { .. });
        if t - self.last_shown >= 1.0 || ended {
            self.last_shown = t;
            let flying = (0..drones).filter(|d| backend.telemetry(*d).state.airborne()).count();
            progress.set_message(format!(
                "t = {t:7.1} s   activities running: {:3}   drones in the air: {flying}",
                self.running
            ));
            progress.tick();
        }
    }
}

pub(super) fn summary(
    mission: &aviary_ir::Mission,
    backend: &dyn Backend,
    odometry: &dyn Fn(usize) -> Option<(f64, f64)>,
    stats: &Stats,
) -> String {
    let mut out = String::new();
    out.push_str(&format!(
        "{:<16} {:>12} {:>12} {:>9}  {}\n",
        "drone", "distance m", "flight s", "battery", "state"
    ));
    for (d, name) in mission.drones.iter().enumerate() {
        let t = backend.telemetry(d);
        let (distance, airborne) = match odometry(d) {
            Some((m, s)) => (format!("{m:.0}"), format!("{s:.0}")),
            None => ("-".to_owned(), "-".to_owned()),
        };
        // A drone without a link is not shown as what it last said (often `Flying`):
        // what it does now is unknown, so the summary says so and where it was last seen.
        let state = if t.link {
            t.state.as_str().to_owned()
        } else {
            let p = t.position;
            format!(
                "no link: last seen {} at ({:.0}, {:.0}, {:.0})",
                t.state.as_str(),
                p[0],
                p[1],
                p[2]
            )
        };
        out.push_str(&format!(
            "{name:<16} {distance:>12} {airborne:>12} {:>8.0}%  {state}\n",
            t.battery * 100.0
        ));
    }
    let signals: Vec<String> = stats
        .signals
        .iter()
        .map(|(n, c)| if *c == 1 { n.clone() } else { format!("{n} ×{c}") })
        .collect();
    out.push_str(&format!(
        "signals: {}\n",
        if signals.is_empty() { "none".to_string() } else { signals.join(", ") }
    ));
    out.push_str(&format!("detections: {}\n", stats.detections));
    let exceptions: Vec<String> = stats
        .exceptions
        .iter()
        .map(|(n, h)| format!("{n} ({})", if *h { "handled" } else { "unhandled" }))
        .collect();
    out.push_str(&format!(
        "exceptions: {}\n",
        if exceptions.is_empty() { "none".to_string() } else { exceptions.join(", ") }
    ));
    out
}
