//! The names an operator uses, and the ids the engine acts on. Whoever hears the operator
//! (the operator API) resolves a request's names here, once, into a [`Control`] of ids,
//! so the engine never looks a name up. A name the mission does not have is refused here,
//! with what was meant, except where the refusal must say what runs now (a capability or
//! a tag no activity has): that is [`Control::Unknown`], which the engine words.

use aviary_api::{BuiltinLeash, Names, Value};
use aviary_diagnostics::suggest::{closest, did_you_mean};
use aviary_ir::{CapId, LeashAction, Mission, SignalId, TagId, TiVec};

use crate::control::{Control, DroneAction, Unknown};

/// A mission's operator-facing names, copied out of it so that a server can keep them for
/// the whole run.
#[derive(Clone, Debug, Default)]
pub struct Directory {
    capabilities: TiVec<CapId, CapabilityNames>,
    tags: TiVec<TagId, String>,
    signals: TiVec<SignalId, String>,
    /// The signals the mission declares with `OPERATOR SIGNAL`, in the order written.
    operator_signals: Vec<SignalId>,
    drones: Names,
}

#[derive(Clone, Debug)]
struct CapabilityNames {
    name: String,
    params: Vec<String>,
    /// Its `PERFORM` sections, by index ([`LeashAction::Section`]).
    sections: Vec<String>,
}

/// How many of the fleet's names a refusal lists.
const FLEET_SHOWN: usize = 10;

impl Directory {
    pub fn of(m: &Mission) -> Directory {
        let capabilities = m
            .capabilities
            .iter()
            .map(|c| CapabilityNames {
                name: c.name.clone(),
                params: c.params.clone(),
                sections: c.sections.iter().map(|(n, _)| n.clone()).collect(),
            })
            .collect();
        Directory {
            capabilities,
            tags: m.tags.clone(),
            signals: m.signals.clone(),
            operator_signals: m.operator_signals.clone(),
            drones: m.drones.clone(),
        }
    }

    /// The capability called `name`, if the mission has it.
    pub fn capability(&self, name: &str) -> Option<CapId> {
        self.capabilities.position(|c| c.name == name)
    }

    /// The parameter of `capability` called `name`, by its index, or why there is none
    /// (with the parameters it has).
    pub fn param(&self, capability: CapId, name: &str) -> Result<usize, String> {
        let Some(cap) = self.capabilities.get(capability) else {
            return Err(format!("no capability has the id {capability}"));
        };
        cap.params.iter().position(|p| p == name).ok_or_else(|| {
            format!(
                "{} has no parameter `{name}`; its parameters are: {}",
                cap.name,
                cap.params.join(", ")
            )
        })
    }

    /// A leash, `capability-tag action`, with a section's arguments by parameter index
    /// ([`Directory::param`]). An unknown capability or tag is left to the engine to
    /// refuse ([`Control::Unknown`]), since only it knows which activities run; an action
    /// the capability does not have is refused here.
    pub fn leash(
        &self,
        capability: &str,
        tag: &str,
        action: &str,
        args: Vec<(usize, Value)>,
    ) -> Result<Control, String> {
        let Some(cap) = self.capability(capability) else {
            let names = self.capabilities.iter().map(|c| c.name.as_str());
            let meant = did_you_mean(capability, names);
            return Ok(Control::Unknown(Unknown::Capability { name: capability.into(), meant }));
        };
        let names = &self.capabilities[cap];
        let action = match BuiltinLeash::parse(action) {
            Some(builtin) => LeashAction::Builtin(builtin),
            None => match names.sections.iter().position(|n| n == action) {
                Some(section) => LeashAction::Section(section),
                None => {
                    let builtins = BuiltinLeash::ALL.into_iter().map(|a| -> &str { a.as_str() });
                    let meant = did_you_mean(
                        action,
                        builtins.chain(names.sections.iter().map(String::as_str)),
                    );
                    return Err(format!(
                        "{capability} has no section PERFORM {action}{}",
                        spaced(meant)
                    ));
                }
            },
        };
        // A tag no statement defines can never match: the engine refuses it, as the checker
        // would, with the tagged activities that run.
        let Some(tag_id) = self.tags.position(|t| t == tag) else {
            let meant = closest(tag, self.tags.iter().map(String::as_str))
                .map(|t| format!("did you mean `{capability}-{t}`?"));
            return Ok(Control::Unknown(Unknown::Tag {
                capability: capability.into(),
                tag: tag.into(),
                meant,
            }));
        };
        Ok(Control::Leash { capability: cap, tag: tag_id, action, args })
    }

    /// The operator signal called `name`, or why an operator may not raise it: the
    /// mission does not declare it with `OPERATOR SIGNAL` (with the ones it declares, and
    /// the one meant when one is close).
    pub fn operator_signal(&self, name: &str) -> Result<SignalId, String> {
        let ops = &self.operator_signals;
        let named = |&s: &SignalId| self.signals.get(s).map_or("", String::as_str);
        if let Some(&id) = ops.iter().find(|s| named(s) == name) {
            return Ok(id);
        }
        let declared: Vec<&str> = ops.iter().map(named).collect();
        let why = aviary_ir::undeclared_signal(name, &declared);
        Err(match declared.is_empty() {
            true => format!("{why}: it would need `OPERATOR SIGNAL {name}` in its MISSION body"),
            false => why,
        })
    }

    /// The signals an operator may raise, in the order the mission declares them.
    pub fn operator_signals(&self) -> impl Iterator<Item = (SignalId, &str)> {
        self.operator_signals.iter().filter_map(|&s| Some((s, self.signals.get(s)?.as_str())))
    }

    /// Steers the drone called `name`, or why there is none: the name meant, or the fleet.
    pub fn drone(&self, name: &str, action: DroneAction) -> Result<Control, String> {
        let drones = &self.drones;
        if let Some(drone) = drones.position(name) {
            return Ok(Control::Drone { drone, action });
        }
        if let Some(close) = closest(name, drones.iter()) {
            return Err(format!("no drone is called `{name}`: did you mean `{close}`?"));
        }
        let mut fleet: Vec<&str> = drones.iter().take(FLEET_SHOWN).collect();
        if drones.len() > FLEET_SHOWN {
            fleet.push("...");
        }
        Err(format!("no drone is called `{name}`: the fleet is {}", fleet.join(", ")))
    }
}

/// `: did you mean ...?` after a refusal, or nothing.
pub(crate) fn spaced(meant: Option<String>) -> String {
    meant.map(|m| format!(": {m}")).unwrap_or_default()
}
