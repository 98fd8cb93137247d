//! Running the nodes of the IR: blocks, statements and capability instances, API calls,
//! leashes, requirements, FOR and IF.

use std::cell::{Cell, RefCell};
use std::future::Future;
use std::pin::pin;
use std::rc::Rc;
use std::time::Duration;

use aviary_api::{CallEnd, DroneId, Ending, Interrupt, Value};
use aviary_ir::{ActorRef, Block, BlockKind, Call, Expr, For, Leash, LeashAction, Node};
use futures_util::future::{join_all, LocalBoxFuture};
use futures_util::stream::{FuturesUnordered, StreamExt};
use smallvec::SmallVec;
use serde_json::{json, Map, Value as Json};
use tokio::sync::Notify;
use crate::cancel::Token as CancellationToken;

use crate::arbiter::{acquire, try_acquire, Claims, Needs};
use crate::engine::{Actors, Ctx, Engine, Frame, Instance, Job, Scope};
use crate::jobs::Jobs;
use crate::join::{join_eager, SMALL};
use crate::trace::{Field, Kind};
use crate::value::to_json;

/// Conditions are looked at again at least this often (LANGUAGE.md §3).
const RECHECK: Duration = Duration::from_millis(100);

impl<'m> Engine<'m> {
    /// Runs `items` in `scope`, with the handlers that scope starts, until all are done.
    pub(crate) async fn drive(&self, scope: &Rc<Scope<'m>>, items: impl Future<Output = ()>) {
        // Jobs come only to a scope that declares handlers or exception handlers (signals,
        // exceptions, `SEQUENTIAL ON` starting) or that tops an instance of a capability
        // with leash sections. Any other scope, most of them, just runs its items.
        let takes_sections = scope.instance.as_ref().is_some_and(|i| !self.m.capabilities[i.capability].sections.is_empty());
        if scope.handlers.is_empty() && scope.exception_handlers.is_empty() && !takes_sections {
            items.await;
            for (target, job) in scope.deferred.take() {
                target.jobs.send(job);
            }
            return;
        }
        let mut items = pin!(items);
        let jobs = &scope.jobs;
        // Made at the first job: most scopes never start a handler, and an empty
        // `FuturesUnordered` still allocates.
        let mut running: Option<FuturesUnordered<_>> = None;
        let mut items_done = false;
        loop {
            let any_running = running.as_ref().is_some_and(|r| !r.is_empty());
            tokio::select! {
                biased;
                job = std::future::poll_fn(|cx| jobs.poll_recv(cx)) => running.get_or_insert_with(FuturesUnordered::new).push(self.start_job(job, scope.clone())),
                _ = &mut items, if !items_done => {
                    items_done = true;
                    // `SEQUENTIAL ON` handlers that waited for this block start now.
                    for (target, job) in scope.deferred.take() {
                        target.jobs.send(job);
                    }
                }
                Some(()) = async { running.as_mut()?.next().await }, if any_running => {}
            }
            if items_done && running.as_ref().is_none_or(|r| r.is_empty()) {
                match jobs.try_recv() {
                    Some(job) => running.get_or_insert_with(FuturesUnordered::new).push(self.start_job(job, scope.clone())),
                    None => break,
                }
            }
        }
    }

    /// A job as it waits for its first poll: the job itself, not its future. Every job
    /// taken is pushed before any is polled (they start in order), so a burst of signals
    /// (W's N `Done`s) would otherwise hold a handler's whole future for each.
    async fn start_job(&self, job: Job<'m>, scope: Rc<Scope<'m>>) {
        Box::pin(self.job(job, scope)).await;
    }

