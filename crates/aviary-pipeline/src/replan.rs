//! A MAVLink drone's figures come from its vehicle. Before anything flies, the plan is made
//! again on the world with each vehicle's own figures (battery, speeds): the battery
//! warnings of that plan are what the operator must see, whether the run was started from
//! the command line (`aviary run`) or from the station. Both show this one [`Replan`].

use aviary_diagnostics::{Code, Diagnostic};
use aviary_mavlink::Facts;
use aviary_world::World;

/// Where one drone's figures came from, and what differs from the world's (as
/// `aviary check --plan --format json` writes it, under `vehicles`).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Figures {
    pub drone: String,
    pub source: String,
    pub differences: Vec<String>,
}

/// A drone whose battery, the plan says with its vehicle's figures, runs out before the
/// mission ends.
pub struct RunsOut {
    pub drone: String,
    /// Of a full battery, in percent: what the mission needs, and what the drone has.
    pub needs: f64,
    pub starts: f64,
}

/// The plan made again with the vehicles' figures.
pub struct Replan {
    pub figures: Vec<Figures>,
    /// The plan's W204 warnings (a reserve under 20 %), pointing into the mission.
    pub low_reserve: Vec<Diagnostic>,
    pub runs_out: Vec<RunsOut>,
}

/// Applies each vehicle's facts to its drone in `world`.
pub fn apply(world: &mut World, facts: &[Facts]) -> Vec<Figures> {
    facts
        .iter()
        .filter_map(|f| {
            let d = world.drones.get_mut(f.drone)?;
            let differences = f.apply(d);
            Some(Figures { drone: f.name.clone(), source: f.source(), differences })
        })
        .collect()
}

/// The plan of `mission` on `world` with the vehicles' `facts` applied.
pub fn replan(mission: &aviary_ir::Mission, world: &World, facts: &[Facts]) -> Replan {
    let mut world = world.clone();
    let figures = apply(&mut world, facts);
    let verification = aviary_verify::verify(mission, &world);
    let low_reserve =
        verification.diagnostics.into_iter().filter(|d| d.code == Code::LowReserve).collect();
    let runs_out = verification
        .plan
        .drones
        .iter()
        .filter(|p| p.battery_left <= 0.0)
        .map(|p| {
            let starts =
                world.drones.iter().find(|d| d.name == p.drone).map_or(100.0, |d| d.battery);
            RunsOut { drone: p.drone.clone(), needs: starts - p.battery_left * 100.0, starts }
        })
        .collect();
    Replan { figures, low_reserve, runs_out }
}

impl RunsOut {
    /// What the operator is told: the drone still flies, and what must bring it home.
    pub fn warning(&self) -> String {
        format!(
            "with its vehicle's figures, the plan says {}'s battery runs out before the mission ends: it needs about {:.0}% of a full battery and starts with {:.0}%. Flying anyway: its BatteryLow and BatteryCritical handlers and the autopilot's battery failsafe must bring it home",
            self.drone, self.needs, self.starts
        )
    }
}
