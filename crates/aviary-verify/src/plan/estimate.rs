//! The estimate: the compiled mission walked once in estimated time, the way the engine
//! would run it, with each drone's flight costed by [`super::model`].
//!
//! Parallel branches are walked one after the other from the same start time; a
//! statement that claims a drone's motion starts no earlier than the drone is free, so
//! queueing follows program order. Handlers run after their block's items, in the order
//! of their signals' times. Detections come from the world's targets (simulation data).

use aviary_api::{DroneId, Place, PlannedCall, Resource, Value};
use aviary_ir::{
    ActorFilter, ActorRef, ApiCall, Block, BlockKind, Call, CapId, Expr, For, Handler, Mission,
    Node, Origin, SignalId, Slot, Slots, TiVec,
};
use aviary_world::World;
use std::cell::RefCell;
use std::rc::Rc;

use super::eval::{Frame, Scope};
use super::model::{first_within, Flyer};
use super::Activity;

#[derive(Clone, Debug)]
pub struct Raise {
    pub t: f64,
    pub signal: SignalId,
    pub actor: Option<DroneId>,
    pub args: Vec<Option<Value>>,
    /// The handler's firing whose body raised it, if any.
    pub from: Option<Rc<Fired>>,
}

/// A firing of a handler in the walk, for the bound the run puts on a cycle of signals
/// at one instant ([`aviary_api::MAX_HANDLER_REENTRIES`]; docs/LANGUAGE.md, section 11):
/// the run fails the mission there, and the walk, which would otherwise follow the cycle
/// for ever, stops following it there too. As the engine's `Entry`, made when it fired.
#[derive(Debug)]
pub struct Fired {
    handler: *const Handler,
    t: f64,
    /// The firing whose body raised this one's signal, if that one fired at this time.
    cause: Option<Rc<Fired>>,
    /// Re-entries per handler among the firings one signal led to at this time.
    counts: Rc<RefCell<Vec<(*const Handler, usize)>>>,
}

impl Fired {
    fn led_from(&self, handler: *const Handler) -> bool {
        std::iter::successors(Some(self), |f| f.cause.as_deref())
            .any(|f| std::ptr::eq(f.handler, handler))
    }

    fn count(&self, handler: *const Handler) -> usize {
        let counts = self.counts.borrow();
        counts.iter().find(|(h, _)| std::ptr::eq(*h, handler)).map_or(0, |(_, n)| *n)
    }

    fn add(&self, handler: *const Handler) {
        let mut counts = self.counts.borrow_mut();
        match counts.iter_mut().find(|(h, _)| std::ptr::eq(*h, handler)) {
            Some((_, n)) => *n += 1,
            None => counts.push((handler, 1)),
        }
    }
}

/// Raises waiting for a block's handlers, taken earliest first and, at one time, in the
/// order they came (a heap: a block that raises N signals costs N log N, not N²).
#[derive(Default)]
struct Pending {
    heap: std::collections::BinaryHeap<std::cmp::Reverse<(Time, usize)>>,
    /// By arrival; taken ones are `None`.
    raises: Vec<Option<Raise>>,
}

/// A time ordered as `f64::total_cmp` orders it.
#[derive(Clone, Copy, PartialEq)]
struct Time(f64);

impl Eq for Time {}

impl PartialOrd for Time {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Time {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

impl Pending {
    fn push(&mut self, r: Raise) {
        self.heap.push(std::cmp::Reverse((Time(r.t), self.raises.len())));
        self.raises.push(Some(r));
    }

