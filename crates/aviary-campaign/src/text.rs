//! The report as text, for the terminal (`aviary test`).

use std::fmt::Write as _;

use crate::report::{Outcome, Report};
use crate::stats::Distribution;

fn percent(x: f64) -> String {
    format!("{:.1}%", x * 100.0)
}

fn row(out: &mut String, what: &str, d: &Option<Distribution>, shown: &dyn Fn(f64) -> String) {
    match d {
        Some(d) => {
            let _ = writeln!(
                out,
                "  {what:<34} {:>9} {:>9} {:>9} {:>9}",
                shown(d.min),
                shown(d.median),
                shown(d.p95),
                shown(d.max)
            );
        }
        None => {
            let _ = writeln!(out, "  {what:<34} {:>9}", "-");
        }
    }
}

impl Report {
    /// The report as the terminal shows it.
    pub fn text(&self) -> String {
        let mut out = String::new();
        let f = &self.flew;
        let _ = writeln!(out, "campaign: {} ({}) in {}", f.mission, f.mission_file, f.world_file);
        let last = self.seeds.first + (self.seeds.runs - 1);
        let _ = match self.shard {
            Some(s) => writeln!(
                out,
                "seeds {} to {}, shard {s}: {} runs (run k, from 0, when k mod {} = {})",
                self.seeds.first,
                last,
                self.runs,
                s.count,
                s.index - 1
            ),
            None => writeln!(out, "seeds {} to {}: {} runs", self.seeds.first, last, self.runs),
        };
        let _ = match self.success_rate {
            Some(rate) => writeln!(
                out,
                "success: {} of {} runs ({}), 95% interval {} to {} (Wilson)",
                self.succeeded,
                self.runs,
                percent(rate),
                percent(self.interval95[0]),
                percent(self.interval95[1])
            ),
            None => writeln!(out, "success: no runs in this shard"),
        };
        if !self.expectations.is_empty() {
            let _ = writeln!(out, "\nexpectations ([expect] in {}):", f.world_file);
            for m in &self.expectations {
                let _ =
                    writeln!(out, "  {:<34} met in {} of {} runs", m.expectation, m.met, self.runs);
            }
        }
        let _ = writeln!(out, "\noutcomes:");
        // Columns as wide as their longest entry, so that a long outcome (several
        // expectations not met) does not push the others out of line.
        let width = |min: usize, cell: &dyn Fn(&Outcome) -> usize| {
            self.outcomes.iter().map(cell).fold(min, usize::max)
        };
        let w_outcome = width(7, &|o| o.outcome.chars().count());
        let w_drone = width(5, &|o| o.drone.as_deref().map_or(1, |d| d.chars().count()));
        let w_statement = width(9, &|o| o.statement.as_deref().map_or(1, |s| s.chars().count()));
        let _ = writeln!(
            out,
            "  {:>6}  {:<w_outcome$}  {:<w_drone$}  {:<w_statement$}  seeds",
            "runs", "outcome", "drone", "statement"
        );
        for o in &self.outcomes {
            let seeds: Vec<String> = o.seeds.iter().map(u64::to_string).collect();
            let more = if o.runs as usize > o.seeds.len() { ", ..." } else { "" };
            let _ = writeln!(
                out,
                "  {:>6}  {:<w_outcome$}  {:<w_drone$}  {:<w_statement$}  {}{more}",
                o.runs,
                o.outcome,
                o.drone.as_deref().unwrap_or("-"),
                o.statement.as_deref().unwrap_or("-"),
                seeds.join(", ")
            );
        }
        let _ = writeln!(out, "\ndistributions:");
        let _ =
            writeln!(out, "  {:<34} {:>9} {:>9} {:>9} {:>9}", "", "min", "median", "p95", "max");
        row(&mut out, "mission time (s)", &self.time, &|x| format!("{x:.1}"));
        for d in &self.lowest_battery {
            row(&mut out, &format!("lowest battery, {}", d.drone), &d.lowest, &|x| percent(x));
        }
        row(&mut out, &format!("targets found (of {})", f.targets), &self.found, &|x| {
            format!("{x:.0}")
        });
        if !self.worst.is_empty() {
            let _ = writeln!(out, "\nworst runs (each flies again exactly with its command):");
            for w in &self.worst {
                let _ = writeln!(
                    out,
                    "  seed {}: {}, {:.1} s, lowest battery {}\n    {}",
                    w.seed,
                    w.outcome,
                    w.time,
                    percent(w.lowest_battery),
                    w.command
                );
            }
        }
        out
    }
}
