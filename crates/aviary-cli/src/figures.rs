//! A MAVLink drone's figures come from its vehicle: `aviary check --plan` asks the
//! vehicles before it plans, and `aviary run` plans again with what they answered at
//! connect, before anything flies.

use std::time::Duration;

use aviary_diagnostics::{render_text, Code, SourceMap};
use aviary_mavlink::Facts;
use aviary_world::World;

use crate::files::color_wanted;

/// How long `aviary check --plan` waits for the vehicles, all at once.
pub const ASK_WAIT: Duration = Duration::from_secs(5);

/// Where one drone's figures came from, and what differs from the world's.
pub struct Source {
    pub drone: String,
    pub source: String,
    pub differences: Vec<String>,
}

/// Applies each vehicle's facts to its drone in `world`.
pub fn apply(world: &mut World, facts: &[Facts]) -> Vec<Source> {
    facts
        .iter()
        .filter_map(|f| {
            let d = world.drones.get_mut(f.drone)?;
            let differences = f.apply(d);
            Some(Source { drone: f.name.clone(), source: f.source(), differences })
        })
        .collect()
}

/// Asks the MAVLink drones of `world` for their facts (within [`ASK_WAIT`]) and applies
/// them. A world without MAVLink drones is not asked.
pub fn ask(world: &mut World) -> Result<Vec<Source>, String> {
    if aviary_mavlink::bindings(world).is_empty() {
        return Ok(Vec::new());
    }
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .map_err(|e| format!("cannot start the runtime: {e}"))?;
    let facts = runtime.block_on(aviary_mavlink::facts::ask(world, ASK_WAIT))?;
    Ok(apply(world, &facts))
}

impl Source {
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({ "drone": self.drone, "source": self.source, "differences": self.differences })
    }
}

/// The sources as text: each drone's line, then what differs, indented.
pub fn render(sources: &[Source]) -> String {
    let mut out = String::new();
    for s in sources {
        out.push_str(&format!("  {}\n", s.source));
        for line in &s.differences {
            out.push_str(&format!("    {line}\n"));
        }
    }
    out
}

/// Before a run with MAVLink drones: the plan again, on `world` with the vehicles' facts
/// applied, and its battery warnings (W204) on standard error. A drone whose battery the
/// plan says runs out still flies: the mission's handlers (BatteryLow, BatteryCritical)
/// and the autopilot's failsafe may bring it home, and only the operator knows whether
/// the estimate is too cautious. So it is said loudly, even with `--quiet`, and the
/// operator can stop (Ctrl-C) before take-off. Returns the drones that run out.
pub fn before_flight(
    mission: &aviary_ir::Mission,
    world: &World,
    facts: &[Facts],
    sources: &SourceMap,
    quiet: bool,
) -> Vec<String> {
    let mut world = world.clone();
    let applied = apply(&mut world, facts);
    let verification = aviary_verify::verify(mission, &world);
    if !quiet {
        eprint!("aviary: the MAVLink drones' figures:\n{}", render(&applied));
        for d in verification.diagnostics.iter().filter(|d| d.code == Code::LowReserve) {
            eprint!("{}", render_text(sources, d, color_wanted()));
        }
    }
    let empty: Vec<&aviary_verify::plan::DronePlan> =
        verification.plan.drones.iter().filter(|p| p.battery_left <= 0.0).collect();
    for p in &empty {
        let start = world.drones.iter().find(|d| d.name == p.drone).map_or(100.0, |d| d.battery);
        eprintln!(
            "aviary: WARNING: with its vehicle's figures, the plan says {}'s battery runs out before the mission ends: it needs about {:.0}% of a full battery and starts with {:.0}%. Flying anyway: its BatteryLow and BatteryCritical handlers and the autopilot's battery failsafe must bring it home; Ctrl-C ends the mission and brings the fleet home",
            p.drone,
            start - p.battery_left * 100.0,
            start
        );
    }
    empty.iter().map(|p| p.drone.clone()).collect()
}
