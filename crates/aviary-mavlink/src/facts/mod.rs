//! Vehicle facts: what a MAVLink vehicle says of itself that the world also says of the
//! drone — its climb and descent, acceleration, landing, return, battery capacity and
//! charge — read with PARAM_REQUEST_READ (by name) and SYS_STATUS/BATTERY_STATUS.
//!
//! The vehicle's figures win: a world written for the simulator (3 m/s down, 30 minutes
//! of battery) would plan a flight the vehicle cannot make. [`Facts::apply`] writes them
//! into the world's drone and says, one line each, what differs; a parameter the vehicle
//! does not answer (or answers with a value the world could not hold) keeps the world's
//! figure, and says so.

mod params;
mod read;
#[cfg(test)]
mod tests;

use std::collections::BTreeMap;

use aviary_api::flight::Descent;
use aviary_world::Drone;
use mavlink::dialects::ardupilotmega::MavParamType;

use crate::mode::Flavour;

pub use params::{decode, table, wanted, Figure, Param, ARDUPILOT, PX4, PX4_ACCELERATION_SHARE};
pub use read::ask;
pub(crate) use read::read;

/// What one vehicle answered.
#[derive(Clone, Debug, PartialEq)]
pub struct Facts {
    /// The drone's index in the world, and its name.
    pub drone: usize,
    pub name: String,
    /// Where it was asked: the world's `mavlink` address and the system id.
    pub address: String,
    pub system: u8,
    /// `None`: the vehicle was not heard; `unheard` says why.
    pub flavour: Option<Flavour>,
    pub unheard: Option<String>,
    /// Each parameter asked, with its answer in the world's unit (`None`: no answer).
    pub answers: Vec<(&'static Param, Option<f64>)>,
    /// Charge in percent (battery_remaining), when the vehicle reports one.
    pub charge: Option<f64>,
}

impl Facts {
    /// A vehicle that could not be asked.
    pub fn unheard(drone: usize, name: &str, address: &str, system: u8, why: String) -> Facts {
        Facts {
            drone,
            name: name.to_owned(),
            address: address.to_owned(),
            system,
            flavour: None,
            unheard: Some(why),
            answers: Vec::new(),
            charge: None,
        }
    }

    /// The facts of a vehicle that answered `params` (PARAM_VALUE's value and type, by
    /// name) and reported `charge` (%), read with its autopilot's table.
    pub fn answered_by(
        drone: usize,
        name: &str,
        address: &str,
        system: u8,
        flavour: Flavour,
        params: &BTreeMap<String, (f32, MavParamType)>,
        charge: Option<f64>,
    ) -> Facts {
        let answers = table(flavour)
            .iter()
            .map(|p| {
                (p, params.get(p.name).map(|(value, ty)| decode(flavour, *value, *ty) * p.scale))
            })
            .collect();
        Facts {
            drone,
            name: name.to_owned(),
            address: address.to_owned(),
            system,
            flavour: Some(flavour),
            unheard: None,
            answers,
            charge,
        }
    }

    fn answer(&self, figure: Figure) -> Option<(&'static Param, f64)> {
        self.answers.iter().find(|(p, _)| p.figure == figure).and_then(|(p, v)| v.map(|v| (*p, v)))
    }

    /// How many of the parameters asked were answered.
    pub fn answered(&self) -> usize {
        self.answers.iter().filter(|(_, v)| v.is_some()).count()
    }

    /// Where the drone's figures come from, in one line.
    pub fn source(&self) -> String {
        let at = format!("{} (system {})", self.address, self.system);
        if let Some(why) = &self.unheard {
            return format!(
                "{}: no answer from {at}: {why}; planned with the world's figures",
                self.name
            );
        }
        let (k, n) = (self.answered(), self.answers.len());
        let charge = self.charge.map(|c| format!(", charge {}%", num(c))).unwrap_or_default();
        match k {
            0 => format!("{}: the vehicle on {at} answered no parameter{charge}: planned with the world's figures", self.name),
            _ if k == n => format!("{}: figures from the vehicle on {at}{charge}", self.name),
            _ => format!("{}: figures from the vehicle on {at}, {k} of {n} parameters answered{charge}", self.name),
        }
    }

    /// Sets the drone's figures from the vehicle's answers; one line per figure that
    /// differs from the world's, per answer it could not use, and for those unanswered.
    pub fn apply(&self, d: &mut Drone) -> Vec<String> {
        let mut lines = Vec::new();
        if self.unheard.is_some() {
            return lines;
        }
        let mut missing = Vec::new();
        for (p, answer) in &self.answers {
            match *answer {
                Some(value) => lines.extend(self.take_answer(p, value, d)),
                None => missing.push((p.name, p.figure.key().0)),
            }
        }
        lines.extend(self.take_charge(d));
        if self.answer(Figure::Capacity).is_some_and(|(_, c)| Figure::Capacity.usable(c)) {
            lines.extend(self.endurance(d));
        }
        if !missing.is_empty() {
            let names: Vec<&str> = missing.iter().map(|m| m.0).collect();
            let keys: Vec<&str> =
                missing.iter().map(|m| m.1).filter(|k| !k.contains(' ')).collect();
            let kept = if keys.is_empty() {
                String::new()
            } else {
                format!(": the world's {} kept", keys.join(", "))
            };
            lines.push(format!("{}: no answer for {}{kept}", self.name, names.join(", ")));
        }
        lines
    }

