//! Where each mission-level statement sits in the block structure, what it claims, and
//! where each signal can be raised: the facts the conflict analysis compares.
//!
//! A position is the path of steps from the mission body down to the statement. `FOR`
//! bodies are walked once per instance, so an alias always names known drones.

use std::collections::{BTreeMap, BTreeSet};

use aviary_api::{BuiltinSignal, DroneId, Function, Resource};
use aviary_ir::{
    ActorFilter, ActorRef, Block, BlockKind, Call, CapId, Mission, Node, Origin, SignalId,
};

/// Which child of a construct a step goes to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Key {
    Item(usize),
    Handler(usize),
    /// The body of `STARTIF`, `WAITFOR` or `DOWHILE`.
    Body,
    Branch(usize),
    Instance(usize),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Construct {
    Block(BlockKind),
    If,
    For { parallel: bool },
    Wrapper,
}

/// One step down: a construct (by id) and which of its children.
pub type Step = (usize, Key);

#[derive(Clone, Debug)]
pub struct HandlerInfo {
    pub signal: SignalId,
    pub every: bool,
    /// The drones its `BY` accepts; `None` without a filter.
    pub by: Option<Vec<DroneId>>,
}

/// A statement that claims resources when it starts.
pub struct ClaimSite {
    pub origin: Origin,
    pub path: Vec<Step>,
    pub claims: Vec<(DroneId, Resource)>,
    pub capability: CapId,
}

pub struct RaiseSite {
    pub signal: SignalId,
    pub path: Vec<Step>,
}

pub struct Sites {
    pub constructs: Vec<Construct>,
    /// By (block construct id, handler index).
    pub handlers: BTreeMap<(usize, usize), HandlerInfo>,
    pub claims: Vec<ClaimSite>,
    pub raises: Vec<RaiseSite>,
}

/// Whether the middle layer raises this signal when it likes, not at a statement.
pub fn untimed(mission: &Mission, signal: SignalId) -> bool {
    BuiltinSignal::ALL.into_iter().any(|s| match s {
        BuiltinSignal::BatteryLow | BuiltinSignal::ConnectionRestored => {
            mission.builtins.signal(s) == signal
        }
        // Raised where detection is on: `capability_raises` places it.
        BuiltinSignal::Detected => false,
    })
}

pub fn collect(mission: &Mission) -> Sites {
    let raises = capability_raises(mission);
    let mut walk = Walk {
        mission,
        raises_of: raises,
        env: vec![Vec::new(); mission.frame_size],
        path: Vec::new(),
        out: Sites {
            constructs: Vec::new(),
            handlers: BTreeMap::new(),
            claims: Vec::new(),
            raises: Vec::new(),
        },
    };
    walk.block(&mission.body);
    walk.out
}

struct Walk<'m> {
    mission: &'m Mission,
    raises_of: Vec<BTreeSet<SignalId>>,
    /// The drones each frame slot may hold (FOR aliases).
    env: Vec<Vec<DroneId>>,
    path: Vec<Step>,
    out: Sites,
}

