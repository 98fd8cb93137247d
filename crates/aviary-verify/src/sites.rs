//! Where each statement sits in the block structure, what it claims, and where each
//! signal can be raised: the facts the conflict analysis compares.
//!
//! A position is the path of steps from the mission body down to the statement. `FOR`
//! bodies are walked once per instance, so an alias always names known drones.
//!
//! `ON EXCEPTION` bodies are walked too, under their block. A capability's body is walked
//! under the statement that calls it when it (or a capability it calls) gives work to a
//! drone that is not one of its own `BY` drones (`carrier Deliver` inside a scout's
//! capability): only such a statement can wait, since the statements of a capability
//! share the claim of the activity that runs them (docs/LANGUAGE.md, section 6). Its
//! named `PERFORM` sections (run by a leash) are not walked.

use std::collections::{BTreeMap, BTreeSet};

use aviary_api::{BuiltinSignal, DroneId, Function, Resource};
use aviary_ir::{
    ActorFilter, ActorRef, Block, BlockKind, Call, CapId, ExceptionId, Expr, Mission, Node, Origin,
    SignalId, Slot, TiSlice, TiVec,
};

/// Which child of a construct a step goes to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Key {
    Item(usize),
    Handler(usize),
    /// An `ON EXCEPTION` of the block (or of a capability's `EXCEPTIONS`).
    Exception(usize),
    /// The body of `STARTIF`, `WAITFOR` or `DOWHILE`.
    Body,
    Branch(usize),
    Instance(usize),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Construct {
    Block(BlockKind),
    If,
    For {
        parallel: bool,
    },
    Wrapper,
    /// A capability's activity, walked under the statement that calls it: its PERFORM
    /// (item 0) and its `EXCEPTIONS`, which cancel the whole PERFORM when they start, so
    /// nothing of the two runs at once.
    Activity,
}

/// One step down: a construct (by id) and which of its children.
pub type Step = (usize, Key);

#[derive(Clone, Debug)]
pub struct HandlerInfo {
    pub signal: SignalId,
    pub every: bool,
    /// `ONE AT A TIME`: its firings never overlap.
    pub one_at_a_time: bool,
    /// The drones its `BY` accepts; `None` without a filter.
    pub by: Option<Vec<DroneId>>,
}