    fn pop(&mut self) -> Option<Raise> {
        let std::cmp::Reverse((_, n)) = self.heap.pop()?;
        self.raises[n].take()
    }
}

pub use super::state::{RaiseTimes, State};

/// Where the walk is. One `Ctx` serves a whole walk of the mission body: a FOR instance
/// or a handler sets its slots in place and puts back what they held ([`Estimator::with`]),
/// because the mission's frame has a slot for every alias and binding of the mission, and
/// a copy per instance or per firing would make a long mission's walk quadratic.
struct Ctx {
    frame: Frame,
    /// The signalling actor: of the capability or FOR instance.
    actor: Option<DroneId>,
    /// The mission-level statement running, while inside a capability.
    statement: Option<Origin>,
    /// The handler's firing being walked, if any: what its body raises comes from it.
    firing: Option<Rc<Fired>>,
}

pub struct Estimator<'m> {
    pub mission: &'m Mission,
    pub world: &'m World,
    /// The world's geofence and no-fly zones: transits are costed along their routes.
    pub airspace: aviary_route::Airspace,
    /// First raise times from the previous pass, for `WAITFOR RECEIVED` ahead of its signal.
    pub known: RaiseTimes,
    /// The part of `known` a condition on `RECEIVED` may read ahead of its signal: the
    /// raises of the walk before that came before its first guess ([`Estimator::guessed`]).
    /// A guess (an unknown `WAITFOR` counted as no wait) can only make what follows it
    /// earlier, and a loop ended by so early a raise would be counted short; without a
    /// sure time the loop runs as before, to its worst case.
    pub known_sure: RaiseTimes,
    /// Whether the walk read `known` (a `WAITFOR RECEIVED`, or a condition on `RECEIVED`
    /// ahead of its signal): a walk that did not would be the same again.
    pub read_known: std::cell::Cell<bool>,
    /// When the walk first guessed (an unknown `WAITFOR` counted as no wait, an unknown
    /// `DOWHILE` as one round, a drone read where a branch walked before left it, ahead
    /// of the time read at): its raises from then on are not sure.
    pub guessed: std::cell::Cell<f64>,
    pub s: State,
    /// The capabilities being walked, by index: a flag each, so that a chain of N
    /// capabilities asks N times in O(1), not in O(depth).
    calling: TiVec<CapId, bool>,
    /// Per capability, the actor slots whose motion it claims (asked at every call).
    motion: TiVec<CapId, std::rc::Rc<[usize]>>,
    /// The built-in `Detected` signal, when the mission can hear it.
    detected: SignalId,
    /// Capability calls the walk may still follow ([`call_budget`]), and whether it ran out.
    budget: usize,
    cut_short: bool,
    /// Whether the walk met a cycle of signals at one instant ([`Fired`]).
    cycled: bool,
    /// Whether the world has a radio, so the drones' legs are kept for W210 (`radio`).
    pub radio: bool,
    /// The mission-level statement of the middle-layer call being costed, for its legs.
    pub leg_origin: Option<Origin>,
    /// A mission frame with every slot empty, lent to each walk of [`Estimator::bound`]
    /// and given back as empty as it was lent.
    blank: Frame,
}

/// How many capability calls a walk follows: generous for any mission's size (64 per
/// call written, and a million more), but finite. Each call is walked where it is made,
/// so capabilities that each call the next twice make 2^depth calls: a mission of a few
/// hundred bytes could otherwise keep `aviary check` busy for years.
fn call_budget(mission: &Mission) -> usize {
    let mut written = 0usize;
    let mut count = |n: &Node| written += usize::from(matches!(n, Node::Call(_)));
    mission.body.visit(&mut count);
    for cap in &mission.capabilities {
        for b in cap.bodies() {
            b.visit(&mut count);
        }
    }
    written.saturating_mul(64).saturating_add(1_000_000)
}

/// More rounds than any mission flies: a loop past it is taken as endless.
const MAX_ROUNDS: usize = 10_000;

impl<'m> Estimator<'m> {
    pub fn new(
        mission: &'m Mission,
        world: &'m World,
        known: RaiseTimes,
        known_sure: RaiseTimes,
    ) -> Estimator<'m> {
        let wind = world.air.wind.as_ref();
        let drones: Vec<Flyer> = world.drones.iter().map(|d| Flyer::new(d, wind)).collect();
        Estimator {
            mission,
            world,
            airspace: aviary_route::Airspace::of(world),
            known,
            known_sure,
            read_known: std::cell::Cell::new(false),
            guessed: std::cell::Cell::new(f64::INFINITY),
            calling: vec![false; mission.capabilities.len()].into(),
            motion: mission
                .capabilities
                .iter()
                .map(|cap| {
                    cap.claims
                        .iter()
                        .filter(|(_, r)| *r == Resource::Motion)
                        .map(|(slot, _)| *slot)
                        .collect::<Vec<_>>()
                        .into()
                })
                .collect(),
            detected: mission.builtins.signal(aviary_api::BuiltinSignal::Detected),
            budget: call_budget(mission),
            cut_short: false,
            cycled: false,
            blank: Vec::new(),
            radio: world.air.radio.is_some(),
            leg_origin: None,
            s: State::new(drones.into(), mission.signals.len()),
        }
    }