    /// Sets the figure `p` is for to the vehicle's `value`, when the world can hold it; the
    /// line that says how it differs from the world's, or why it is not used.
    fn take_answer(&self, p: &Param, value: f64, d: &mut Drone) -> Option<String> {
        let name = &self.name;
        let (_, unit) = p.figure.key();
        if !p.figure.usable(value) {
            let raw = value / p.scale;
            return Some(format!(
                "{name}: the vehicle's {} is {} {}, no usable {}: the world's kept",
                p.name,
                num(raw),
                p.unit,
                what(p.figure)
            ));
        }
        let slot = match p.figure {
            Figure::Climb => &mut d.climb_rate,
            Figure::Descent => &mut d.descent_rate,
            Figure::Acceleration => &mut d.acceleration,
            Figure::LandSpeed => &mut d.land_speed,
            Figure::LandSpeedBelow => &mut d.land_speed_below,
            Figure::ReturnAltitude => &mut d.return_altitude,
            Figure::ReturnLoiter => &mut d.return_loiter,
            Figure::TakeoffSpeed => &mut d.takeoff_speed,
            Figure::ReturnSpeed => &mut d.return_speed,
            Figure::LandSpeedHigh => {
                return (value > 0.0).then(|| format!(
                    "{name}: it lands from high at {} {unit} (the vehicle's {}); the world has one descent rate, so the plan lands at {} {unit} and the battery rule at {} {unit}",
                    num(value), p.name, num(d.descent_rate), num(value)
                ));
            }
            Figure::Capacity => {
                let line = match d.battery_capacity {
                    Some(old) if same(old, value) => None,
                    Some(old) => Some(format!(
                        "{name}: battery {} {unit} (the vehicle's {}), not the world's {} {unit}",
                        num(value),
                        p.name,
                        num(old)
                    )),
                    None => Some(format!(
                        "{name}: battery {} {unit} (the vehicle's {}); the world gave none",
                        num(value),
                        p.name
                    )),
                };
                d.battery_capacity = Some(value);
                return line;
            }
        };
        let line = (!same(*slot, value)).then(|| {
            format!(
                "{name}: {} {} {unit} ({} {}), not the world's {} {unit}",
                what(p.figure),
                num(value),
                p.of,
                p.name,
                num(*slot)
            )
        });
        *slot = value;
        line
    }

    /// Sets the drone's charge to the vehicle's; the line that says how it differs, or
    /// that the vehicle reports none.
    fn take_charge(&self, d: &mut Drone) -> Option<String> {
        let name = &self.name;
        match self.charge {
            Some(c) if !same(c, d.battery) => {
                let line = format!(
                    "{name}: charge {}% (the vehicle's battery_remaining), not the world's {}%",
                    num(c),
                    num(d.battery)
                );
                d.battery = c;
                Some(line)
            }
            Some(_) => None,
            None => Some(format!(
                "{name}: the vehicle reports no charge: the world's {}% kept",
                num(d.battery)
            )),
        }
    }

    /// The endurance from the vehicle's capacity and the world's draw (the vehicle has no
    /// parameter for what it draws: that is measured in flight, see `battery`).
    fn endurance(&self, d: &mut Drone) -> Option<String> {
        let name = &self.name;
        let minutes = |s: f64| num(s / 60.0);
        match Drone::endurance_from_battery(d.battery_capacity, d.flight_current) {
            Some(e) if same(e, d.endurance) => None,
            Some(e) => {
                let line = format!(
                    "{name}: endurance {} min ({} mAh at the world's flight_current {} A), not the world's {} min",
                    minutes(e),
                    num(d.battery_capacity.unwrap_or(0.0)),
                    num(d.flight_current.unwrap_or(0.0)),
                    minutes(d.endurance)
                );
                d.endurance = e;
                Some(line)
            }
            None => Some(format!(
                "{name}: the world gives no `flight_current`, so the plan keeps its endurance of {} min (in flight the battery rule uses the current the vehicle measures)",
                minutes(d.endurance)
            )),
        }
    }

    /// How the vehicle lands (the battery rule's descent): the drone's, with
    /// LAND_SPEED_HIGH for the upper part when the vehicle sets one.
    pub fn landing(&self, d: &Drone) -> Descent {
        let mut descent = d.descent();
        if let Some((_, high)) =
            self.answer(Figure::LandSpeedHigh).filter(|(_, v)| *v > 0.0 && v.is_finite())
        {
            descent.rate = high;
        }
        descent
    }
}

fn what(figure: Figure) -> &'static str {
    match figure {
        Figure::Climb => "climb",
        Figure::Descent => "descent",
        Figure::Acceleration => "acceleration",
        Figure::LandSpeed => "landing speed",
        Figure::LandSpeedBelow => "slow landing below",
        Figure::LandSpeedHigh => "landing speed from high",
        Figure::ReturnAltitude => "return altitude",
        Figure::ReturnLoiter => "wait above home",
        Figure::TakeoffSpeed => "take-off speed",
        Figure::ReturnSpeed => "speed home",
        Figure::Capacity => "battery capacity",
    }
}

fn same(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-6 * b.abs().max(1.0)
}

/// A number as people write it: at most two decimals, no trailing zeros.
pub fn num(x: f64) -> String {
    let s = format!("{:.2}", x + 0.0);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}