#[derive(Clone, Debug)]
pub struct ExceptionInfo {
    pub exception: ExceptionId,
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
    /// By (block construct id, exception handler index).
    pub exceptions: BTreeMap<(usize, usize), ExceptionInfo>,
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

/// The first step of `path` that enters a handler whose firings may overlap (an `ON
/// EVERY` without `ONE AT A TIME`), with its signal. Two statements under one such step
/// may run in two firings at once, whatever stands between them inside.
pub fn overlapping_firings(sites: &Sites, path: &[Step]) -> Option<(Step, SignalId)> {
    path.iter().find_map(|&(id, key)| {
        let Key::Handler(h) = key else { return None };
        let info = sites.handlers.get(&(id, h))?;
        (info.every && !info.one_at_a_time).then_some(((id, key), info.signal))
    })
}

/// Whether exception handler `e` of block `id` hears only `drone`'s exceptions: every
/// activity of the drone is stopped when it starts (docs/LANGUAGE.md, section 12), so its
/// statements on the drone wait for nothing that ran before.
pub fn stops_the_drone(sites: &Sites, id: usize, e: usize, drone: DroneId) -> bool {
    sites.exceptions.get(&(id, e)).is_some_and(|x| x.by.as_deref() == Some(&[drone]))
}

/// Whether what block `id` runs may go on while one of its `ON EXCEPTION` handlers runs:
/// a PARALLEL block's other branches, a block whose signal handlers may be the thrower,
/// and the mission's body (where a drone's fault comes while it is idle). In a SEQUENTIAL
/// block, the handler takes the place of the item that threw, and the block waits for it.
pub fn goes_on_beside_exceptions(sites: &Sites, id: usize) -> bool {
    id == 0
        || matches!(sites.constructs[id], Construct::Block(BlockKind::Parallel))
        || sites.handlers.range((id, 0)..(id + 1, 0)).next().is_some()
}

/// Whether a statement at `below` (its path below a SEQUENTIAL block's item step) may run
/// beside the chain an exception aborts: under a parallel construct or a handler.
pub fn beside_the_chain(sites: &Sites, below: &[Step]) -> bool {
    below.iter().any(|&(id, key)| {
        matches!(key, Key::Handler(_) | Key::Exception(_))
            || matches!(
                sites.constructs[id],
                Construct::Block(BlockKind::Parallel) | Construct::For { parallel: true }
            )
    })
}

pub fn collect(mission: &Mission) -> Sites {
    let raises = capability_raises(mission);
    let mut walk = Walk {
        mission,
        section_raises: section_raises(mission, &raises),
        raises_of: raises,
        foreign: foreign_capabilities(mission),
        env: vec![Vec::new(); mission.frame_size].into(),
        path: Vec::new(),
        held: Vec::new(),
        inside: Vec::new(),
        out: Sites {
            constructs: Vec::new(),
            handlers: BTreeMap::new(),
            exceptions: BTreeMap::new(),
            claims: Vec::new(),
            raises: Vec::new(),
        },
    };
    walk.block(&mission.body);
    walk.out
}

struct Walk<'m> {
    mission: &'m Mission,
    raises_of: TiVec<CapId, BTreeSet<SignalId>>,
    /// What each capability's named sections raise: raised at the statement that calls
    /// it, since the sections are not walked.
    section_raises: TiVec<CapId, BTreeSet<SignalId>>,
    /// The capabilities whose bodies are walked (see the module's comment).
    foreign: TiVec<CapId, bool>,
    /// The drones each frame slot may hold (FOR aliases; in a capability's body, its
    /// `BY` drones and its parameters that hold drones).
    env: TiVec<Slot, Vec<DroneId>>,
    path: Vec<Step>,
    /// What the activities around the walk hold: their statements share it.
    held: Vec<(DroneId, Resource)>,
    /// The capabilities being walked, outermost first (a recursion is walked once).
    inside: Vec<CapId>,
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
            let by = self.filter(&h.by);
            let info = HandlerInfo {
                signal: h.signal,
                every: h.every,
                one_at_a_time: h.one_at_a_time,
                by,
            };
            self.out.handlers.insert((id, i), info);
            self.under(id, Key::Handler(i), |w| w.block(&h.body));
        }
        self.exception_handlers(id, &block.exception_handlers);
    }

    fn exception_handlers(&mut self, id: usize, handlers: &[aviary_ir::ExceptionHandler]) {
        for (i, h) in handlers.iter().enumerate() {
            let info = ExceptionInfo { exception: h.exception, by: self.filter(&h.by) };
            self.out.exceptions.insert((id, i), info);
            self.under(id, Key::Exception(i), |w| w.block(&h.body));
        }
    }

    fn filter(&self, by: &Option<ActorFilter>) -> Option<Vec<DroneId>> {
        by.as_ref().map(|f| match f {
            ActorFilter::Drones(ds) => ds.clone(),
            ActorFilter::Slot(s) => self.env.get(*s).cloned().unwrap_or_default(),
        })
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
            // The drone an ANY takes, no other ANY holds while its body runs: what the body
            // claims through its alias is compared with nothing (docs/LANGUAGE.md, ANY).
            Node::Any(a) => {
                let id = self.construct(Construct::Wrapper);
                let saved = std::mem::take(&mut self.env[a.alias]);
                self.under(id, Key::Body, |w| w.block(&a.body));
                self.env[a.alias] = saved;
            }
            // Detection raises `Detected` where it is started (docs/LANGUAGE.md, section 16).
            Node::Api(a) if a.function == Function::StartDetection => {
                let signal = self.mission.builtins.signal(BuiltinSignal::Detected);
                self.out.raises.push(RaiseSite { signal, path: self.path.clone() })
            }
            Node::WaitFor { body: None, .. }
            | Node::Leash(_)
            | Node::StopBlock { .. }
            | Node::Api(_)
            | Node::Throw { .. }
            | Node::Let { .. } => {}
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
        // `a b Cap` binds actors to BY slots in order; a one-actor capability given
        // several actors runs once per actor (all of them in its one slot here).
        let slots: Vec<Vec<DroneId>> = match (call.actors.as_slice(), cap.actors) {
            ([ActorRef::Drone(d)], 1) => vec![vec![*d]],
            (_, 1) if call.actors.len() > 1 => {
                vec![call.actors.iter().flat_map(|a| self.drones(a)).collect()]
            }
            _ => call.actors.iter().map(|a| self.drones(a)).collect(),
        };
        let mut claims = Vec::new();
        for &(slot, resource) in &cap.claims {
            for &d in slots.get(slot).into_iter().flatten() {
                // What an activity around holds, this one shares: it waits for nothing.
                if !claims.contains(&(d, resource)) && !self.held.contains(&(d, resource)) {
                    claims.push((d, resource));
                }
            }
        }
        let walked = self.foreign[call.capability] && !self.inside.contains(&call.capability);
        if !claims.is_empty() {
            self.out.claims.push(ClaimSite {
                origin: call.origin,
                path: self.path.clone(),
                claims: claims.clone(),
                capability: call.capability,
            });
        }
        let raises = if walked {
            &self.section_raises[call.capability]
        } else {
            &self.raises_of[call.capability]
        };
        for &signal in raises {
            self.out.raises.push(RaiseSite { signal, path: self.path.clone() });
        }
        if walked {
            self.capability_body(call, slots, claims);
        }
    }

    /// The body of the capability `call` calls, under the call: its PERFORM as item 0 of
    /// a sequential construct (the activity), its `EXCEPTIONS` as that construct's
    /// exception handlers (they take the PERFORM's place).
    fn capability_body(&mut self, call: &Call, slots: Vec<Vec<DroneId>>, claims: Vec<Claim>) {
        let cap = &self.mission.capabilities[call.capability];
        let mut env: TiVec<Slot, Vec<DroneId>> =
            vec![Vec::new(); cap.frame_size.max(cap.actors + cap.params.len())].into();
        for (slot, drones) in slots.into_iter().enumerate().take(cap.actors) {
            env[Slot(slot)] = drones;
        }
        // A parameter given a drone names it inside.
        for (i, arg) in call.args.iter().enumerate() {
            if let (Expr::Actor(r), Some(slot)) = (arg, env.get_mut(Slot::param(cap.actors, i))) {
                *slot = match r {
                    ActorRef::Drone(d) => vec![*d],
                    ActorRef::Group(g) => g.clone(),
                    ActorRef::Slot(s) => self.env.get(*s).cloned().unwrap_or_default(),
                };
            }
        }
        let env = std::mem::replace(&mut self.env, env);
        let held = self.held.len();
        self.held.extend(claims);
        self.inside.push(call.capability);
        let id = self.construct(Construct::Activity);
        self.under(id, Key::Item(0), |w| w.block(&cap.perform));
        self.exception_handlers(id, &cap.exception_handlers);
        self.inside.pop();
        self.held.truncate(held);
        self.env = env;
    }
}