    /// Walks the mission body, then sends home what is still in the air; the end time.
    pub fn run(&mut self) -> f64 {
        let mut ctx = Ctx {
            frame: vec![None; self.mission.frame_size],
            actor: None,
            statement: None,
            firing: None,
        };
        let (end, _) = self.block(&self.mission.body, &mut ctx, 0.0);
        let mut last = end;
        for d in self.s.drones.keys() {
            if self.s.drones[d].airborne {
                let f = &mut self.s.drones[d];
                let start = end.max(f.free_at);
                let done = start + f.return_home(&self.airspace, self.world.site.max_altitude);
                f.land(done);
                self.s.activities[d].push(Activity {
                    start,
                    end: done,
                    what: "ReturnToLaunch (mission end)".into(),
                    at: None,
                    origin: None,
                });
                last = last.max(done);
            }
        }
        last
    }

    /// What one firing of `h` at `t` would add, per drone it flies: (metres, seconds in
    /// the air, battery left at the end). The state is left as it was.
    pub fn bound(&mut self, h: &Handler, t: f64) -> Vec<(DroneId, (f64, f64, f64))> {
        let mark = self.s.mark();
        let mut blank = std::mem::take(&mut self.blank);
        blank.resize(self.mission.frame_size, None);
        let mut ctx = Ctx { frame: blank, actor: None, statement: None, firing: None };
        let (end, _) = self.block(&h.body, &mut ctx, t);
        self.blank = ctx.frame;
        let mut out = Vec::new();
        for (d, then) in mark.drones().iter_enumerated() {
            let f = &mut self.s.drones[d];
            if f.airborne {
                let took = f.return_home(&self.airspace, self.world.site.max_altitude);
                f.land(end.max(f.free_at) + took);
            }
            let now = &self.s.drones[d];
            if now.distance > then.distance {
                out.push((
                    d,
                    (
                        now.distance - then.distance,
                        now.flight_time - then.flight_time,
                        now.battery_start - now.flight_time / now.endurance,
                    ),
                ));
            }
        }
        self.s.back_keeping_notes(mark);
        out
    }

    pub fn note(&mut self, at: Option<Origin>, text: String) {
        self.s.assumptions.push((at.map(|o| (o.file.0, o.span.start)), text));
    }

    fn scope<'a>(&'a self, ctx: &'a Ctx, t: f64) -> Scope<'a> {
        Scope {
            mission: self.mission,
            frame: &ctx.frame,
            drones: &self.s.drones,
            raised: &self.s.raised,
            known: &self.known_sure,
            read_known: &self.read_known,
            guessed: &self.guessed,
            t,
        }
    }

    /// Walks with `slots` set and `actor` signalling, then puts back what the slots and
    /// the actor were: the frame leaves as it came (in reverse, so a slot written twice
    /// gets its first value back).
    fn with<R>(
        &mut self,
        ctx: &mut Ctx,
        slots: impl IntoIterator<Item = (Slot, Option<Value>)>,
        actor: Option<DroneId>,
        walk: impl FnOnce(&mut Self, &mut Ctx) -> R,
    ) -> R {
        let mut held = Vec::new();
        for (slot, value) in slots {
            if let Some(s) = ctx.frame.slot_mut(slot) {
                held.push((slot, std::mem::replace(s, value)));
            }
        }
        let outer = std::mem::replace(&mut ctx.actor, actor);
        let r = walk(self, ctx);
        ctx.actor = outer;
        for (slot, value) in held.into_iter().rev() {
            if let Some(s) = ctx.frame.slot_mut(slot) {
                *s = value;
            }
        }
        r
    }

    fn block(&mut self, b: &Block, ctx: &mut Ctx, t: f64) -> (f64, Vec<Raise>) {
        let mut raises = Vec::new();
        let mut end = t;
        for node in &b.items {
            let start = if b.kind == BlockKind::Sequential { end } else { t };
            let (e, r) = self.node(node, ctx, start);
            end = if b.kind == BlockKind::Sequential { e } else { end.max(e) };
            raises.extend(r);
        }
        if b.handlers.is_empty() {
            return (end, raises);
        }
        self.handlers(b, ctx, end, raises)
    }

