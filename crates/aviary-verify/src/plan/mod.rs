//! The energy and time plan of `aviary check --plan`: per drone, an estimated timeline of
//! its activities, distance, flight time and battery left at the end, from the world's
//! speeds and endurance. Handlers whose trigger the estimate never sees get a worst-case
//! bound per firing. A reserve under 20% is a W204 at the statement during which it is
//! crossed.

mod estimate;
mod eval;
mod flight;
mod model;
mod radio;
mod state;

use aviary_api::show::fixed;
use aviary_diagnostics::{Code, Diagnostic, FileId, SourceMap, Span};
use aviary_ir::{Block, Handler, Mission, Node, Origin};
use aviary_world::World;
use serde::Serialize;

use estimate::Estimator;

#[derive(Clone, Debug, Serialize)]
pub struct Activity {
    /// Seconds from the mission's start.
    pub start: f64,
    pub end: f64,
    /// The capability (or the mission's closing return).
    pub what: String,
    /// `path:line:col` of the statement, once [`Plan::locate`] has run.
    pub at: Option<String>,
    #[serde(skip)]
    pub origin: Option<Origin>,
}

/// What one firing of a handler whose trigger is unknown adds to a drone, at worst.
#[derive(Clone, Debug, Serialize)]
pub struct Bound {
    pub handler: String,
    pub distance: f64,
    pub flight_time: f64,
    /// Battery left at the end if it fires once, as a fraction.
    pub battery_left: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct DronePlan {
    pub drone: String,
    /// Metres flown, climbs and descents included.
    pub distance: f64,
    /// Seconds in the air.
    pub flight_time: f64,
    /// Battery left at the end, as a fraction.
    pub battery_left: f64,
    pub activities: Vec<Activity>,
    pub worst_case: Vec<Bound>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Assumption {
    pub at: Option<String>,
    pub text: String,
    #[serde(skip)]
    pub origin: Option<(u32, u32)>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Plan {
    /// Seconds until the last drone is down.
    pub mission_time: f64,
    pub drones: Vec<DronePlan>,
    pub assumptions: Vec<Assumption>,
}

/// Each drone's way as the plan flies it (what `aviary check --plan` times): the end of
/// every leg, `[x, y, z]` in the local frame, in order (`aviary export-plan`'s waypoints).
/// A takeoff, a landing or a climb where the drone stands is no leg; a detour around a
/// no-fly zone is a leg per corner.
pub fn waypoints(mission: &Mission, world: &World) -> Vec<Vec<[f64; 3]>> {
    // The legs are kept as for the radio's check.
    let (est, _) = walked(mission, world, true);
    let point = |l: &radio::Leg| [l.to[0], l.to[1], l.z];
    est.s.tracks.iter().map(|legs| legs.iter().map(point).collect()).collect()
}

/// Under this fraction of a full battery, a drone has no reserve left (W204).
const RESERVE: f64 = 0.20;

/// How many walks may pass for `WAITFOR RECEIVED`, and conditions on `RECEIVED`, to learn
/// times raised later in the walk.
const PASSES: usize = 4;

/// The estimator after its walks, each learning from the one before when signals are
/// raised (at most [`PASSES`]), and the end the last one found. `keep_legs`: every leg is
/// kept, as for the radio's check, even without a radio.
fn walked<'m>(mission: &'m Mission, world: &'m World, keep_legs: bool) -> (Estimator<'m>, f64) {
    let new = |known: state::RaiseTimes, sure: state::RaiseTimes| {
        let mut est = Estimator::new(mission, world, known, sure);
        est.radio |= keep_legs;
        est
    };
    let mut known: state::RaiseTimes = vec![None; mission.signals.len()].into();
    let mut est = new(known.clone(), known.clone());
    let mut end = est.run();
    for _ in 1..PASSES {
        if !est.read_known.get() || est.s.raised == known {
            break;
        }
        known = est.s.raised.clone();
        let guessed = est.guessed.get();
        let sure = known.iter().map(|at| at.filter(|&at| at < guessed)).collect();
        est = new(known.clone(), sure);
        end = est.run();
    }
    (est, end)
}

/// Estimates `mission` on `world`; appends a W204 per drone whose reserve falls under 20%.
pub fn estimate(mission: &Mission, world: &World, diagnostics: &mut Vec<Diagnostic>) -> Plan {
    let (mut est, end) = walked(mission, world, false);
    // The activities are moved into the plan, not copied (a long mission has millions);
    // the worst-case walks below go on with empty lists, which the plan does not read.
    let empty = vec![Vec::new(); est.s.activities.len()].into();
    let activities = std::mem::replace(&mut est.s.activities, empty);
    let mut drones: Vec<DronePlan> = world
        .drones
        .iter()
        .zip(&est.s.drones)
        .zip(activities)
        .map(|((w, f), activities)| DronePlan {
            drone: w.name.clone(),
            distance: f.distance,
            flight_time: f.flight_time,
            battery_left: f.battery_at(end),
            activities,
            worst_case: Vec::new(),
        })
        .collect();
    for (d, at) in est.s.reserve.iter_enumerated() {
        // Crossed on the way home after the mission's end: at the drone's last statement.
        let after_end = at.is_none();
        let at = at.or_else(|| {
            (drones[d.0].battery_left < RESERVE)
                .then(|| drones[d.0].activities.iter().rev().find_map(|a| a.origin))
                .flatten()
        });
        if let Some(o) = at {
            let p = &drones[d.0];
            let end = if p.battery_left > 0.0 {
                format!("{}% left at the end", fixed(p.battery_left * 100.0, 0))
            } else {
                // What it uses is what it starts with less what is left.
                let start = est.s.drones[d].battery_start;
                format!(
                    "it runs out before the end: the mission needs {}% of a full battery",
                    fixed((start - p.battery_left) * 100.0, 0)
                )
            };
            diagnostics.push(
                Diagnostic::new(Code::LowReserve, o.file, o.span, format!("{}'s battery is estimated to fall under 20% {} ({end})", p.drone, if after_end { "on its way home after the mission ends; this is its last statement" } else { "during this statement" }))
                    .label("the reserve is crossed here")
                    .with_help("shorten the drone's work or split it with another drone; if the figures are wrong, correct the drone's `battery` and `endurance` (or `battery_capacity` and `flight_current`) in the world file, or for a MAVLink drone its vehicle's battery; `aviary check --plan` shows the estimate and where the figures came from"),
            );
        }
    }
    for h in unfired(&mission.body, &est.s.fired) {
        let label =
            format!("ON {}{}", if h.every { "EVERY " } else { "" }, mission.signals[h.signal]);
        for (d, b) in est.bound(h, end) {
            drones[d.0].worst_case.push(Bound {
                handler: label.clone(),
                distance: b.0,
                flight_time: b.1,
                battery_left: b.2,
            });
        }
    }
    for out in radio::out_of_reach(world, &est.s.tracks.raw) {
        let name = &world.drones[out.drone].name;
        let reach = world.air.radio.as_ref().map_or(0.0, |r| r.range);
        diagnostics.push(
            Diagnostic::new(
                Code::OutOfRadioReach,
                out.at.file,
                out.at.span,
                format!(
                    "{name}'s planned path leaves radio reach during this statement: about {} s in, at ({}, {}), it is {} m from the station (its range is {} m) and out of reach of every relay",
                    fixed(out.t, 0),
                    fixed(out.place[0], 0),
                    fixed(out.place[1], 0),
                    fixed(out.off, 0),
                    fixed(reach, 0)
                ),
            )
            .label("the link is lost here")
            .with_help("in flight the drone loses its link there (ConnectionLost), holds, and flies home on its own after `link_loss_rtl_after`; keep its path within reach, move the station (`[air.radio] station`), or give the fleet a relay that stays in reach of both (`air = { relay = true }` on a drone)"),
        );
    }
    let assumptions = est
        .s
        .notes()
        .into_iter()
        .map(|(o, text)| Assumption { at: None, text: text.clone(), origin: *o })
        .collect();
    Plan { mission_time: end, drones, assumptions }
}

/// The mission-level handlers (not those inside capabilities) that never fired.
fn unfired<'m>(block: &'m Block, fired: &[usize]) -> Vec<&'m Handler> {
    let fired: std::collections::HashSet<usize> = fired.iter().copied().collect();
    let mut out = Vec::new();
    let mut visit = |b: &'m Block| {
        for h in &b.handlers {
            if !fired.contains(&(h as *const Handler as usize)) {
                out.push(h);
            }
        }
    };
    visit(block);
    block.visit(&mut |node| match node {
        Node::Block(b) => visit(b),
        Node::StartIf { body, .. }
        | Node::DoWhile { body, .. }
        | Node::WaitFor { body: Some(body), .. } => visit(body),
        Node::For(f) => visit(&f.body),
        Node::Any(a) => visit(&a.body),
        Node::If { branches, otherwise } => {
            branches.iter().for_each(|(_, b)| visit(b));
            otherwise.iter().for_each(&mut visit);
        }
        Node::Call(_)
        | Node::Leash(_)
        | Node::Api(_)
        | Node::Signal { .. }
        | Node::Throw { .. }
        | Node::WaitFor { body: None, .. }
        | Node::Let { .. }
        | Node::StopBlock { .. } => {}
    });
    out
}