impl Walk<'_> {
    fn construct(&mut self, c: Construct) -> usize {
        self.out.constructs.push(c);
        self.out.constructs.len() - 1
    }

    fn under(&mut self, id: usize, key: Key, f: impl FnOnce(&mut Self)) {
        self.path.push((id, key));
        f(self);
        self.path.pop();
    }

    fn block(&mut self, block: &Block) {
        let id = self.construct(Construct::Block(block.kind));
        for (i, node) in block.items.iter().enumerate() {
            self.under(id, Key::Item(i), |w| w.node(node));
        }
        for (i, h) in block.handlers.iter().enumerate() {
            let by = h.by.as_ref().map(|f| match f {
                ActorFilter::Drones(ds) => ds.clone(),
                ActorFilter::Slot(s) => self.env.get(*s).cloned().unwrap_or_default(),
            });
            self.out.handlers.insert((id, i), HandlerInfo { signal: h.signal, every: h.every, by });
            self.under(id, Key::Handler(i), |w| w.block(&h.body));
        }
        // Exception handlers take the place of what they abort; they are not analysed.
    }

    fn node(&mut self, node: &Node) {
        match node {
            Node::Block(b) => self.block(b),
            Node::Call(call) => self.call(call),
            Node::Signal { signal, .. } => {
                self.out.raises.push(RaiseSite { signal: *signal, path: self.path.clone() })
            }
            Node::StartIf { body, .. }
            | Node::DoWhile { body, .. }
            | Node::WaitFor { body: Some(body), .. } => {
                let id = self.construct(Construct::Wrapper);
                self.under(id, Key::Body, |w| w.block(body));
            }
            Node::If { branches, otherwise } => {
                let id = self.construct(Construct::If);
                for (i, (_, body)) in branches.iter().enumerate() {
                    self.under(id, Key::Branch(i), |w| w.block(body));
                }
                if let Some(body) = otherwise {
                    self.under(id, Key::Branch(branches.len()), |w| w.block(body));
                }
            }
            Node::For(f) => {
                let id = self.construct(Construct::For { parallel: f.parallel });
                for (i, (actor, _)) in f.instances.iter().enumerate() {
                    let drones = self.drones(actor);
                    let saved = std::mem::replace(&mut self.env[f.alias], drones);
                    self.under(id, Key::Instance(i), |w| w.block(&f.body));
                    self.env[f.alias] = saved;
                }
            }
            Node::WaitFor { body: None, .. }
            | Node::Leash(_)
            | Node::Api(_)
            | Node::Throw { .. } => {}
        }
    }

    fn drones(&self, actor: &ActorRef) -> Vec<DroneId> {
        match actor {
            ActorRef::Drone(d) => vec![*d],
            ActorRef::Group(g) => g.clone(),
            ActorRef::Slot(s) => self.env.get(*s).cloned().unwrap_or_default(),
        }
    }

    fn call(&mut self, call: &Call) {
        let cap = &self.mission.capabilities[call.capability];
        // The common case, one drone for a one-actor capability: its claims on slot 0
        // (each once already: the compiler sorts and dedups them).
        if let ([ActorRef::Drone(d)], 1) = (call.actors.as_slice(), cap.actors) {
            let claims =
                cap.claims.iter().filter(|(slot, _)| *slot == 0).map(|&(_, r)| (*d, r)).collect();
            self.out.claims.push(ClaimSite {
                origin: call.origin,
                path: self.path.clone(),
                claims,
                capability: call.capability,
            });
            for &signal in &self.raises_of[call.capability] {
                self.out.raises.push(RaiseSite { signal, path: self.path.clone() });
            }
            return;
        }
        // `a b Cap` binds actors to BY slots in order; a one-actor capability given
        // several actors runs once per actor.
        let slots: Vec<Vec<DroneId>> = if cap.actors == 1 && call.actors.len() > 1 {
            vec![call.actors.iter().flat_map(|a| self.drones(a)).collect()]
        } else {
            call.actors.iter().map(|a| self.drones(a)).collect()
        };
        let mut claims = Vec::new();
        for &(slot, resource) in &cap.claims {
            for &d in slots.get(slot).into_iter().flatten() {
                if !claims.contains(&(d, resource)) {
                    claims.push((d, resource));
                }
            }
        }
        self.out.claims.push(ClaimSite {
            origin: call.origin,
            path: self.path.clone(),
            claims,
            capability: call.capability,
        });
        for &signal in &self.raises_of[call.capability] {
            self.out.raises.push(RaiseSite { signal, path: self.path.clone() });
        }
    }
}

/// The signals each capability can raise while it runs, through the capabilities it
/// calls: its own `SIGNAL`s, and `Detected` when it starts detection.
fn capability_raises(mission: &Mission) -> Vec<BTreeSet<SignalId>> {
    let detected = mission.builtins.signal(BuiltinSignal::Detected);
    let mut direct: Vec<BTreeSet<SignalId>> = Vec::new();
    let mut calls: Vec<BTreeSet<CapId>> = Vec::new();
    for cap in &mission.capabilities {
        let (mut raised, mut called) = (BTreeSet::new(), BTreeSet::new());
        for block in cap.bodies() {
            block.visit(&mut |node| match node {
                Node::Signal { signal, .. } => {
                    raised.insert(*signal);
                }
                Node::Call(c) => {
                    called.insert(c.capability);
                }
                Node::Api(a) if a.function == Function::StartDetection => {
                    raised.insert(detected);
                }
                _ => {}
            });
        }
        direct.push(raised);
        calls.push(called);
    }
    // To a fixpoint, by a worklist: when a capability's signals grow, only its callers
    // take them up, so a chain of N capabilities costs N steps, not N rounds of N.
    let mut callers: Vec<Vec<CapId>> = vec![Vec::new(); direct.len()];
    for (i, called) in calls.iter().enumerate() {
        for &c in called {
            callers[c].push(i);
        }
    }
    let mut pending: Vec<CapId> = (0..direct.len()).filter(|&c| !direct[c].is_empty()).collect();
    while let Some(callee) = pending.pop() {
        for &caller in &callers[callee] {
            if caller == callee {
                continue;
            }
            let before = direct[caller].len();
            let inherited: Vec<SignalId> = direct[callee].iter().copied().collect();
            direct[caller].extend(inherited);
            if direct[caller].len() > before {
                pending.push(caller);
            }
        }
    }
    direct
}