    /// The block's handlers, fired by the raises of its items and by one another. Out of
    /// `block`, which recurses once per nested block and capability call: its frame then
    /// stays small, and a deep chain of calls touches less stack.
    #[inline(never)]
    fn handlers(
        &mut self,
        b: &Block,
        ctx: &mut Ctx,
        items_end: f64,
        raises: Vec<Raise>,
    ) -> (f64, Vec<Raise>) {
        let mut end = items_end;
        let mut once = vec![false; b.handlers.len()];
        // When the last firing of each `ONE AT A TIME` handler ends: the next starts then.
        let mut serial_end = vec![f64::NEG_INFINITY; b.handlers.len()];
        let (mut pending, mut heard) = (Pending::default(), Vec::new());
        for r in raises {
            pending.push(r);
        }
        // The block's handlers by signal, each list in handler order: a raise looks only
        // at its own (matched against them all, N handlers for N signals would cost N²).
        let mut by_signal: std::collections::HashMap<SignalId, Vec<usize>> =
            std::collections::HashMap::new();
        for (hi, h) in b.handlers.iter().enumerate() {
            by_signal.entry(h.signal).or_default().push(hi);
        }
        while let Some(r) = pending.pop() {
            for &hi in by_signal.get(&r.signal).map_or(&[][..], Vec::as_slice) {
                let h = &b.handlers[hi];
                if (!h.every && once[hi]) || !matches(h, &ctx.frame, r.actor) {
                    continue;
                }
                // A firing raised at once by a firing of the same handler (or by one it led
                // to), at the same time: the run allows so many, then fails the mission.
                let cause = r.from.as_ref().filter(|f| f.t == r.t).cloned();
                let again = cause.as_ref().filter(|c| c.led_from(h));
                if let Some(c) = again {
                    if c.count(h) >= aviary_api::MAX_HANDLER_REENTRIES {
                        self.note_cycle(h);
                        continue;
                    }
                    c.add(h);
                }
                once[hi] = true;
                self.s.fired.push(h as *const Handler as usize);
                let bindings = h.bindings.iter().copied().zip(r.args.iter().cloned());
                let mut start = if h.sequential { items_end.max(r.t) } else { r.t };
                if h.one_at_a_time {
                    start = start.max(serial_end[hi]);
                }
                // A firing that starts later than its signal starts a count of its own.
                let cause = cause.filter(|_| start == r.t);
                let counts = cause.as_ref().map_or_else(Rc::default, |c| c.counts.clone());
                let fired = Rc::new(Fired { handler: h, t: start, cause, counts });
                let outer = ctx.firing.replace(fired);
                let (e, more) =
                    self.with(ctx, bindings, ctx.actor, |est, ctx| est.block(&h.body, ctx, start));
                ctx.firing = outer;
                serial_end[hi] = e;
                end = end.max(e);
                for r in more {
                    pending.push(r);
                }
            }
            heard.push(r);
        }
        (end, heard)
    }

    /// Every arm but the plainest is a function of its own, kept out of line: `node` and
    /// `block` recurse once per nested block and capability call, and the locals of every
    /// arm would otherwise sit in each of their frames (a chain of 50,000 calls touched
    /// 70 MB of stack).
    fn node(&mut self, node: &Node, ctx: &mut Ctx, t: f64) -> (f64, Vec<Raise>) {
        match node {
            Node::Block(b) => self.block(b, ctx, t),
            Node::Call(c) => self.call(c, ctx, t),
            Node::Api(a) => self.api(a, ctx, t),
            Node::Signal { signal, args, .. } => self.signal(*signal, args, ctx, t),
            // A stopped block's drones are free at once: the plan cannot know when.
            Node::Leash(_) | Node::StopBlock { .. } | Node::Throw { .. } => (t, Vec::new()),
            Node::StartIf { condition, body } => self.start_if(condition, body, ctx, t),
            Node::WaitFor { condition, body } => {
                let t = self.wait(condition, ctx, t);
                match body {
                    Some(b) => self.block(b, ctx, t),
                    None => (t, Vec::new()),
                }
            }
            Node::DoWhile { condition, body } => self.repeat(condition, body, ctx, t),
            Node::For(f) => self.for_each(f, ctx, t),
            Node::Any(a) => self.any(a, ctx, t),
            Node::If { branches, otherwise } => self.choose(branches, otherwise.as_ref(), ctx, t),
            // Taken when reached, as the engine takes it: unknown before flight (`None`)
            // where what it reads is, as a signal's values are.
            Node::Let { slot, value, .. } => {
                let value = self.scope(ctx, t).eval(value);
                if let Some(s) = ctx.frame.slot_mut(*slot) {
                    *s = value;
                }
                (t, Vec::new())
            }
        }
    }

