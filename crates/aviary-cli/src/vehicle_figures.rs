//! A MAVLink drone's figures come from its vehicle: `aviary check --plan` asks the
//! vehicles before it plans, and `aviary run` plans again with what they answered at
//! connect, before anything flies.

use std::time::Duration;

use aviary_diagnostics::{render_text, SourceMap};
use aviary_world::World;

use crate::files::color_wanted;

/// How long `aviary check --plan` waits for the vehicles, all at once.
pub const ASK_WAIT: Duration = Duration::from_secs(5);

pub use aviary_pipeline::replan::{apply, Figures as Source};

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

/// Before a run with MAVLink drones: the plan made again with the vehicles' facts
/// (`aviary_pipeline::replan`, as the station shows it), and its battery warnings (W204)
/// on standard error. A drone whose battery the plan says runs out still flies: the
/// mission's handlers (BatteryLow, BatteryCritical) and the autopilot's failsafe may bring
/// it home, and only the operator knows whether the estimate is too cautious. So it is
/// said loudly, even with `--quiet`, and the operator can stop (Ctrl-C) before take-off.
/// Returns the drones that run out.
pub fn before_flight(
    replan: &aviary_pipeline::replan::Replan,
    sources: &SourceMap,
    quiet: bool,
) -> Vec<String> {
    if !quiet {
        eprint!("aviary: the MAVLink drones' figures:\n{}", render(&replan.figures));
        for d in &replan.low_reserve {
            eprint!("{}", render_text(sources, d, color_wanted()));
        }
    }
    for r in &replan.runs_out {
        eprintln!(
            "aviary: WARNING: {}; Ctrl-C ends the mission and brings the fleet home",
            r.warning()
        );
    }
    replan.runs_out.iter().map(|r| r.drone.clone()).collect()
}
