//! Running the nodes of the IR: blocks, statements and capability instances, API calls,
//! leashes, requirements, FOR and IF.

use std::cell::{Cell, RefCell};
use std::future::Future;
use std::pin::pin;
use std::rc::Rc;
use std::task::Poll;
use std::time::Duration;

use aviary_api::{BuiltinLeash, DroneId, Value};
use aviary_ir::{
    ActorRef, Block, BlockKind, Call, CapId, Expr, For, Leash, LeashAction, Mission, Node,
    SignalId, Slot, Slots, TagId,
};

use crate::cancel::Token as CancellationToken;
use futures_util::future::{Either, LocalBoxFuture};
use futures_util::stream::{FuturesUnordered, StreamExt};
use tokio::sync::Notify;

use crate::arbiter::Claims;
use crate::engine::{Actors, Ctx, Engine, Frame, Instance, Job, Scope};
use crate::jobs::Jobs;
use crate::join::{join_eager, join_in_order, join_woken, SMALL};
use aviary_api::trace::{Event, EventKind, Status};

/// Conditions are looked at again at least this often (docs/LANGUAGE.md, section 7).
pub(crate) const RECHECK: Duration = Duration::from_millis(100);

impl<'m> Engine<'m> {
    /// Runs `items` in `scope`, with the handlers that scope starts, until all are done.
    pub(crate) async fn drive(&self, scope: &Rc<Scope<'m>>, items: impl Future<Output = ()>) {
        // Jobs come only to a scope that declares handlers or exception handlers (signals,
        // exceptions, `SEQUENTIAL ON` starting) or that tops an instance of a capability
        // with leash sections. Any other scope, most of them, just runs its items.
        let takes_sections = scope
            .instance
            .as_ref()
            .is_some_and(|i| !self.m.capabilities[i.capability].sections.is_empty());
        if scope.handlers.is_empty() && scope.exception_handlers.is_empty() && !takes_sections {
            items.await;
            for (target, job) in scope.deferred.take() {
                target.fire(job);
            }
            return;
        }
        let mut items = pin!(items);
        let jobs = &scope.jobs;
        // A job taken and not yet polled. The next job waits in the queue until then: a
        // burst of signals (W's N `Done`s, raised in one poll of its FOR) is started one
        // job at a time, not made N tasks at once.
        let unstarted = Cell::new(false);
        // Made at the first job: most scopes never start a handler, and an empty
        // `FuturesUnordered` still allocates.
        let mut running: Option<FuturesUnordered<_>> = None;
        let mut items_done = false;
        std::future::poll_fn(|cx| loop {
            // A stop from outside is heard here too: a scope that starts handler after
            // handler at one instant never lets the engine wait.
            self.heed_interrupt();
            // Jobs first, then the items, then the handlers running, as a biased select.
            let took_jobs = !unstarted.get();
            if took_jobs {
                if let Poll::Ready(job) = jobs.poll_recv(cx) {
                    unstarted.set(true);
                    running.get_or_insert_with(FuturesUnordered::new).push(self.start_job(
                        job,
                        scope.clone(),
                        &unstarted,
                    ));
                    continue;
                }
            }
            if !items_done && items.as_mut().poll(cx).is_ready() {
                items_done = true;
                // `SEQUENTIAL ON` handlers that waited for this block start now.
                for (target, job) in scope.deferred.take() {
                    target.fire(job);
                }
                continue;
            }
            if let Some(r) = running.as_mut().filter(|r| !r.is_empty()) {
                if let Poll::Ready(Some(())) = r.poll_next_unpin(cx) {
                    continue;
                }
            }
            // The job taken was polled just now: the queue is looked at again.
            if !took_jobs && !unstarted.get() {
                continue;
            }
            // Nothing queued (looked at above), nothing running, the items done: over.
            if items_done && running.as_ref().is_none_or(|r| r.is_empty()) {
                return Poll::Ready(());
            }
            return Poll::Pending;
        })
        .await;
    }

    /// A job as it waits for its first poll: the job itself, not its future (88 bytes,
    /// not a handler's whole future). Its first poll clears `unstarted`.
    async fn start_job(&self, job: Job<'m>, scope: Rc<Scope<'m>>, unstarted: &Cell<bool>) {
        unstarted.set(false);
        Box::pin(self.job(job, scope)).await;
    }