    #[inline(never)]
    fn signal(
        &mut self,
        signal: SignalId,
        args: &[Expr],
        ctx: &mut Ctx,
        t: f64,
    ) -> (f64, Vec<Raise>) {
        let args = args.iter().map(|e| self.scope(ctx, t).eval(e)).collect();
        self.s.raise(signal, t);
        (t, vec![Raise { t, signal, actor: ctx.actor, args, from: ctx.firing.clone() }])
    }

    #[inline(never)]
    fn start_if(
        &mut self,
        condition: &Expr,
        body: &Block,
        ctx: &mut Ctx,
        t: f64,
    ) -> (f64, Vec<Raise>) {
        match self.scope(ctx, t).condition(condition) {
            Some(false) => (t, Vec::new()),
            known => {
                if known.is_none() {
                    self.note(
                        ctx.statement,
                        "a STARTIF whose condition is unknown before flight is counted as run"
                            .into(),
                    );
                }
                self.block(body, ctx, t)
            }
        }
    }

    #[inline(never)]
    fn for_each(&mut self, f: &For, ctx: &mut Ctx, t: f64) -> (f64, Vec<Raise>) {
        let mut end = t;
        let mut raises = Vec::new();
        for (actor, values) in &f.instances {
            let members = match actor {
                ActorRef::Group(g) => g.clone(),
                a @ (ActorRef::Drone(_) | ActorRef::Slot(_)) => {
                    self.scope(ctx, t).actor(a).into_iter().collect()
                }
            };
            for d in members {
                // The values are read where the FOR stands, before its alias is set.
                let mut slots = vec![(f.alias, Some(Value::Actor(d)))];
                for (slot, v) in f.params.iter().zip(values) {
                    slots.push((*slot, self.scope(ctx, t).eval(v)));
                }
                let start = if f.parallel { t } else { end };
                let (e, r) =
                    self.with(ctx, slots, Some(d), |est, ctx| est.block(&f.body, ctx, start));
                end = end.max(e);
                raises.extend(r);
            }
        }
        (end, raises)
    }

    /// An `ANY`: which drones it takes is known only in flight. The plan counts its body
    /// as flown by the first drones of its group, at once, and says so.
    #[inline(never)]
    fn any(&mut self, a: &aviary_ir::Any, ctx: &mut Ctx, t: f64) -> (f64, Vec<Raise>) {
        self.note(
            ctx.statement,
            format!(
                "an ANY takes its drones in flight; the estimate counts the first {} of {}",
                a.count, a.group
            ),
        );
        let mut end = t;
        let mut raises = Vec::new();
        for &d in a.candidates.iter().take(a.count) {
            let slots = vec![(a.alias, Some(Value::Actor(d)))];
            let (e, r) = self.with(ctx, slots, Some(d), |est, ctx| est.block(&a.body, ctx, t));
            end = end.max(e);
            raises.extend(r);
        }
        (end, raises)
    }

    /// The first branch whose condition holds; when one cannot be decided, the longer of
    /// taking it and not (the worst case).
    fn choose(
        &mut self,
        branches: &[(Expr, Block)],
        otherwise: Option<&Block>,
        ctx: &mut Ctx,
        t: f64,
    ) -> (f64, Vec<Raise>) {
        let Some(((cond, body), rest)) = branches.split_first() else {
            return otherwise.map_or((t, Vec::new()), |b| self.block(b, ctx, t));
        };
        match self.scope(ctx, t).condition(cond) {
            Some(true) => self.block(body, ctx, t),
            Some(false) => self.choose(rest, otherwise, ctx, t),
            None => {
                let mark = self.s.mark();
                let taken = self.block(body, ctx, t);
                let after_taken = self.s.cut(&mark);
                let skipped = self.choose(rest, otherwise, ctx, t);
                if taken.0 > skipped.0 {
                    self.s.redo(&mark, after_taken);
                    return taken;
                }
                skipped
            }
        }
    }