type Claim = (DroneId, Resource);

/// The capabilities whose bodies give work to a drone that is not one of their own `BY`
/// drones, directly or through the capabilities they call.
fn foreign_capabilities(mission: &Mission) -> TiVec<CapId, bool> {
    let caps = &mission.capabilities;
    let mut foreign: TiVec<CapId, bool> = vec![false; caps.len()].into();
    let mut callers: TiVec<CapId, Vec<CapId>> = vec![Vec::new(); caps.len()].into();
    for (i, cap) in caps.iter_enumerated() {
        for block in
            std::iter::once(&cap.perform).chain(cap.exception_handlers.iter().map(|h| &h.body))
        {
            block.visit(&mut |node| {
                if let Node::Call(c) = node {
                    let own = |a: &ActorRef| matches!(a, ActorRef::Slot(s) if s.actor(cap.actors).is_some());
                    if !c.actors.iter().all(own) {
                        foreign[i] = true;
                    }
                    callers[c.capability].push(i);
                }
            });
        }
    }
    let mut pending: Vec<CapId> =
        foreign.iter_enumerated().filter(|(_, f)| **f).map(|(c, _)| c).collect();
    while let Some(callee) = pending.pop() {
        for &caller in &callers[callee] {
            if !foreign[caller] {
                foreign[caller] = true;
                pending.push(caller);
            }
        }
    }
    foreign
}