    fn new_scope(
        &self,
        ctx: &Ctx<'m>,
        block: &'m Block,
        instance: Option<Rc<Instance>>,
    ) -> Rc<Scope<'m>> {
        let scope = Rc::new(Scope {
            parent: Some(ctx.scope.clone()),
            path: &block.path,
            mission_block: ctx.instance.is_none() && instance.is_none(),
            handlers: &block.handlers,
            fired: RefCell::new(vec![false; block.handlers.len()]),
            exception_handlers: &block.exception_handlers,
            frame: RefCell::new(ctx.frame.clone()),
            jobs: Jobs::default(),
            unwinding: Cell::new(false),
            deferred: RefCell::new(Vec::new()),
            serial: RefCell::new(Vec::new()),
            catching: Cell::new(0),
            caught: Notify::new(),
            instance,
            section: Cell::new(ctx.scope.section.get()),
            stop: if self.is_stoppable(block) {
                Some(self.mission_level_token(ctx))
            } else {
                ctx.scope.stop.clone()
            },
        });
        if !block.handlers.is_empty() {
            self.listeners.borrow_mut().push(Rc::downgrade(&scope));
        }
        if ctx.scope.parent.is_none() {
            *self.mission_scope.borrow_mut() = Some(scope.clone());
        }
        scope
    }

    pub(crate) fn block<'a>(
        &'a self,
        block: &'m Block,
        ctx: &'a Ctx<'m>,
    ) -> LocalBoxFuture<'a, ()> {
        Box::pin(self.block_with(block, ctx, |_| ()))
    }

    /// A block in a scope of its own. `on_scope` is told the scope first, and what it
    /// gives back is kept while the block runs.
    pub(crate) async fn block_with<T>(
        &self,
        block: &'m Block,
        ctx: &Ctx<'m>,
        on_scope: impl FnOnce(&Rc<Scope<'m>>) -> T,
    ) {
        let scope = self.new_scope(ctx, block, None);
        let _kept = on_scope(&scope);
        if block.traced {
            self.trace(EventKind::BlockStart, || Event::BlockStart {
                block: block.path.as_str().into(),
            });
        }
        // A block that a `Name ABORT` may stop is found by its name while it runs.
        let _listed = self.is_stoppable(block).then(|| Listed::new(self, &scope));
        let inner = Ctx { scope: scope.clone(), ..ctx.clone() };
        // Futures made in place and passed pinned: moving a large future into the
        // next one's state is a copy of all of it, at every step.
        let items = pin!(self.items(block, &inner));
        self.drive(&scope, items).await;
        if block.traced {
            // A block inside a stopped one ends aborted with it.
            let stopped = scope.unwinding.get() || scope.block_stopped();
            let status = if stopped { Status::Aborted } else { Status::Ok };
            self.trace(EventKind::BlockEnd, || Event::BlockEnd {
                block: block.path.as_str().into(),
                status,
            });
        }
    }

    pub(crate) async fn items(&self, block: &'m Block, ctx: &Ctx<'m>) {
        match block.kind {
            BlockKind::Sequential => self.sequence(&block.items, ctx).await,
            BlockKind::Parallel => {
                // Every item starts at this instant: the LETs are taken first, in order,
                // and every branch starts from the frame with their values.
                let mut bound: Option<Ctx<'m>> = None;
                for node in &block.items {
                    if let Node::Let { slot, value, .. } = node {
                        bound = Some(self.bind(*slot, value, bound.as_ref().unwrap_or(ctx)));
                    }
                }
                let ctx = bound.as_ref().unwrap_or(ctx);
                let branches = block.items.iter().map(|n| self.node(n, ctx));
                if block.items.len() <= SMALL {
                    join_in_order(branches).await;
                } else {
                    join_woken(branches).await;
                }
            }
        }
    }

    /// Statements one after another, until the scope unwinds or a block around it is
    /// stopped. A LET gives the items after it a frame with its value.
    pub(crate) async fn sequence(&self, items: &'m [Node], ctx: &Ctx<'m>) {
        let mut bound: Option<Ctx<'m>> = None;
        for node in items {
            let ctx = bound.as_ref().unwrap_or(ctx);
            if ctx.scope.unwinding.get() || ctx.scope.block_stopped() {
                break;
            }
            if let Node::Let { slot, value, .. } = node {
                bound = Some(self.bind(*slot, value, ctx));
                continue;
            }
            // Long runs of statements that end at once (W's steps) never let the engine
            // wait: a stop from outside is looked for before each.
            self.heed_interrupt();
            self.statement(node, ctx).await;
            self.caught(ctx).await;
        }
    }

    /// `LET`: the value taken now, once (a drone's position read now stays what it
    /// was), into `slot` of a new frame for the items after it; the body's handlers
    /// that start from now on start from it too.
    fn bind(&self, slot: Slot, value: &Expr, ctx: &Ctx<'m>) -> Ctx<'m> {
        let value = {
            let received = self.received.borrow();
            self.env(&ctx.frame, &received).eval(value)
        };
        let mut frame = ctx.frame.to_vec();
        set(&mut frame, slot, value);
        let frame: Frame = Rc::from(frame);
        *ctx.scope.frame.borrow_mut() = frame.clone();
        Ctx { frame, ..ctx.clone() }
    }

    /// A handler caught here takes the place of what it aborted: waits for it.
    pub(crate) async fn caught(&self, ctx: &Ctx<'m>) {
        while ctx.scope.catching.get() > 0 {
            let done = ctx.scope.caught.notified();
            if ctx.scope.catching.get() == 0 {
                break;
            }
            done.await;
        }
    }

    /// A statement of a sequence. API calls and signals run inside the sequence's own
    /// future rather than in a box of their own; a capability call's future is far
    /// larger, and every block holding it would be as large.
    async fn statement(&self, node: &'m Node, ctx: &Ctx<'m>) {
        match node {
            Node::Api(a) => {
                if !self.stopped() {
                    self.api(a, ctx).await;
                }
            }
            Node::Signal { signal, args, origin } => {
                if !self.stopped() {
                    self.signal(*signal, args, origin, ctx);
                }
            }
            Node::Call(c) if self.instant[c.capability] => self.instant_statement(c, ctx).await,
            // A wait that is over before it starts (`wait_until` looks first): no box.
            Node::WaitFor { condition, body: None }
                if self.stopped() || self.truth(condition, ctx) => {}
            _ => self.node(node, ctx).await,
        }
    }

    pub(crate) fn node<'a>(&'a self, node: &'m Node, ctx: &'a Ctx<'m>) -> LocalBoxFuture<'a, ()> {
        // Each kind of node is boxed at its own size: with one future type for all, every
        // SIGNAL or API call took the room of a capability instance's future.
        match node {
            // Started when first polled, as every node is.
            Node::Call(c) if self.instant[c.capability] => Box::pin(self.instant_statement(c, ctx)),
            Node::Call(c) => Box::pin(async move {
                if !self.stopped() {
                    self.call(c, ctx).await;
                }
            }),
            Node::Api(a) => Box::pin(async move {
                if !self.stopped() {
                    self.api(a, ctx).await;
                }
            }),
            Node::For(f) => Box::pin(async move {
                if !self.stopped() {
                    self.for_each(f, ctx).await;
                }
            }),
            _ => Box::pin(async move {
                if !self.stopped() {
                    self.other_node(node, ctx).await;
                }
            }),
        }
    }

    /// Blocks, leashes, signals, exceptions, requirements and IF.
    async fn other_node(&self, node: &'m Node, ctx: &Ctx<'m>) {
        {
            match node {
                Node::Block(b) => self.block(b, ctx).await,
                Node::Call(_) | Node::Api(_) | Node::For(_) => {
                    unreachable!("boxed apart in `node`")
                }
                Node::Leash(l) => self.leash(l, ctx),
                // Taken by the sequence or the PARALLEL block that holds it.
                Node::Let { .. } => {}
                Node::StopBlock { block, origin } => self.stop_block(block, origin),
                Node::Signal { signal, args, origin } => self.signal(*signal, args, origin, ctx),
                Node::Throw { exception, args, origin } => {
                    let args = self.eval_all(args, ctx);
                    self.throw(*exception, args, ctx.actor, &ctx.scope, Some(*origin), None);
                }
                Node::StartIf { condition, body } => {
                    if self.truth(condition, ctx) {
                        self.block(body, ctx).await;
                    }
                }
                Node::WaitFor { condition, body } => {
                    self.wait_until(condition, ctx).await;
                    if let Some(b) = body {
                        self.block(b, ctx).await;
                    }
                }
                Node::DoWhile { condition, body } => {
                    while self.truth(condition, ctx)
                        && !ctx.scope.unwinding.get()
                        && !ctx.scope.block_stopped()
                    {
                        let before = self.now();
                        self.block(body, ctx).await;
                        // A round that takes no time must not starve the clock.
                        if self.now() == before {
                            aviary_clock::sleep(RECHECK).await;
                        }
                    }
                }
                Node::Any(a) => self.any(a, ctx).await,
                Node::If { branches, otherwise } => {
                    let chosen = branches
                        .iter()
                        .find(|(c, _)| self.truth(c, ctx))
                        .map(|(_, b)| b)
                        .or(otherwise.as_ref());
                    if let Some(b) = chosen {
                        self.block(b, ctx).await;
                    }
                }
            }
        }
    }

    /// `SIGNAL`: raised by the actor of this place, from its scope.
    fn signal(&self, signal: SignalId, args: &[Expr], origin: &aviary_ir::Origin, ctx: &Ctx<'m>) {
        let args = self.eval_all(args, ctx);
        self.raise(signal, args, ctx.actor, &ctx.scope, Some(origin));
    }

    pub(crate) fn eval_all(&self, exprs: &[Expr], ctx: &Ctx<'m>) -> Vec<Value> {
        let received = self.received.borrow();
        let env = self.env(&ctx.frame, &received);
        exprs.iter().map(|e| env.eval(e)).collect()
    }

    fn truth(&self, e: &Expr, ctx: &Ctx<'m>) -> bool {
        let received = self.received.borrow();
        self.env(&ctx.frame, &received).truth(e)
    }

    /// Until `condition` holds, or a block around the wait is stopped.
    async fn wait_until(&self, condition: &Expr, ctx: &Ctx<'m>) {
        let stopped = async {
            match &ctx.scope.stop {
                Some(token) => token.cancelled().await,
                None => std::future::pending().await,
            }
        };
        let mut stopped = pin!(stopped);
        loop {
            let changed = self.changed.notified();
            if self.truth(condition, ctx) || ctx.scope.block_stopped() {
                return;
            }
            tokio::select! {
                biased;
                _ = stopped.as_mut() => return,
                _ = changed => {}
                _ = aviary_clock::sleep(RECHECK) => {}
            }
        }
    }

    /// The drones an actor reference stands for here: a group is each of its members.
    fn drones(&self, r: &ActorRef, ctx: &Ctx<'m>) -> Vec<DroneId> {
        match r {
            ActorRef::Drone(d) => vec![*d],
            ActorRef::Group(g) => g.clone(),
            ActorRef::Slot(s) => match ctx.frame.slot(*s) {
                Some(Value::Actor(d)) => vec![*d],
                _ => Vec::new(),
            },
        }
    }

    async fn for_each(&self, f: &'m For, ctx: &Ctx<'m>) {
        // Every instance's values are taken when the FOR starts; the frames are made as
        // the instances start (making them has no effect but memory).
        let mut instances = Vec::new();
        for (actor, values) in &f.instances {
            let values = Rc::new(self.eval_all(values, ctx));
            instances.extend(self.drones(actor, ctx).into_iter().map(|d| (d, values.clone())));
        }
        let count = instances.len();
        let runs = instances.into_iter().map(|(d, values)| {
            let mut frame = ctx.frame.to_vec();
            set(&mut frame, f.alias, Value::Actor(d));
            for (slot, v) in f.params.iter().zip(values.iter()) {
                set(&mut frame, *slot, v.clone());
            }
            Ctx { frame: Rc::from(frame), actor: Some(d), ..ctx.clone() }
        });
        let body = &f.body;
        if f.parallel && count <= SMALL {
            let runs: Vec<Ctx<'m>> = runs.collect();
            join_in_order(runs.iter().map(|c| self.block(body, c))).await;
        } else if f.parallel {
            join_eager(runs.map(|c| async move { self.block(body, &c).await })).await;
        } else {
            for c in runs {
                if ctx.scope.unwinding.get() || ctx.scope.block_stopped() {
                    break;
                }
                self.block(body, &c).await;
            }
        }
    }

    /// A statement: one instance, or one per actor when a one-actor capability is given
    /// several (or a group), in parallel.
    pub(crate) async fn call(&self, call: &'m Call, ctx: &Ctx<'m>) {
        let capability = &self.m.capabilities[call.capability];
        let args = self.eval_all(&call.args, ctx);
        // The common case, one actor for a one-actor capability: no join.
        if let ([actor], 1) = (call.actors.as_slice(), capability.actors) {
            match actor {
                ActorRef::Drone(d) => {
                    return self.instance(call, Actors::from_elem(*d, 1), args, ctx).await
                }
                ActorRef::Slot(s) => {
                    if let Some(Value::Actor(d)) = ctx.frame.slot(*s) {
                        self.instance(call, Actors::from_elem(*d, 1), args, ctx).await;
                    }
                    return;
                }
                ActorRef::Group(_) => {}
            }
        }
        let per_actor: Vec<Vec<DroneId>> =
            call.actors.iter().map(|a| self.drones(a, ctx)).collect();
        let sets: Vec<Actors> = if capability.actors == 1 {
            per_actor.into_iter().flatten().map(|d| Actors::from_elem(d, 1)).collect()
        } else {
            vec![per_actor.iter().filter_map(|ds| ds.first().copied()).collect()]
        };
        let instant = self.instant[call.capability];
        let runs = sets.into_iter().map(|actors| match (instant, actors.as_slice()) {
            (true, &[drone]) => {
                let args = args.clone();
                Either::Left(async move {
                    if let Some(rest) = self.instant_instance(call, drone, args, ctx) {
                        rest.await;
                    }
                })
            }
            _ => Either::Right(self.instance(call, actors, args.clone(), ctx)),
        });
        if runs.len() <= SMALL {
            join_in_order(runs).await;
        } else {
            join_eager(runs).await;
        }
    }

    async fn job(&self, job: Job<'m>, scope: Rc<Scope<'m>>) {
        match job {
            Job::Signal { handler, args, actor, signal, entry } => {
                self.heed_interrupt();
                // Nothing new starts once the mission has failed: a firing that waited
                // its turn (`ONE AT A TIME`) is dropped, and lets the next go (dropped too).
                if self.stopped() {
                    scope.firing_ended(handler);
                    return;
                }
                let mut frame = scope.frame.borrow().to_vec();
                for (slot, v) in handler.bindings.iter().zip(args) {
                    set(&mut frame, *slot, v);
                }
                let who = actor.map(|a| self.name(a));
                let signal_name = self.m.signals[signal].as_str();
                self.trace(EventKind::HandlerStart, || Event::HandlerStart {
                    signal: signal_name.into(),
                    handler: handler.body.path.as_str().into(),
                    actor: who.map(Into::into),
                });
                let ctx = self.scope_ctx(&scope, Rc::from(frame));
                // Boxed, as `block` is: the job's future stays small while it waits.
                Box::pin(self.block_with(&handler.body, &ctx, |body| self.enter(body, entry)))
                    .await;
                self.trace(EventKind::HandlerEnd, || Event::HandlerEnd {
                    signal: signal_name.into(),
                    handler: handler.body.path.as_str().into(),
                    actor: who.map(Into::into),
                });
                scope.firing_ended(handler);
            }
            Job::Exception { handler, args, entry } => {
                let mut frame = scope.frame.borrow().to_vec();
                for (slot, v) in handler.bindings.iter().zip(args) {
                    set(&mut frame, *slot, v);
                }
                let ctx = self.scope_ctx(&scope, Rc::from(frame));
                // Boxed, as `block` is: the job's future stays small while it waits.
                Box::pin(self.block_with(&handler.body, &ctx, |body| self.enter(body, entry)))
                    .await;
                scope.catching.set(scope.catching.get().saturating_sub(1));
                scope.caught.notify_waiters();
            }
            Job::Section { block, frame } => {
                let ctx = self.scope_ctx(&scope, frame);
                Box::pin(self.section(block, &ctx)).await;
            }
        }
    }

    /// The context a handler body runs in: inside the scope that declared it.
    fn scope_ctx(&self, scope: &Rc<Scope<'m>>, frame: Frame) -> Ctx<'m> {
        let instance = scope.chain().find_map(|s| s.instance.clone());
        let claims = instance.as_ref().map_or_else(Claims::default, |i| i.claims.borrow().clone());
        let actor = instance.as_ref().and_then(|i| i.actors.first().copied());
        Ctx { scope: scope.clone(), frame, actor, instance, claims }
    }

    fn leash(&self, l: &'m Leash, ctx: &Ctx<'m>) {
        let values: Vec<(usize, Value)> = {
            let received = self.received.borrow();
            let env = self.env(&ctx.frame, &received);
            l.args.iter().map(|(p, e)| (*p, env.eval(e))).collect()
        };
        self.leash_by_id(l.capability, l.tag, l.action, values, Some(&l.origin));
    }

    /// A leash on every running activity of `capability` tagged `tag`; recorded even when
    /// none runs (docs/LANGUAGE.md, section 14).
    pub(crate) fn leash_by_id(
        &self,
        capability: CapId,
        tag: TagId,
        action: LeashAction,
        values: Vec<(usize, Value)>,
        at: Option<&aviary_ir::Origin>,
    ) {
        let cap = &self.m.capabilities[capability];
        self.trace(EventKind::Leash, || Event::Leash {
            capability: cap.name.as_str().into(),
            tag: self.m.tags[tag].as_str().into(),
            // Always a name: the lowering and `Control::Leash` give the capability's own.
            action: cap.action_name(action).unwrap_or_default().into(),
            block: false,
            line: at.and_then(|o| self.m.line_of(o)),
        });
        let targets: Vec<(Rc<Instance>, Rc<Scope<'m>>)> =
            self.instances.borrow().tagged(capability, tag).cloned().collect();
        for (instance, scope) in targets {
            match action {
                LeashAction::Builtin(BuiltinLeash::Abort) => {
                    instance.by_leash.set(true);
                    instance.token.cancel();
                }
                // What else holds it (a drone the operator holds, a section) stays.
                LeashAction::Builtin(pause @ (BuiltinLeash::Pause | BuiltinLeash::Resume)) => {
                    let before = instance.holding();
                    instance.paused.set(pause == BuiltinLeash::Pause);
                    self.rehold(&instance, before);
                }
                LeashAction::Section(i) => {
                    let mut frame = scope.frame.borrow().to_vec();
                    for (p, v) in &values {
                        set(&mut frame, Slot::param(cap.actors, *p), v.clone());
                    }
                    scope
                        .jobs
                        .send(Job::Section { block: &cap.sections[i].1, frame: Rc::from(frame) });
                }
            }
        }
    }
}

impl<'m> Engine<'m> {
    /// Whether some `Name ABORT` names this block (most missions have none).
    fn is_stoppable(&self, block: &Block) -> bool {
        block.traced && !self.stoppable.is_empty() && self.stoppable.contains(&block.path.as_str())
    }

    /// The token of an activity started at mission level here: a child of the innermost
    /// stoppable block's, or of the mission's.
    pub(crate) fn mission_level_token(&self, ctx: &Ctx<'m>) -> CancellationToken {
        ctx.scope.stop.as_ref().unwrap_or(&self.stop).child_token()
    }

    /// `Name ABORT`: every running instance of the block `path` ends at once: its
    /// activities are aborted (as a leash's ABORT aborts one), nothing more in it starts,
    /// and its `block_end` says `aborted`. Recorded as a `leash` event (`block: true`)
    /// even when no instance runs (docs/LANGUAGE.md, section 14).
    fn stop_block(&self, path: &str, at: &aviary_ir::Origin) {
        self.trace(EventKind::Leash, || Event::Leash {
            capability: path.into(),
            tag: "".into(),
            action: BuiltinLeash::Abort.as_str().into(),
            block: true,
            line: self.m.line_of(at),
        });
        let running: Vec<Rc<Scope<'m>>> =
            self.stoppable_running.borrow().iter().filter(|s| s.path == path).cloned().collect();
        for scope in running {
            scope.unwinding.set(true);
            if let Some(token) = &scope.stop {
                token.cancel();
            }
        }
    }
}

/// The paths of the blocks that some `Name ABORT` of the mission names.
pub(crate) fn stoppable_blocks<'m>(m: &'m Mission) -> Vec<&'m str> {
    let mut out: Vec<&str> = Vec::new();
    let mut see = |node: &'m Node| {
        if let Node::StopBlock { block, .. } = node {
            if !out.contains(&block.as_str()) {
                out.push(block.as_str());
            }
        }
    };
    m.body.visit(&mut see);
    for cap in &m.capabilities {
        for body in cap.bodies() {
            body.visit(&mut see);
        }
    }
    out
}

/// A stoppable block's scope listed among the running ones while it runs.
struct Listed<'e, 'm> {
    engine: &'e Engine<'m>,
    scope: Rc<Scope<'m>>,
}

impl<'e, 'm> Listed<'e, 'm> {
    fn new(engine: &'e Engine<'m>, scope: &Rc<Scope<'m>>) -> Self {
        engine.stoppable_running.borrow_mut().push(scope.clone());
        Listed { engine, scope: scope.clone() }
    }
}

impl Drop for Listed<'_, '_> {
    fn drop(&mut self) {
        self.engine.stoppable_running.borrow_mut().retain(|s| !Rc::ptr_eq(s, &self.scope));
    }
}

pub(crate) fn set(frame: &mut Vec<Value>, Slot(slot): Slot, value: Value) {
    if frame.len() <= slot {
        frame.resize(slot + 1, Value::Absent);
    }
    frame[slot] = value;
}