    /// A `DOWHILE`: rounds while its condition holds as far as the estimate knows it. A
    /// condition it cannot decide counts one round; a loop it never sees end is cut where
    /// the fleet's longest flight on a full battery would end, the physical worst case.
    fn repeat(
        &mut self,
        condition: &Expr,
        body: &Block,
        ctx: &mut Ctx,
        t: f64,
    ) -> (f64, Vec<Raise>) {
        let limit = t + self.s.drones.iter().map(|f| f.endurance).fold(0.0, f64::max);
        let (mut now, mut raises) = (t, Vec::new());
        for round in 0..MAX_ROUNDS {
            match self.scope(ctx, now).condition(condition) {
                Some(false) => return (now, raises),
                None => {
                    self.guessed.set(self.guessed.get().min(now));
                    self.note(ctx.statement, "a DOWHILE whose condition is unknown before flight is counted as one round".into());
                    let (e, r) = self.block(body, ctx, now);
                    raises.extend(r);
                    return (e, raises);
                }
                Some(true) if now > limit || (round > 0 && raises.is_empty() && now == t) => break,
                Some(true) => {
                    let (e, r) = self.block(body, ctx, now);
                    raises.extend(r);
                    now = e;
                }
            }
        }
        self.note(ctx.statement, "a DOWHILE that the estimate never sees end is cut where the longest endurance in the fleet runs out (its worst case)".into());
        (now.max(limit), raises)
    }

    fn wait(&mut self, condition: &Expr, ctx: &Ctx, t: f64) -> f64 {
        if let Expr::Received(s) = condition {
            let at = match self.s.raised[*s] {
                Some(at) => Some(at),
                None => {
                    self.read_known.set(true);
                    self.known[*s]
                }
            };
            if let Some(at) = at {
                return t.max(at);
            }
        }
        if self.scope(ctx, t).condition(condition) != Some(true) {
            self.guessed.set(self.guessed.get().min(t));
            let what = match condition {
                Expr::Received(s) => format!("a WAITFOR RECEIVED({}) whose signal the estimate never raises is counted as no wait", self.mission.signals[*s]),
                Expr::Const(_)
                | Expr::Slot(_)
                | Expr::Actor(_)
                | Expr::Telemetry(..)
                | Expr::Attribute(..)
                | Expr::Point(_)
                | Expr::Geo(_)
                | Expr::Distance(..)
                | Expr::Add(..)
                | Expr::Sub(..)
                | Expr::Offset(..)
                | Expr::Midpoint(..)
                | Expr::Elapsed
                | Expr::Not(_)
                | Expr::And(..)
                | Expr::Or(..)
                | Expr::Compare(..) => {
                    "a WAITFOR whose condition is unknown before flight is counted as no wait".into()
                }
            };
            self.note(ctx.statement, what);
        }
        t
    }

    #[inline(never)]
    fn call(&mut self, c: &Call, ctx: &mut Ctx, t: f64) -> (f64, Vec<Raise>) {
        let cap = &self.mission.capabilities[c.capability];
        // A capability that calls itself, directly or not, would never end here.
        if self.calling[c.capability] {
            self.note_calls_itself(c);
            return (t, Vec::new());
        }
        if self.budget == 0 {
            self.note_cut_short(c);
            return (t, Vec::new());
        }
        self.budget -= 1;
        let args = self.values(&c.args, ctx, t);
        // The common case, one drone for a one-actor capability, without the lists of
        // lists the general case builds.
        if let ([a @ (ActorRef::Drone(_) | ActorRef::Slot(_))], 1) =
            (c.actors.as_slice(), cap.actors)
        {
            let Some(d) = self.scope(ctx, t).actor(a) else { return (t, Vec::new()) };
            return self.run_call(c, &[d], &args, ctx, t);
        }
        self.call_on_sets(c, &args, ctx, t)
    }