    fn new_scope(&self, ctx: &Ctx<'m>, block: &'m Block, instance: Option<Rc<Instance>>) -> Rc<Scope<'m>> {
        let scope = Rc::new(Scope {
            parent: Some(ctx.scope.clone()),
            path: &block.path,
            mission_block: ctx.instance.is_none() && instance.is_none(),
            handlers: &block.handlers,
            fired: RefCell::new(vec![false; block.handlers.len()]),
            exception_handlers: &block.exception_handlers,
            frame: ctx.frame.clone(),
            jobs: Jobs::default(),
            unwinding: Cell::new(false),
            deferred: RefCell::new(Vec::new()),
            catching: Cell::new(0),
            caught: Notify::new(),
            instance,
        });
        if !block.handlers.is_empty() {
            self.listeners.borrow_mut().push(Rc::downgrade(&scope));
        }
        if ctx.scope.parent.is_none() {
            *self.mission_scope.borrow_mut() = Some(scope.clone());
        }
        scope
    }

    pub(crate) fn block<'a>(&'a self, block: &'m Block, ctx: &'a Ctx<'m>) -> LocalBoxFuture<'a, ()> {
        Box::pin(async move {
            let scope = self.new_scope(ctx, block, None);
            if block.traced {
                self.trace(Kind::BlockStart, || [("block", Field::Str(&block.path))]);
            }
            let inner = Ctx { scope: scope.clone(), ..ctx.clone() };
            // Futures made in place and passed pinned: moving a large future into the
            // next one's state is a copy of all of it, at every step.
            let items = pin!(self.items(block, &inner));
            self.drive(&scope, items).await;
            if block.traced {
                let status = if scope.unwinding.get() { "aborted" } else { "ok" };
                self.trace(Kind::BlockEnd, || [("block", Field::Str(&block.path)), ("status", Field::Str(status))]);
            }
        })
    }

    async fn items(&self, block: &'m Block, ctx: &Ctx<'m>) {
        match block.kind {
            BlockKind::Sequential => {
                for node in &block.items {
                    if ctx.scope.unwinding.get() {
                        break;
                    }
                    self.statement(node, ctx).await;
                    // A handler caught here takes the place of what it aborted.
                    while ctx.scope.catching.get() > 0 {
                        let done = ctx.scope.caught.notified();
                        if ctx.scope.catching.get() == 0 {
                            break;
                        }
                        done.await;
                    }
                }
            }
            BlockKind::Parallel => {
                join_all(block.items.iter().map(|n| self.node(n, ctx))).await;
            }
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
            Node::Signal { signal, args, .. } => {
                if !self.stopped() {
                    self.signal(*signal, args, ctx);
                }
            }
            _ => self.node(node, ctx).await,
        }
    }

    fn node<'a>(&'a self, node: &'m Node, ctx: &'a Ctx<'m>) -> LocalBoxFuture<'a, ()> {
        // Each kind of node is boxed at its own size: with one future type for all, every
        // SIGNAL or API call took the room of a capability instance's future.
        match node {
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
                Node::Call(_) | Node::Api(_) | Node::For(_) => unreachable!("boxed apart in `node`"),
                Node::Leash(l) => self.leash(l, ctx),
                Node::Signal { signal, args, .. } => self.signal(*signal, args, ctx),
                Node::Throw { exception, args, .. } => {
                    let args = self.eval_all(args, ctx);
                    self.throw(*exception, args, ctx.actor, &ctx.scope);
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
                    while self.truth(condition, ctx) && !ctx.scope.unwinding.get() {
                        let before = self.now();
                        self.block(body, ctx).await;
                        // A round that takes no time must not starve the clock.
                        if self.now() == before {
                            tokio::time::sleep(RECHECK).await;
                        }
                    }
                }
                Node::If { branches, otherwise } => {
                    let chosen = branches.iter().find(|(c, _)| self.truth(c, ctx)).map(|(_, b)| b).or(otherwise.as_ref());
                    if let Some(b) = chosen {
                        self.block(b, ctx).await;
                    }
                }
            }
        }
    }

    /// `SIGNAL`: raised by the actor of this place, from its scope.
    fn signal(&self, signal: usize, args: &[Expr], ctx: &Ctx<'m>) {
        let args = self.eval_all(args, ctx);
        self.raise(signal, args, ctx.actor, &ctx.scope);
    }

    fn eval_all(&self, exprs: &[Expr], ctx: &Ctx<'m>) -> Vec<Value> {
        let received = self.received.borrow();
        let env = self.env(&ctx.frame, &received);
        exprs.iter().map(|e| env.eval(e)).collect()
    }

    fn truth(&self, e: &Expr, ctx: &Ctx<'m>) -> bool {
        let received = self.received.borrow();
        self.env(&ctx.frame, &received).truth(e)
    }

    async fn wait_until(&self, condition: &Expr, ctx: &Ctx<'m>) {
        loop {
            let changed = self.changed.notified();
            if self.truth(condition, ctx) {
                return;
            }
            tokio::select! {
                biased;
                _ = changed => {}
                _ = tokio::time::sleep(RECHECK) => {}
            }
        }
    }

    /// The drones an actor reference stands for here: a group is each of its members.
    fn drones(&self, r: &ActorRef, ctx: &Ctx<'m>) -> Vec<DroneId> {
        match r {
            ActorRef::Drone(d) => vec![*d],
            ActorRef::Group(g) => g.clone(),
            ActorRef::Slot(s) => match ctx.frame.get(*s) {
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
            join_all(runs.iter().map(|c| self.block(body, c))).await;
        } else if f.parallel {
            join_eager(runs.map(|c| async move { self.block(body, &c).await })).await;
        } else {
            for c in runs {
                if ctx.scope.unwinding.get() {
                    break;
                }
                self.block(body, &c).await;
            }
        }
    }

    /// A statement: one instance, or one per actor when a one-actor capability is given
    /// several (or a group), in parallel.
    async fn call(&self, call: &'m Call, ctx: &Ctx<'m>) {
        let capability = &self.m.capabilities[call.capability];
        let args = self.eval_all(&call.args, ctx);
        // The common case, one actor for a one-actor capability: no join.
        if let ([actor], 1) = (call.actors.as_slice(), capability.actors) {
            match actor {
                ActorRef::Drone(d) => return self.instance(call, Actors::from_elem(*d, 1), args, ctx).await,
                ActorRef::Slot(s) => {
                    if let Some(Value::Actor(d)) = ctx.frame.get(*s) {
                        self.instance(call, Actors::from_elem(*d, 1), args, ctx).await;
                    }
                    return;
                }
                ActorRef::Group(_) => {}
            }
        }
        let per_actor: Vec<Vec<DroneId>> = call.actors.iter().map(|a| self.drones(a, ctx)).collect();
        let sets: Vec<Actors> = if capability.actors == 1 {
            per_actor.into_iter().flatten().map(|d| Actors::from_elem(d, 1)).collect()
        } else {
            vec![per_actor.iter().filter_map(|ds| ds.first().copied()).collect()]
        };
        let runs = sets.into_iter().map(|actors| self.instance(call, actors, args.clone(), ctx));
        if runs.len() <= SMALL {
            join_all(runs).await;
        } else {
            join_eager(runs).await;
        }
    }

    async fn instance(&self, call: &'m Call, actors: Actors, args: Vec<Value>, ctx: &Ctx<'m>) {
        let cap = &self.m.capabilities[call.capability];
        // Actors, then arguments, then the body's own slots: one allocation.
        let size = cap.frame_size.max(cap.actors + cap.params.len());
        let frame: Frame = (0..size)
            .map(|i| match i.checked_sub(cap.actors) {
                None => actors.get(i).map_or(Value::Bool(false), |d| Value::Actor(*d)),
                Some(j) => args.get(j).cloned().unwrap_or(Value::Bool(false)),
            })
            .collect();
        let id = self.next_id.get() + 1;
        self.next_id.set(id);
        let instance = Rc::new(Instance {
            id,
            capability: call.capability,
            tag: call.tag,
            actors: actors.clone(),
            root: ctx.instance.as_ref().map(|p| p.root().clone()),
            token: ctx.instance.as_ref().map_or_else(|| self.stop.child_token(), |p| p.token.child_token()),
            // Only the capability's own exception handler cancels its PERFORM body.
            perform: (!cap.exception_handlers.is_empty()).then(CancellationToken::new),
            by_leash: Cell::new(false),
            failed: Cell::new(false),
            // An activity started while the operator holds the mission starts held.
            paused: Cell::new(ctx.instance.is_none() && self.mission_paused.get()),
            resumed: Notify::new(),
            calls: RefCell::new(SmallVec::new()),
            depth: ctx.instance.as_ref().map_or(0, |p| p.depth + 1),
            claims: RefCell::new(ctx.claims.clone()),
        });
        let actor = actors.first().copied();
        // Built only when the trace wants it.
        let start = || {
            let tag = Field::name(call.tag.map(|t| self.m.tags[t].as_str()));
            let shown_args: Map<String, Json> = cap.params.iter().zip(&args).map(|(p, v)| (p.clone(), to_json(self.m, v))).collect();
            let who = match actors.as_slice() {
                [one] => Field::Str(self.name(*one)),
                all => Field::Text(all.iter().map(|d| self.name(*d)).collect::<Vec<_>>().join(" ")),
            };
            [("actor", who), ("capability", Field::Str(&cap.name)), ("tag", tag), ("args", Field::Json(Json::Object(shown_args)))]
        };
        let end = |status: &'static str| {
            self.trace(Kind::CapabilityEnd, || {
                let [actor, capability, tag, args] = start();
                [actor, capability, tag, args, ("status", Field::Str(status))]
            });
        };
        // Claims first (a second instance on a busy resource waits), then the start.
        let needs: Needs = cap.claims.iter().filter_map(|(i, r)| actors.get(*i).map(|d| (*d, *r))).filter(|c| !ctx.claims.contains(c)).collect();
        let claims = ctx.claims.with(&needs);
        // An instance that waits is known while it waits (a leash can abort it), by where
        // it was called; one granted at once is listed once its own scope exists.
        let mut listed = false;
        let held = if instance.token.is_cancelled() {
            None
        } else {
            match try_acquire(&self.arbiter, needs) {
                Ok(held) => Some(held),
                Err(needs) => {
                    self.instances.borrow_mut().insert(instance.clone(), ctx.scope.clone());
                    listed = true;
                    instance.token.run(acquire(&self.arbiter, needs)).await
                }
            }
        };
        if self.stopped() {
            self.instances.borrow_mut().remove(&instance);
            return;
        }
        self.trace(Kind::CapabilityStart, start);
        if held.is_none() {
            self.instances.borrow_mut().remove(&instance);
            end("aborted");
            return;
        }
        *instance.claims.borrow_mut() = claims.clone();

        let requirements_met = {
            let received = self.received.borrow();
            let env = self.env(&frame, &received);
            cap.requirements.iter().all(|r| env.truth(r))
        };
        if !requirements_met {
            self.instances.borrow_mut().remove(&instance);
            end("failed");
            drop(held);
            let id = self.m.exceptions.iter().position(|e| e == "RequirementNotMet").unwrap_or(0);
            let why = format!("a requirement of {} does not hold", cap.name);
            self.throw(id, vec![Value::Text(why)], actor, &ctx.scope);
            return;
        }

        let scope = {
            Rc::new(Scope {
                parent: Some(ctx.scope.clone()),
                path: &cap.name,
                mission_block: false,
                handlers: &[],
                fired: RefCell::new(Vec::new()),
                exception_handlers: &cap.exception_handlers,
                frame: frame.clone(),
                jobs: Jobs::default(),
                unwinding: Cell::new(false),
                deferred: RefCell::new(Vec::new()),
                catching: Cell::new(0),
                caught: Notify::new(),
                instance: Some(instance.clone()),
            })
        };
        if listed {
            self.instances.borrow_mut().set_scope(&instance, scope.clone());
        } else {
            self.instances.borrow_mut().insert(instance.clone(), scope.clone());
        }
        let inner = Ctx { scope: scope.clone(), frame, actor, instance: Some(instance.clone()), claims };
        // A PERFORM body that declares no handlers, in a capability without exception
        // handlers, runs its statements in the instance's own scope: a scope of its own
        // would hear nothing and catch nothing, and an exception unwinds both alike.
        let own_scope = !cap.perform.handlers.is_empty() || !cap.perform.exception_handlers.is_empty() || cap.perform.traced;
        let perform = pin!(async {
            match &instance.perform {
                Some(perform) => _ = perform.run(self.block(&cap.perform, &inner)).await,
                None if own_scope => self.block(&cap.perform, &inner).await,
                None => self.items(&cap.perform, &inner).await,
            }
        });
        let drive = pin!(self.drive(&scope, perform));
        let finished = instance.token.run(drive).await.is_some();
        self.instances.borrow_mut().remove(&instance);
        if !finished && instance.by_leash.get() {
            // `PERFORM ABORT:` says what aborting this activity also does.
            if let Some((_, section)) = cap.sections.iter().find(|(n, _)| n == "ABORT") {
                let after = Ctx { instance: None, ..inner.clone() };
                self.block(section, &after).await;
            }
        }
        drop(held);
        let status = if finished && !instance.failed.get() {
            "ok"
        } else if instance.failed.get() {
            "failed"
        } else {
            "aborted"
        };
        end(status);
    }

    async fn job(&self, job: Job<'m>, scope: Rc<Scope<'m>>) {
        match job {
            Job::Signal { handler, args, actor, signal } => {
                let mut frame = scope.frame.to_vec();
                for (slot, v) in handler.bindings.iter().zip(args) {
                    set(&mut frame, *slot, v);
                }
                let who = actor.map(|a| self.name(a));
                let signal_name = &self.m.signals[signal];
                self.trace(Kind::HandlerStart, || [("signal", Field::Str(signal_name)), ("handler", Field::Str(&handler.body.path)), ("actor", Field::name(who))]);
                let ctx = self.scope_ctx(&scope, Rc::from(frame));
                self.block(&handler.body, &ctx).await;
                self.trace(Kind::HandlerEnd, || [("signal", Field::Str(signal_name)), ("handler", Field::Str(&handler.body.path)), ("actor", Field::name(who))]);
            }
            Job::Exception { handler, args } => {
                let mut frame = scope.frame.to_vec();
                for (slot, v) in handler.bindings.iter().zip(args) {
                    set(&mut frame, *slot, v);
                }
                let ctx = self.scope_ctx(&scope, Rc::from(frame));
                self.block(&handler.body, &ctx).await;
                scope.catching.set(scope.catching.get().saturating_sub(1));
                scope.caught.notify_waiters();
            }
            Job::Section { block, frame } => {
                let ctx = self.scope_ctx(&scope, frame);
                self.block(block, &ctx).await;
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
        self.leash_by_id(l.capability, l.tag, l.action, &l.action_name, values);
    }

    /// A leash on every running activity of `capability` tagged `tag`; recorded even when
    /// none runs (LANGUAGE.md §3).
    pub(crate) fn leash_by_id(&self, capability: usize, tag: usize, action: LeashAction, action_name: &str, values: Vec<(usize, Value)>) {
        let cap = &self.m.capabilities[capability];
        self.trace(Kind::Leash, || [("capability", Field::Str(&cap.name)), ("tag", Field::Str(&self.m.tags[tag])), ("action", Field::Str(action_name))]);
        let targets: Vec<(Rc<Instance>, Rc<Scope<'m>>)> = self.instances.borrow().tagged(capability, tag).cloned().collect();
        for (instance, scope) in targets {
            match action {
                LeashAction::Abort => {
                    instance.by_leash.set(true);
                    instance.token.cancel();
                }
                LeashAction::Pause => {
                    instance.paused.set(true);
                    for call in instance.calls.borrow().iter() {
                        self.backend.interrupt(*call, Interrupt::Pause);
                    }
                }
                LeashAction::Resume => {
                    instance.paused.set(false);
                    for call in instance.calls.borrow().iter() {
                        self.backend.interrupt(*call, Interrupt::Resume);
                    }
                    instance.resumed.notify_waiters();
                }
                LeashAction::Section(i) => {
                    let mut frame = scope.frame.to_vec();
                    for (p, v) in &values {
                        set(&mut frame, cap.actors + p, v.clone());
                    }
                    scope.jobs.send(Job::Section { block: &cap.sections[i].1, frame: Rc::from(frame) });
                }
            }
        }
    }

    async fn api(&self, a: &'m aviary_ir::ApiCall, ctx: &Ctx<'m>) {
        let drone = {
            let received = self.received.borrow();
            self.env(&ctx.frame, &received).actor(&a.actor)
        };
        let Some(drone) = drone else { return };
        let root = ctx.instance.as_ref().map(|i| i.root());
        if let Some(root) = &root {
            loop {
                let resumed = root.resumed.notified();
                if !root.paused.get() {
                    break;
                }
                resumed.await;
            }
        }
        let args = self.eval_all(&a.args, ctx);
        let function = self.m.functions[a.function].0.as_str();
        self.trace(Kind::ApiCall, || [("actor", Field::Str(self.name(drone))), ("function", Field::Str(function)), ("args", Field::Json(self.values(&args)))]);
        let pending = self.backend.call(drone, function, &args);
        let end = match pending.end {
            // Over as it was made: nothing in flight to pause, resume or abort.
            Ending::Now(end) => end,
            Ending::Later(answer) => {
                let guard = CallGuard { engine: self, id: pending.id, root, done: Cell::new(false), drone, function, args: &args };
                if let Some(root) = root {
                    root.calls.borrow_mut().push(pending.id);
                    if root.paused.get() {
                        self.backend.interrupt(pending.id, Interrupt::Pause);
                    }
                }
                let end = answer.await.unwrap_or(CallEnd::Interrupted);
                guard.done.set(true);
                end
            }
        };
        self.trace_done(drone, function, &args, &end);
        match end {
            CallEnd::Done => self.after_call(function, drone, &args, ctx),
            CallEnd::Failed(f) => {
                let id = self.m.exceptions.iter().position(|e| e == f.exception).unwrap_or(0);
                self.throw(id, vec![Value::Text(f.reason)], Some(drone), &ctx.scope);
            }
            CallEnd::Interrupted => {
                // A fault interrupted it: raise that first, while this activity still runs.
                self.drain_events();
                ctx.scope.unwinding.set(true);
            }
        }
    }

    fn after_call(&self, function: &str, drone: DroneId, args: &[Value], ctx: &Ctx<'m>) {
        let kind = match args.first() {
            Some(Value::Symbol(k) | Value::Text(k)) => k.clone(),
            _ => return,
        };
        match function {
            // Finds are raised in the activity that started detection (LANGUAGE.md §5).
            "StartDetection" => {
                self.detections.borrow_mut().insert((drone, kind), ctx.scope.clone());
            }
            "StopDetection" => {
                self.detections.borrow_mut().remove(&(drone, kind));
            }
            _ => {}
        }
    }
}

/// Interrupts a call whose activity is dropped before the call ended, and says so in
/// the trace: every `api_call` has its `api_done`.
struct CallGuard<'e, 'm> {
    engine: &'e Engine<'m>,
    id: aviary_api::CallId,
    root: Option<&'e Rc<Instance>>,
    done: Cell<bool>,
    drone: DroneId,
    function: &'e str,
    args: &'e [Value],
}

impl Drop for CallGuard<'_, '_> {
    fn drop(&mut self) {
        if !self.done.get() {
            self.engine.backend.interrupt(self.id, Interrupt::Abort);
            let engine = self.engine;
            engine.trace(Kind::ApiDone, || {
                let p = engine.backend.telemetry(self.drone).position;
                [
                    ("actor", Field::Str(engine.name(self.drone))),
                    ("function", Field::Str(self.function)),
                    ("args", Field::Json(engine.values(self.args))),
                    ("status", Field::Str("aborted")),
                    ("position", Field::Json(json!(p))),
                ]
            });
        }
        if let Some(root) = &self.root {
            root.calls.borrow_mut().retain(|c| *c != self.id);
        }
    }
}

fn set(frame: &mut Vec<Value>, slot: usize, value: Value) {
    if frame.len() <= slot {
        frame.resize(slot + 1, Value::Bool(false));
    }
    frame[slot] = value;
}