impl Plan {
    /// Fills each `at` with the place of its origin, as the caller names places.
    pub fn locate(&mut self, place: impl Fn(Origin) -> String) {
        for d in &mut self.drones {
            for a in &mut d.activities {
                a.at = a.origin.map(&place);
            }
        }
        for a in &mut self.assumptions {
            a.at = a.origin.map(|(file, start)| {
                place(Origin { file: FileId(file), span: Span::point(start as usize) })
            });
        }
    }

    /// Fills each `at` with `path:line:col` in `sources`, as diagnostics name places.
    pub fn locate_in(&mut self, sources: &SourceMap) {
        self.locate(|o| {
            let at = sources.line_col(o.file, o.span.start);
            format!("{}:{}:{}", sources.name(o.file), at.line, at.column)
        });
    }

    /// The plan as a table per drone, for people.
    pub fn render_text(&self) -> String {
        let mut out =
            format!("plan: the mission takes about {} (estimate)\n", clock(self.mission_time));
        for d in &self.drones {
            out.push_str(&format!(
                "\n{}: {} m, {} in the air, {}% battery left{}\n",
                d.drone,
                fixed(d.distance, 0),
                clock(d.flight_time),
                fixed(d.battery_left * 100.0, 0),
                if d.battery_left < RESERVE { "  (under the 20% reserve)" } else { "" }
            ));
            for a in &d.activities {
                out.push_str(&format!(
                    "  {:>7} – {:>7} s  {}{}\n",
                    fixed(a.start, 1),
                    fixed(a.end, 1),
                    a.what,
                    a.at.as_ref().map(|p| format!("  ({p})")).unwrap_or_default()
                ));
            }
            for b in &d.worst_case {
                out.push_str(&format!(
                    "  worst case per firing of {} (its trigger is unknown before flight): +{} m, +{}, {}% battery left\n",
                    b.handler,
                    fixed(b.distance, 0),
                    clock(b.flight_time),
                    fixed(b.battery_left * 100.0, 0)
                ));
            }
        }
        if !self.assumptions.is_empty() {
            out.push_str("\nassumed:\n");
            for a in &self.assumptions {
                out.push_str(&format!(
                    "  {}{}\n",
                    a.at.as_ref().map(|p| format!("{p}: ")).unwrap_or_default(),
                    a.text
                ));
            }
        }
        out
    }
}

fn clock(seconds: f64) -> String {
    let s = seconds.max(0.0).round() as u64;
    format!("{}:{:02} min", s / 60, s % 60)
}