    #[cold]
    fn note_calls_itself(&mut self, c: &Call) {
        let name = &self.mission.capabilities[c.capability].name;
        let text = format!("`{name}` calls itself; the estimate counts one round of it");
        self.note(Some(c.origin), text);
    }

    #[cold]
    fn note_cycle(&mut self, h: &Handler) {
        if !self.cycled {
            self.cycled = true;
            let text = format!(
                "signals go round in a cycle at one instant ({} is started again {} times without time passing): the run fails the mission there, and the estimate follows the signals no further",
                h.body.path,
                aviary_api::MAX_HANDLER_REENTRIES
            );
            self.note(None, text);
        }
    }

    #[cold]
    fn note_cut_short(&mut self, c: &Call) {
        if !self.cut_short {
            self.cut_short = true;
            self.note(Some(c.origin), "the capability calls fan out past what the estimate follows (64 per call written and a million more); from here on, calls are counted as taking no time".into());
        }
    }

    #[inline(never)]
    fn values(&self, exprs: &[Expr], ctx: &Ctx, t: f64) -> Vec<Option<Value>> {
        exprs.iter().map(|e| self.scope(ctx, t).eval(e)).collect()
    }

    /// A call on groups, or on several actors: one run per drone of a one-actor capability,
    /// else one run on the first drone of each actor. Out of `call`, whose frame is on the
    /// stack once per level of a chain of calls.
    #[inline(never)]
    fn call_on_sets(
        &mut self,
        c: &Call,
        args: &[Option<Value>],
        ctx: &mut Ctx,
        t: f64,
    ) -> (f64, Vec<Raise>) {
        let cap = &self.mission.capabilities[c.capability];
        let sets: Vec<Vec<DroneId>> = c
            .actors
            .iter()
            .map(|a| match a {
                ActorRef::Group(g) => g.clone(),
                a @ (ActorRef::Drone(_) | ActorRef::Slot(_)) => {
                    self.scope(ctx, t).actor(a).into_iter().collect()
                }
            })
            .collect();
        let runs: Vec<Vec<DroneId>> = if cap.actors == 1 {
            sets.concat().into_iter().map(|d| vec![d]).collect()
        } else {
            vec![sets.iter().filter_map(|s| s.first().copied()).collect()]
        };
        let (mut end, mut raises) = (t, Vec::new());
        for actors in runs {
            let (e, r) = self.run_call(c, &actors, args, ctx, t);
            end = end.max(e);
            raises.extend(r);
        }
        (end, raises)
    }

    /// One run of a called capability on `actors`.
    fn run_call(
        &mut self,
        c: &Call,
        actors: &[DroneId],
        args: &[Option<Value>],
        ctx: &Ctx,
        t: f64,
    ) -> (f64, Vec<Raise>) {
        let cap = &self.mission.capabilities[c.capability];
        let top = ctx.statement.is_none();
        let motion = self.motion[c.capability].clone();
        let (mut end, mut raises) = (t, Vec::new());
        {
            let mut start = t;
            if top {
                for &slot in motion.iter() {
                    if let Some(&d) = actors.get(slot) {
                        start = start.max(self.s.drones[d].free_at);
                    }
                }
            }
            let mut frame = vec![None; cap.frame_size];
            for (slot, v) in frame
                .iter_mut()
                .zip(actors.iter().map(|d| Some(Value::Actor(*d))).chain(args.iter().cloned()))
            {
                *slot = v;
            }
            let mut cctx = Ctx {
                frame,
                actor: actors.first().copied(),
                statement: Some(ctx.statement.unwrap_or(c.origin)),
                firing: ctx.firing.clone(),
            };
            self.calling[c.capability] = true;
            let (e, r) = self.block(&cap.perform, &mut cctx, start);
            self.calling[c.capability] = false;
            if top {
                self.ran_at_top(c, actors, &motion, start, e);
            }
            end = end.max(e);
            raises.extend(r);
        }
        (end, raises)
    }