/// What each capability's named sections raise, through the capabilities they call.
fn section_raises(
    mission: &Mission,
    raises_of: &TiSlice<CapId, BTreeSet<SignalId>>,
) -> TiVec<CapId, BTreeSet<SignalId>> {
    let detected = mission.builtins.signal(BuiltinSignal::Detected);
    mission
        .capabilities
        .iter()
        .map(|cap| {
            let mut raised = BTreeSet::new();
            for (_, block) in &cap.sections {
                block.visit(&mut |node| match node {
                    Node::Signal { signal, .. } => {
                        raised.insert(*signal);
                    }
                    Node::Call(c) => raised.extend(raises_of[c.capability].iter().copied()),
                    Node::Api(a) if a.function == Function::StartDetection => {
                        raised.insert(detected);
                    }
                    // Nothing raised by the node itself: `visit` goes into its bodies.
                    Node::Block(_)
                    | Node::Leash(_)
                    | Node::Api(_)
                    | Node::Throw { .. }
                    | Node::StartIf { .. }
                    | Node::WaitFor { .. }
                    | Node::DoWhile { .. }
                    | Node::For(_)
                    | Node::Any(_)
                    | Node::If { .. }
                    | Node::Let { .. }
                    | Node::StopBlock { .. } => {}
                });
            }
            raised
        })
        .collect()
}

/// The signals each capability can raise while it runs, through the capabilities it
/// calls: its own `SIGNAL`s, and `Detected` when it starts detection.
fn capability_raises(mission: &Mission) -> TiVec<CapId, BTreeSet<SignalId>> {
    let detected = mission.builtins.signal(BuiltinSignal::Detected);
    let mut direct: TiVec<CapId, BTreeSet<SignalId>> = TiVec::new();
    let mut calls: TiVec<CapId, BTreeSet<CapId>> = TiVec::new();
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
                // Nothing raised by the node itself: `visit` goes into its bodies.
                Node::Block(_)
                | Node::Leash(_)
                | Node::Api(_)
                | Node::Throw { .. }
                | Node::StartIf { .. }
                | Node::WaitFor { .. }
                | Node::DoWhile { .. }
                | Node::For(_)
                | Node::Any(_)
                | Node::If { .. }
                | Node::Let { .. }
                | Node::StopBlock { .. } => {}
            });
        }
        direct.push(raised);
        calls.push(called);
    }
    // To a fixpoint, by a worklist: when a capability's signals grow, only its callers
    // take them up, so a chain of N capabilities costs N steps, not N rounds of N.
    let mut callers: TiVec<CapId, Vec<CapId>> = vec![Vec::new(); direct.len()].into();
    for (i, called) in calls.iter_enumerated() {
        for &c in called {
            callers[c].push(i);
        }
    }
    let mut pending: Vec<CapId> =
        direct.iter_enumerated().filter(|(_, d)| !d.is_empty()).map(|(c, _)| c).collect();
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