    /// A top-level call that ran from `start` to `end`: its drones are busy until then, and
    /// it is one activity of each.
    #[inline(never)]
    fn ran_at_top(&mut self, c: &Call, actors: &[DroneId], motion: &[usize], start: f64, end: f64) {
        for &slot in motion {
            if let Some(&d) = actors.get(slot) {
                self.s.drones[d].free_at = self.s.drones[d].free_at.max(end);
            }
        }
        let what = &self.mission.capabilities[c.capability].name;
        for &d in actors {
            self.s.activities[d].push(Activity {
                start,
                end,
                what: what.clone(),
                at: None,
                origin: Some(c.origin),
            });
        }
    }

    #[inline(never)]
    fn api(&mut self, a: &ApiCall, ctx: &Ctx, t: f64) -> (f64, Vec<Raise>) {
        let Some(d) = self.scope(ctx, t).actor(&a.actor) else { return (t, Vec::new()) };
        let args: Vec<Option<Value>> = a.args.iter().map(|e| self.scope(ctx, t).eval(e)).collect();
        // The checker holds a call to its signature's count of arguments: one it refused
        // takes no time here.
        let Ok(call) = PlannedCall::new(a.function, &args) else { return (t, Vec::new()) };
        let (duration, raises) = super::flight::fly(self, d, &call, ctx.statement, t);
        let end = t + duration;
        let f = &self.s.drones[d];
        if f.battery_at(end) < super::RESERVE && self.s.reserve[d].is_none() {
            self.s.reserve[d] = ctx.statement;
        }
        (end, raises)
    }

    /// Targets of the kinds `d` detects that its ground track `from`→`to`, flown during
    /// `[t, t + duration]`, comes within range of: each is a `Detected` at that moment.
    pub fn scan(
        &mut self,
        d: DroneId,
        from: [f64; 2],
        to: [f64; 2],
        t: f64,
        duration: f64,
    ) -> Vec<Raise> {
        let detected = self.detected;
        let mut out = Vec::new();
        for (kind, range, found) in self.s.drones[d].detecting.iter_mut() {
            for (i, target) in self.world.targets.iter().enumerate() {
                if target.kind != *kind || found.contains(&i) {
                    continue;
                }
                if let Some(s) = first_within(from, to, [target.at[0], target.at[1]], *range) {
                    found.push(i);
                    let location =
                        aviary_api::Point { x: target.at[0], y: target.at[1], z: Some(0.0) };
                    out.push(Raise {
                        t: t + s * duration,
                        signal: detected,
                        actor: Some(d),
                        args: vec![
                            Some(Value::Symbol(kind.clone())),
                            Some(Value::Position(location)),
                        ],
                        from: None,
                    });
                }
            }
        }
        out
    }

    /// Where a position argument takes drone `d`: a position (at the drone's altitude
    /// when it gives none), an area's centroid, or, known only in flight (`None`), the
    /// worst case.
    pub fn position_arg(
        &mut self,
        place: Option<&Place>,
        d: DroneId,
        at: Option<Origin>,
    ) -> Option<[f64; 3]> {
        match place {
            Some(Place::Point(p)) => Some([p.x, p.y, p.z.unwrap_or(self.s.drones[d].pos[2])]),
            Some(Place::Area(polygon)) => {
                let c = aviary_api::centroid(polygon);
                Some([c[0], c[1], self.s.drones[d].pos[2]])
            }
            None => {
                // Unknown before flight: the farthest corner of the geofence is the worst case.
                let here = self.s.drones[d].pos;
                let far = self.world.site.geofence.as_ref().and_then(|fence| {
                    fence.iter().copied().max_by(|p, q| dist2(*p, here).total_cmp(&dist2(*q, here)))
                });
                self.note(at, match far {
                    Some(_) => "a position known only in flight is taken as the geofence corner farthest from the drone".into(),
                    None => "a position known only in flight is not counted: the site has no geofence to bound it".into(),
                });
                far.map(|p| [p[0], p[1], here[2]])
            }
        }
    }
}

fn dist2(p: [f64; 2], q: [f64; 3]) -> f64 {
    (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)
}

fn matches(h: &Handler, frame: &Frame, actor: Option<DroneId>) -> bool {
    match &h.by {
        None => true,
        Some(ActorFilter::Drones(ds)) => actor.is_some_and(|a| ds.contains(&a)),
        Some(ActorFilter::Slot(s)) => {
            matches!((frame.slot(*s), actor), (Some(Some(Value::Actor(d))), Some(a)) if *d == a)
        }
    }
}
