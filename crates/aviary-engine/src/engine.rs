//! The engine's state and its cross-cutting rules: scopes, signals, exceptions, drone
//! events, the trace, and the run from start to `mission_end`.

use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::future::Future;
use std::pin::pin;
use std::rc::Rc;

use std::borrow::Cow;

use aviary_api::trace::{AutopilotAction, CallStatus, Event, EventKind, RaisedBy, Record, Shown};
use aviary_api::{Backend, DroneEvent, DroneId, Function, Value};
use aviary_ir::{
    ActorFilter, CapId, ExceptionHandler, ExceptionId, Handler, Mission, SignalId, Slots, TagId,
    TiSlice, TiVec,
};
use tokio::sync::{mpsc, Notify};

use crate::cancel::Token as CancellationToken;
use crate::jobs::Jobs;
use crate::registry::Registry;
use aviary_clock::Instant;

use crate::arbiter::{Arbiter, Claims};
use crate::value::Env;
use crate::{Outcome, RunOptions, Status, TraceSink};

pub(crate) type Frame = Rc<[Value]>;
/// The drones of an activity: nearly always one, kept inline.
pub(crate) type Actors = smallvec::SmallVec<[DroneId; 2]>;

/// Work a scope starts on request, while it runs.
pub(crate) enum Job<'m> {
    Signal {
        handler: &'m Handler,
        args: Vec<Value>,
        actor: Option<DroneId>,
        signal: SignalId,
        entry: Rc<Entry>,
    },
    Exception {
        handler: &'m ExceptionHandler,
        args: Vec<Value>,
        entry: Rc<Entry>,
    },
    Section {
        block: &'m aviary_ir::Block,
        frame: Frame,
    },
}

/// A handler of either kind, known by its address in the mission: what the bound on
/// re-entering handlers at one instant counts.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) struct Taker(usize);

impl Taker {
    pub fn signal(h: &Handler) -> Taker {
        Taker(h as *const Handler as usize)
    }

    pub fn exception(h: &ExceptionHandler) -> Taker {
        Taker(h as *const ExceptionHandler as usize)
    }
}

/// A handler's instance (an exception handler's, or a firing of a signal's handler), for
/// the bound on re-entering a handler at one instant
/// ([`crate::RunOptions::max_handler_reentries`]): made when the exception is thrown or
/// the signal raised, and kept by its body's scope while the body runs
/// (`Engine::entered`), so that what the body throws or raises knows what led to it. The
/// two kinds share one chain: a signal's handler that throws, and an exception's handler
/// that raises the signal again, are one cycle.
pub(crate) struct Entry {
    handler: Taker,
    /// When it was made: the clock, and the runtime's poll of the mission. A firing that
    /// waited its turn (`ONE AT A TIME`) while time passed starts a new count.
    at: Instant,
    poll: u64,
    /// The instance whose body led to this one, if that one was made at this same
    /// instant; so on back, all at this instant.
    cause: Option<Rc<Entry>>,
    /// The re-entries of the instances one exception or signal led to at this instant,
    /// shared by all of them: a body that fails twice at once (a statement on a group),
    /// or raises twice, starts two instances, and their count must not grow as a tree does.
    counts: Rc<Counts>,
}

/// How many times each handler has been re-entered among the instances one exception or
/// signal led to at one instant.
#[derive(Default)]
pub(crate) struct Counts(RefCell<Vec<(Taker, usize)>>);

impl Counts {
    fn of(&self, handler: Taker) -> usize {
        let counts = self.0.borrow();
        counts.iter().find(|(h, _)| *h == handler).map_or(0, |(_, n)| *n)
    }

    fn add(&self, handler: Taker) {
        let mut counts = self.0.borrow_mut();
        match counts.iter_mut().find(|(h, _)| *h == handler) {
            Some((_, n)) => *n += 1,
            None => counts.push((handler, 1)),
        }
    }
}

impl Entry {
    /// Whether an instance of `handler` led to this one (or is this one): another instance
    /// of it started now is a re-entry.
    fn led_from(&self, handler: Taker) -> bool {
        std::iter::successors(Some(self), |e| e.cause.as_deref()).any(|e| e.handler == handler)
    }
}

/// While an exception handler's body runs, its scope is known by the instance's
/// [`Entry`]; the guard forgets it when the body ends or is dropped.
pub(crate) struct Entered<'e, 'm> {
    engine: &'e Engine<'m>,
    key: usize,
}

impl Drop for Entered<'_, '_> {
    fn drop(&mut self) {
        self.engine.entered.borrow_mut().remove(&self.key);
    }
}

/// A running body: what it hears, where its handlers start, whether it is unwinding.
pub(crate) struct Scope<'m> {
    pub parent: Option<Rc<Scope<'m>>>,
    pub path: &'m str,
    /// A block of the mission itself (not inside a capability): a signalling block.
    pub mission_block: bool,
    pub handlers: &'m [Handler],
    pub fired: RefCell<Vec<bool>>,
    pub exception_handlers: &'m [ExceptionHandler],
    /// The frame the body's handlers start from: the body's, with the LETs it has
    /// reached so far (`Engine::bind`).
    pub frame: RefCell<Frame>,
    pub jobs: Jobs<'m>,
    /// Set when an exception aborts the sequential chain through this scope.
    pub unwinding: Cell<bool>,
    /// `SEQUENTIAL ON` handlers to start, in their own scope, when this block has finished.
    pub deferred: RefCell<Vec<(Rc<Scope<'m>>, Job<'m>)>>,
    /// The `ONE AT A TIME` handlers of this scope with a firing running, by index, each
    /// with the firings that came meanwhile, in order. Empty (no allocation) in nearly
    /// every scope.
    pub serial: RefCell<Vec<(usize, std::collections::VecDeque<Job<'m>>)>>,
    /// Exception handlers running here; a sequence waits for them before going on.
    pub catching: Cell<usize>,
    pub caught: Notify,
    /// The capability instance this scope is the top of, if any.
    pub instance: Option<Rc<Instance>>,
    /// Inside a leash section (`PERFORM Name:`) running on an activity: its calls are not
    /// held while the sections hold the activity's body (`section.rs`). Set on the
    /// section's block, and taken over by every scope made inside one.
    pub section: Cell<bool>,
    /// The token of the innermost block around this scope that a `Name ABORT` may stop
    /// (`None` outside every such block, as in most missions): the activities started at
    /// mission level under it are its children, and sequences end once it is cancelled.
    pub stop: Option<CancellationToken>,
}

impl<'m> Scope<'m> {
    /// Whether a block around this scope was stopped (`Name ABORT`): nothing more starts.
    pub fn block_stopped(&self) -> bool {
        self.stop.as_ref().is_some_and(CancellationToken::is_cancelled)
    }

    /// Starts a firing of one of this scope's handlers; a firing of a `ONE AT A TIME`
    /// handler that has one running waits behind it instead (docs/LANGUAGE.md, section 11).
    pub fn fire(&self, job: Job<'m>) {
        if let Job::Signal { handler, .. } = &job {
            if let Some(i) = self.serial_index(handler) {
                let mut serial = self.serial.borrow_mut();
                match serial.iter_mut().find(|(h, _)| *h == i) {
                    Some((_, waiting)) => {
                        waiting.push_back(job);
                        return;
                    }
                    None => serial.push((i, std::collections::VecDeque::new())),
                }
            }
        }
        self.jobs.send(job);
    }

    /// A firing of `handler` has ended: for a `ONE AT A TIME` handler, the next one that
    /// waits starts now.
    pub fn firing_ended(&self, handler: &Handler) {
        let Some(i) = self.serial_index(handler) else { return };
        let next = {
            let mut serial = self.serial.borrow_mut();
            let Some(k) = serial.iter().position(|(h, _)| *h == i) else { return };
            let next = serial[k].1.pop_front();
            if next.is_none() {
                serial.swap_remove(k);
            }
            next
        };
        if let Some(job) = next {
            self.jobs.send(job);
        }
    }

    fn serial_index(&self, handler: &Handler) -> Option<usize> {
        if !handler.one_at_a_time {
            return None;
        }
        self.handlers.iter().position(|h| std::ptr::eq(h, handler))
    }

    /// This scope and those around it, innermost first.
    pub fn chain(self: &Rc<Self>) -> impl Iterator<Item = &Rc<Scope<'m>>> {
        std::iter::successors(Some(self), |s| s.parent.as_ref())
    }
}

/// Calls in flight: nearly always one or none, kept inline.
pub(crate) type Calls = smallvec::SmallVec<[aviary_api::CallId; 2]>;

/// A running capability instance (an activity).
pub(crate) struct Instance {
    pub id: u64,
    pub capability: CapId,
    pub tag: Option<TagId>,
    pub actors: Actors,
    /// The instance a statement of the mission started: pausing it pauses all inside it.
    pub root: Option<Rc<Instance>>,
    pub token: CancellationToken,
    /// Cancels the PERFORM body only: the capability's own exception handler takes its place.
    pub perform: Option<CancellationToken>,
    pub by_leash: Cell<bool>,
    pub failed: Cell<bool>,
    /// Paused by a leash or with the whole mission (kept on the root).
    pub paused: Cell<bool>,
    /// Held because the operator holds a drone of it (kept on the root, `steer.rs`). On
    /// its own beside `paused`: either holds the activity, and resuming one leaves the other.
    pub held: Cell<bool>,
    pub resumed: Notify,
    /// The calls in flight of the activity's body and of the activities inside it (kept
    /// on the root), but not its leash sections'.
    pub calls: RefCell<Calls>,
    /// The leash sections asked of this activity (kept on the root) and not yet ended,
    /// running or waiting their turn: while there is one, the body is held (`section.rs`).
    pub sections: Cell<usize>,
    /// The calls in flight of its leash sections (kept on the root).
    pub section_calls: RefCell<Calls>,
    /// One leash section at a time, in the order they were asked (kept on the root).
    pub turn: tokio::sync::Semaphore,
    pub depth: usize,
    /// What this activity and its ancestors hold: handlers inside it share the claim.
    pub claims: RefCell<Claims>,
}

impl Instance {
    pub fn root(self: &Rc<Self>) -> &Rc<Instance> {
        self.root.as_ref().unwrap_or(self)
    }

    /// Whether this root's calls wait: paused (a leash, the mission) or held (a drone).
    pub fn waits(&self) -> bool {
        self.paused.get() || self.held.get()
    }

    /// Whether this root's calls made in its body (`in_section` false) or in its leash
    /// sections wait: a section is held only by a pause or a hold, the body also while a
    /// section runs.
    pub fn holds(&self, in_section: bool) -> bool {
        self.waits() || (!in_section && self.sections.get() > 0)
    }

    /// What holds this root now, body and sections: before a change, for
    /// [`Engine::rehold`].
    pub fn holding(&self) -> Holds {
        Holds { body: self.holds(false), sections: self.holds(true) }
    }

    /// The calls in flight of this root's body (`in_section` false) or of its sections.
    pub fn calls_of(&self, in_section: bool) -> &RefCell<Calls> {
        if in_section {
            &self.section_calls
        } else {
            &self.calls
        }
    }
}

/// Whether a root's body and its leash sections are held (`Instance::holding`).
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) struct Holds {
    pub body: bool,
    pub sections: bool,
}

/// What an execution knows about where it is.
#[derive(Clone)]
pub(crate) struct Ctx<'m> {
    pub scope: Rc<Scope<'m>>,
    pub frame: Frame,
    pub actor: Option<DroneId>,
    pub instance: Option<Rc<Instance>>,
    pub claims: Claims,
}

pub(crate) struct Engine<'m> {
    pub m: &'m Mission,
    pub backend: &'m dyn Backend,
    sink: RefCell<&'m mut dyn TraceSink>,
    /// What the sink wants, by kind (asked once).
    wanted: [bool; EventKind::ALL.len()],
    start: Instant,
    pub received: RefCell<TiVec<SignalId, bool>>,
    pub changed: Notify,
    pub arbiter: Rc<RefCell<Arbiter>>,
    pub instances: RefCell<Registry<'m>>,
    pub detections: RefCell<BTreeMap<(DroneId, String), Rc<Scope<'m>>>>,
    /// Where each drone's work is, for its own events (`place.rs`).
    pub places: crate::place::Places<'m>,
    /// How the mission ends early, if it does: failed (an unhandled exception, a lost
    /// backend) or aborted (the operator), and why.
    ending: RefCell<Option<(Status, String)>>,
    /// Where the first unhandled exception was raised (`Outcome::at`).
    failed_at: Cell<Option<aviary_ir::Origin>>,
    /// Per drone, the statement of its latest middle-layer call: where a fault or a
    /// refusal on it is said to have happened.
    last_call: RefCell<TiVec<DroneId, Option<aviary_ir::Origin>>>,
    /// False once the backend cannot answer: then nobody can be sent home.
    backend_alive: Cell<bool>,
    /// The operator paused the whole mission.
    pub mission_paused: Cell<bool>,
    /// What the operator did to single drones (`steer.rs`).
    pub steering: crate::steer::Steering,
    /// Faults of drones on their way down, outside the mission: after its end, or once the
    /// operator took them out of it (`homing.rs`).
    pub down_faults: crate::homing::Faults,
    /// Set once the mission's body, handlers and controls are over and only the way
    /// down is left.
    pub over: Cell<bool>,
    /// Running scopes that declare handlers, in the order they started (for signals from
    /// outside the mission, which every running block hears).
    pub listeners: RefCell<Vec<std::rc::Weak<Scope<'m>>>>,
    pub stop: CancellationToken,
    /// The paths of the blocks some `Name ABORT` names (in no order; few).
    pub stoppable: Vec<&'m str>,
    /// The instances of those blocks running now, each with its scope.
    pub stoppable_running: RefCell<Vec<Rc<Scope<'m>>>>,
    events: RefCell<Option<mpsc::UnboundedReceiver<DroneEvent>>>,
    root: RefCell<Option<Rc<Scope<'m>>>>,
    /// The MISSION body's own block: "mission level", where an idle drone's events are raised.
    pub mission_scope: RefCell<Option<Rc<Scope<'m>>>>,
    pub next_id: Cell<u64>,
    /// Which capabilities may run as instant activities (`instant.rs`).
    pub instant: TiVec<CapId, bool>,
    /// [`crate::RunOptions::max_call_depth`].
    pub max_call_depth: usize,
    /// [`crate::RunOptions::max_handler_reentries`].
    max_handler_reentries: usize,
    /// The exception handler instances running, by their body's scope (its address).
    entered: RefCell<BTreeMap<usize, Rc<Entry>>>,
    /// What each drone's last `Sweep` or `FollowPath` left (`coverage.rs`).
    pub coverage: crate::coverage::Coverage,
    /// The drones each `ANY` holds (`choose.rs`).
    pub taken: crate::choose::Taken,
    /// How many times the runtime has polled the mission. Within one poll the engine has
    /// not waited for anything: with the wall clock (MAVLink drones), whose every reading
    /// differs, that is what "at one instant" is.
    polls: Cell<u64>,
    /// A stop asked from outside, looked at between steps (`control.rs`).
    pub(crate) interrupt: std::cell::OnceCell<std::sync::Arc<crate::control::Interrupt>>,
}

impl<'m> Engine<'m> {
    pub fn new(
        m: &'m Mission,
        backend: &'m dyn Backend,
        sink: &'m mut dyn TraceSink,
        options: &RunOptions,
    ) -> Self {
        Engine {
            m,
            backend,
            wanted: EventKind::ALL.map(|k| sink.wants(k)),
            sink: RefCell::new(sink),
            start: Instant::now(),
            received: RefCell::new(vec![false; m.signals.len()].into()),
            changed: Notify::new(),
            arbiter: Rc::new(RefCell::new(Arbiter::default())),
            instances: RefCell::new(Registry::default()),
            detections: RefCell::new(BTreeMap::new()),
            places: Default::default(),
            ending: RefCell::new(None),
            failed_at: Cell::new(None),
            last_call: RefCell::new(vec![None; m.drones.len()].into()),
            backend_alive: Cell::new(true),
            mission_paused: Cell::new(false),
            steering: Default::default(),
            down_faults: Default::default(),
            over: Cell::new(false),
            listeners: RefCell::new(Vec::new()),
            stop: CancellationToken::new(),
            stoppable: crate::exec::stoppable_blocks(m),
            stoppable_running: RefCell::new(Vec::new()),
            events: RefCell::new(backend.events()),
            root: RefCell::new(None),
            mission_scope: RefCell::new(None),
            next_id: Cell::new(0),
            instant: crate::instant::instant_capabilities(m),
            max_call_depth: options.max_call_depth,
            max_handler_reentries: options.max_handler_reentries,
            entered: RefCell::new(BTreeMap::new()),
            polls: Cell::new(0),
            interrupt: std::cell::OnceCell::new(),
            coverage: crate::coverage::Coverage::new(m.drones.len()),
            taken: Default::default(),
        }
    }

    /// After a failure nothing new starts: the failsafe takes over.
    pub fn stopped(&self) -> bool {
        self.stop.is_cancelled()
    }

    pub fn now(&self) -> f64 {
        (Instant::now() - self.start).as_secs_f64()
    }

    /// Records an event of `kind`, if the sink wants that kind: `event` is made only then.
    pub fn trace<'a>(&self, kind: EventKind, event: impl FnOnce() -> Event<'a>) {
        if !self.wanted[kind as usize] {
            return;
        }
        let event = event();
        debug_assert_eq!(event.kind(), kind, "an event of the kind asked for");
        self.sink.borrow_mut().record(&Record { t: self.now(), event });
    }

    pub fn name(&self, d: DroneId) -> &'m str {
        self.m.drones.get(d).unwrap_or("?")
    }

    /// Values as the trace shows them, their text borrowed.
    pub fn values<'a>(&'a self, values: &'a [Value]) -> Vec<Shown<'a>> {
        Shown::all(values, &self.m.drones)
    }

    pub fn env<'a>(&'a self, frame: &'a [Value], received: &'a TiSlice<SignalId, bool>) -> Env<'a> {
        Env {
            mission: self.m,
            backend: self.backend,
            coverage: &self.coverage,
            frame,
            received,
            start: self.start,
        }
    }

    pub async fn run(&self, options: &RunOptions, controls: Option<crate::Controls>) -> Outcome {
        let controls = controls.map(|c| {
            let (rx, interrupt) = c.into_parts();
            let _ = self.interrupt.set(interrupt);
            rx
        });
        self.trace(EventKind::MissionStart, || Event::MissionStart {
            mission: self.m.name.as_str().into(),
            world: options.world.clone(),
        });
        let root = Rc::new(Scope {
            parent: None,
            path: &self.m.name,
            mission_block: true,
            handlers: &[],
            fired: RefCell::new(Vec::new()),
            exception_handlers: &[],
            frame: RefCell::new(Rc::from(vec![Value::Absent; self.m.frame_size])),
            jobs: Jobs::default(),
            unwinding: Cell::new(false),
            deferred: RefCell::new(Vec::new()),
            serial: RefCell::new(Vec::new()),
            catching: Cell::new(0),
            caught: Notify::new(),
            instance: None,
            section: Cell::new(false),
            stop: None,
        });
        *self.root.borrow_mut() = Some(root.clone());
        let ctx = Ctx {
            scope: root.clone(),
            frame: root.frame.borrow().clone(),
            actor: None,
            instance: None,
            claims: Claims::default(),
        };
        let body = self.drive(&root, self.block(&self.m.body, &ctx));
        let controls = async {
            match controls {
                Some(rx) => self.controls(rx).await,
                None => std::future::pending().await,
            }
        };
        // Unconstrained by tokio's cooperative budget: the budget makes a task yield
        // after 128 channel operations, and each yield re-polls the mission's tree of
        // futures from its root. With N actors in parallel that would turn every step
        // into a walk over many of them, and a run quadratic in N. Nothing here needs it:
        // the mission is one task, every wait is on time or a notification, and the
        // simulator's driver runs whenever the mission waits.
        let body = tokio::task::unconstrained(body);
        // Drones the operator took out of the mission, brought down beside it and after
        // its end (last: what the mission does at an instant comes first).
        let mut withdrawals = Box::pin(self.withdrawals());
        {
            let mut all = pin!(async {
                tokio::select! {
                    biased;
                    _ = self.stop.cancelled() => {}
                    _ = body => {}
                    _ = self.pump() => {}
                    _ = controls => {}
                    _ = self.telemetry(options.telemetry_hz) => {}
                    _ = withdrawals.as_mut() => {}
                }
            });
            // Each poll counted (`polls`): between two, the engine has waited.
            std::future::poll_fn(|cx| {
                self.polls.set(self.polls.get().wrapping_add(1));
                all.as_mut().poll(cx)
            })
            .await;
        }
        self.over.set(true);
        // No more mission: only the way home is left, and it waits.
        if let Some(interrupt) = self.interrupt.get() {
            interrupt.heard();
        }
        let ending = self.ending.borrow().clone();
        // Drones still flying go home: at the end of the mission, or as the failsafe.
        let home = if self.backend_alive.get() {
            self.all_home(withdrawals.as_mut()).await
        } else {
            Default::default()
        };
        // Nobody can be commanded any more: a drone on its way down is left to it, its
        // call written as ended before the mission's end.
        drop(withdrawals);
        let (mut status, mut reason) = match ending {
            Some((status, reason)) => (status, Some(reason)),
            None => (Status::Ok, None),
        };
        // A drone that did not come down safely fails a mission that had ended well; a
        // fault on the way down that a drone survived is said in the reason all the same.
        if !home.stranded.is_empty() && status == Status::Ok {
            status = Status::Failed;
        }
        let said: Vec<String> = reason.into_iter().chain(home.stranded).chain(home.notes).collect();
        reason = (!said.is_empty()).then(|| said.join("; "));
        // The drones as they are at the end: the last periodic sample may be older (a
        // drone a centimetre above the field, still `Landing`), and a page that shows the
        // trace must not leave it there.
        if options.telemetry_hz.is_some_and(|h| h > 0.0) && self.backend_alive.get() {
            self.sample_telemetry();
        }
        self.trace(EventKind::MissionEnd, || Event::MissionEnd {
            status,
            reason: reason.as_deref().map(Cow::Borrowed),
        });
        Outcome { status, reason, at: self.failed_at.get() }
    }

    /// Remembers `origin` as the statement of `drone`'s latest middle-layer call.
    pub(crate) fn calling(&self, drone: DroneId, origin: aviary_ir::Origin) {
        if let Some(at) = self.last_call.borrow_mut().get_mut(drone) {
            *at = Some(origin);
        }
    }

    /// Ends the mission early; the first reason given is the one reported.
    pub fn end_with(&self, status: Status, reason: String, backend_alive: bool) {
        self.ending.borrow_mut().get_or_insert((status, reason));
        if let Some(interrupt) = self.interrupt.get() {
            interrupt.heard();
        }
        if !backend_alive {
            self.backend_alive.set(false);
        }
        self.stop.cancel();
    }

    // `run` sets the root scope before it starts anything that can ask for it.
    #[allow(clippy::expect_used)]
    pub fn root_scope(&self) -> Rc<Scope<'m>> {
        self.root.borrow().clone().expect("the run has a root scope")
    }

    /// `api_done` of a call of `function` on `d`, its arguments shown by `args` (only
    /// when the trace wants the event).
    pub(crate) fn trace_done<'a>(
        &'a self,
        d: DroneId,
        function: Function,
        args: impl FnOnce() -> Vec<Shown<'a>>,
        end: &aviary_api::CallEnd,
    ) {
        let status = match end {
            aviary_api::CallEnd::Done => CallStatus::Ok,
            aviary_api::CallEnd::Failed(_) => CallStatus::Failed,
            aviary_api::CallEnd::Interrupted => CallStatus::Interrupted,
        };
        let left = self.path_ended(d, function, end);
        self.trace(EventKind::ApiDone, || Event::ApiDone {
            actor: self.name(d).into(),
            function,
            args: args(),
            status,
            position: self.backend.telemetry(d).position,
            left,
        });
    }

    async fn telemetry(&self, hz: Option<f64>) {
        let Some(hz) = hz.filter(|h| *h > 0.0) else { return std::future::pending().await };
        let period = std::time::Duration::from_secs_f64(1.0 / hz);
        let mut next = Instant::now();
        loop {
            self.sample_telemetry();
            next += period;
            aviary_clock::sleep_until(next).await;
        }
    }

    /// One telemetry sample of every drone, in the trace.
    fn sample_telemetry(&self) {
        for d in (0..self.m.drones.len()).map(DroneId) {
            let t = self.backend.telemetry(d);
            self.trace(EventKind::Telemetry, || Event::Telemetry {
                actor: self.name(d).into(),
                position: t.position,
                battery: t.battery,
                state: t.state,
            });
        }
    }

    /// The next drone event (`None` once the backend has no more).
    pub(crate) async fn next_event(&self) -> Option<DroneEvent> {
        std::future::poll_fn(|cx| match self.events.borrow_mut().as_mut() {
            Some(rx) => rx.poll_recv(cx),
            None => std::task::Poll::Pending,
        })
        .await
    }

    /// Drone events, as they come.
    async fn pump(&self) {
        loop {
            match self.next_event().await {
                Some(e) => self.on_event(e),
                None => std::future::pending().await,
            }
        }
    }

    /// Handles every drone event already queued. A call that ended `Interrupted` does
    /// this first, so the fault behind it is raised while its activity still runs.
    pub fn drain_events(&self) {
        loop {
            let event = match self.events.borrow_mut().as_mut() {
                Some(rx) => rx.try_recv().ok(),
                None => None,
            };
            match event {
                Some(e) => self.on_event(e),
                None => break,
            }
        }
    }

    fn on_event(&self, event: DroneEvent) {
        // A drone the operator took out of the mission is on its way down: the mission
        // no longer hears from it (`steer.rs`).
        if self.steering.withdrawn(event.drone()).is_some() {
            self.on_the_way_down(event);
            return;
        }
        match event {
            DroneEvent::Detected { drone, kind, location } => {
                self.trace(EventKind::Detection, || Event::Detection {
                    actor: self.name(drone).into(),
                    kind: kind.as_str().into(),
                    location,
                });
                let scope = self.detections.borrow().get(&(drone, kind.clone())).cloned();
                if let Some(scope) = scope {
                    let id = self.m.builtins.signal(aviary_api::BuiltinSignal::Detected);
                    // A find is a point on the ground: flying to it keeps the altitude.
                    let args = vec![
                        Value::Symbol(kind),
                        Value::Position(aviary_api::Point::flat(location[0], location[1])),
                    ];
                    self.raise(id, args, Some(drone), &scope, None);
                }
            }
            DroneEvent::Signal { drone, signal } => {
                let scope = self.actor_scope(drone);
                self.raise(self.m.builtins.signal(signal), Vec::new(), Some(drone), &scope, None);
            }
            DroneEvent::Fault { drone, failure } => {
                // What a path call in progress left, before a handler can read it.
                self.path_stopped(drone);
                let scope = self.actor_scope(drone);
                self.fail(failure, drone, &scope);
            }
            DroneEvent::Autopilot { drone, action, reason } => {
                self.autopilot(drone, action, &reason)
            }
        }
    }

    /// What a drone's autopilot did on its own: recorded, for the operator and the
    /// record; the mission hears the fault behind it, not this.
    pub(crate) fn autopilot(&self, drone: DroneId, action: AutopilotAction, reason: &str) {
        self.trace(EventKind::Autopilot, || Event::Autopilot {
            actor: self.name(drone).into(),
            action,
            reason: reason.into(),
        });
    }

    /// Raises a backend's failure on `drone` as its built-in exception, with the reason.
    pub(crate) fn fail(&self, failure: aviary_api::Failure, drone: DroneId, from: &Rc<Scope<'m>>) {
        let id = self.m.builtins.exception(failure.exception);
        let cause = failure.cause;
        self.throw(id, vec![Value::Text(failure.reason)], Some(drone), from, None, cause);
    }

    fn matches(&self, by: &Option<ActorFilter>, frame: &[Value], actor: Option<DroneId>) -> bool {
        match by {
            None => true,
            Some(ActorFilter::Drones(ds)) => actor.is_some_and(|a| ds.contains(&a)),
            Some(ActorFilter::Slot(s)) => {
                matches!((frame.slot(*s), actor), (Some(Value::Actor(d)), Some(a)) if *d == a)
            }
        }
    }

    /// A signal from outside the mission (the operator): heard by every running handler
    /// that matches, at once (there is no signalling block to wait for).
    pub fn raise_from_outside(&self, signal: SignalId, args: Vec<Value>) {
        self.trace(EventKind::Signal, || Event::Signal {
            name: self.m.signals[signal].as_str().into(),
            actor: None,
            args: self.values(&args),
            by: Some(RaisedBy::Operator),
            line: None,
        });
        if let Some(r) = self.received.borrow_mut().get_mut(signal) {
            *r = true;
        }
        self.changed.notify_waiters();
        self.listeners.borrow_mut().retain(|w| w.strong_count() > 0);
        let scopes: Vec<Rc<Scope<'m>>> =
            self.listeners.borrow().iter().filter_map(|w| w.upgrade()).collect();
        for scope in scopes {
            if self.stopped() {
                break;
            }
            self.deliver(&scope, signal, &args, None, None, &None);
        }
    }

    /// `SIGNAL`: recorded, then heard by every matching handler of every scope up the chain.
    /// `at`: the `SIGNAL` statement, whose line the trace names; none for a drone's signal.
    pub fn raise(
        &self,
        signal: SignalId,
        args: Vec<Value>,
        actor: Option<DroneId>,
        from: &Rc<Scope<'m>>,
        at: Option<&aviary_ir::Origin>,
    ) {
        self.heed_interrupt();
        if self.stopped() {
            return;
        }
        self.trace(EventKind::Signal, || Event::Signal {
            name: self.m.signals[signal].as_str().into(),
            actor: actor.map(|a| self.name(a).into()),
            args: self.values(&args),
            by: None,
            line: at.and_then(|o| self.m.line_of(o)),
        });
        if let Some(r) = self.received.borrow_mut().get_mut(signal) {
            *r = true;
        }
        self.changed.notify_waiters();
        let signalling_block = from.chain().find(|s| s.mission_block);
        let cause = self.cause(from);
        for scope in from.chain() {
            // A cycle of signals cut off by the bound ends the mission: no one hears more.
            if self.stopped() {
                break;
            }
            self.deliver(scope, signal, &args, actor, signalling_block, &cause);
        }
        if self.stopped() {
            // The raiser's chain ends aborted, as an unhandled exception's does.
            for scope in from.chain() {
                scope.unwinding.set(true);
                if let Some(i) = &scope.instance {
                    i.failed.set(true);
                }
            }
        }
    }

    /// Starts (or, for `SEQUENTIAL ON`, defers to the signalling block's end) each handler
    /// of `scope` that hears this signal. `cause` is the handler instance whose body
    /// raised it, if that one was made at this instant: a handler that it (or what led to
    /// it) is an instance of, started again too often at this instant, is a cycle of
    /// signals that takes no time, and ends the mission.
    fn deliver(
        &self,
        scope: &Rc<Scope<'m>>,
        signal: SignalId,
        args: &[Value],
        actor: Option<DroneId>,
        signalling_block: Option<&Rc<Scope<'m>>>,
        cause: &Option<Rc<Entry>>,
    ) {
        let handlers: &'m [Handler] = scope.handlers;
        for (i, h) in handlers.iter().enumerate() {
            if h.signal != signal || !self.matches(&h.by, &scope.frame.borrow(), actor) {
                continue;
            }
            if !h.every {
                let mut fired = scope.fired.borrow_mut();
                if fired[i] {
                    continue;
                }
                fired[i] = true;
            }
            let taker = Taker::signal(h);
            let reentries = self.reentries(taker, cause);
            if let Some(n) = reentries.filter(|n| *n >= self.max_handler_reentries) {
                self.cycle_of_signals(h, n);
                return;
            }
            let entry = self.new_entry(taker, cause.clone(), reentries.is_some());
            let job = Job::Signal { handler: h, args: args.to_vec(), actor, signal, entry };
            match (signalling_block, h.sequential) {
                (Some(block), true) => block.deferred.borrow_mut().push((scope.clone(), job)),
                _ => scope.fire(job),
            }
        }
    }

    /// `THROW EXCEPTION` (or a drone fault): abort the thrower's chain up to the nearest
    /// handler, abort its other activities, and start the handler in that place.
    /// `caused_by`: what the trace says caused it, for a fault that says (`Failure::cause`).
    pub fn throw(
        &self,
        exception: ExceptionId,
        args: Vec<Value>,
        actor: Option<DroneId>,
        from: &Rc<Scope<'m>>,
        at: Option<aviary_ir::Origin>,
        caused_by: Option<aviary_api::Cause>,
    ) {
        self.heed_interrupt();
        if self.stopped() {
            return;
        }
        let name = self.m.exceptions.get(exception).map_or("", String::as_str);
        let cause = self.cause(from);
        // A handler re-entered too often at this instant is passed over, as if it were not
        // there: the exception goes on outward. The first one passed over is reported.
        let mut skipped = None;
        let found = from.chain().find_map(|scope| {
            let handlers: &'m [ExceptionHandler] = scope.exception_handlers;
            let i = handlers.iter().position(|h| {
                h.exception == exception && self.matches(&h.by, &scope.frame.borrow(), actor)
            })?;
            let reentry = self.reentries(Taker::exception(&handlers[i]), &cause);
            let reentries = reentry.unwrap_or(0);
            if reentry.is_some() && reentries >= self.max_handler_reentries {
                skipped.get_or_insert_with(|| {
                    let line = match handlers[i].line {
                        0 => String::new(),
                        line => format!(", line {line},"),
                    };
                    // Whole milliseconds: the clock's own digits say nothing more.
                    let t = (self.now() * 1000.0).round() / 1000.0;
                    format!(
                        "{}/ON EXCEPTION {name}{line} re-entered {} times at t = {t} s without time passing",
                        scope.path, reentries
                    )
                });
                return None;
            }
            Some((scope.clone(), i, reentry.is_some()))
        });
        self.trace(EventKind::Exception, || Event::Exception {
            name: name.into(),
            actor: actor.map(|a| self.name(a).into()),
            args: self.values(&args),
            handled: found.is_some(),
            handler: found
                .as_ref()
                .map(|(s, _, _)| Cow::Owned(format!("{}/ON EXCEPTION {name}", s.path))),
            during: None,
            skipped: skipped.as_deref().map(Cow::Borrowed),
            line: at.as_ref().and_then(|o| self.m.line_of(o)),
            cause: caused_by,
        });
        let Some((handler_scope, index, reentry)) = found else {
            for scope in from.chain() {
                scope.unwinding.set(true);
                if let Some(i) = &scope.instance {
                    i.failed.set(true);
                }
            }
            let who = actor.map_or(String::from("the mission"), |a| self.name(a).to_string());
            let mut reason = match args.first() {
                Some(Value::Text(why)) => format!("unhandled exception {name} on {who}: {why}"),
                _ => format!("unhandled exception {name} on {who}"),
            };
            if let Some(skipped) = skipped {
                reason = format!("{reason}; its handler {skipped}, so it did not take it again");
            }
            if self.ending.borrow().is_none() {
                let last = || actor.and_then(|d| self.last_call.borrow().get(d).copied().flatten());
                self.failed_at.set(at.or_else(last));
            }
            self.end_with(Status::Failed, reason, true);
            return;
        };
        let keep: Vec<*const Scope> = handler_scope.chain().map(Rc::as_ptr).collect();
        for scope in from.chain().take_while(|s| !Rc::ptr_eq(s, &handler_scope)) {
            scope.unwinding.set(true);
            if let Some(i) = &scope.instance {
                i.failed.set(true);
            }
        }
        if let Some(actor) = actor {
            for (instance, scope) in self.instances.borrow().of_actor(actor) {
                if !keep.contains(&Rc::as_ptr(scope)) {
                    instance.token.cancel();
                }
            }
        }
        if let Some(perform) = handler_scope.instance.as_ref().and_then(|i| i.perform.as_ref()) {
            perform.cancel();
        }
        handler_scope.catching.set(handler_scope.catching.get() + 1);
        let handlers: &'m [ExceptionHandler] = handler_scope.exception_handlers;
        let handler = &handlers[index];
        let entry = self.new_entry(Taker::exception(handler), cause, reentry);
        handler_scope.jobs.send(Job::Exception { handler, args, entry });
    }

    /// How many times `handler` has been re-entered among the instances that led to
    /// `cause`, if one of them is an instance of it (a new one is then a re-entry).
    fn reentries(&self, handler: Taker, cause: &Option<Rc<Entry>>) -> Option<usize> {
        cause.as_ref().filter(|c| c.led_from(handler)).map(|c| c.counts.of(handler))
    }

    /// A new instance of `handler`, made now, led to by `cause`; counted if a re-entry.
    fn new_entry(&self, handler: Taker, cause: Option<Rc<Entry>>, reentry: bool) -> Rc<Entry> {
        let counts = cause.as_ref().map_or_else(Rc::default, |c| c.counts.clone());
        if reentry {
            counts.add(handler);
        }
        Rc::new(Entry { handler, at: Instant::now(), poll: self.polls.get(), cause, counts })
    }

    /// A signal's handler started again `n` times at this instant by what its own firings
    /// raised: the signals go round for ever without time passing. The mission fails, and
    /// the fleet goes home.
    #[cold]
    fn cycle_of_signals(&self, h: &Handler, n: usize) {
        let line = match h.line {
            0 => String::new(),
            line => format!(", line {line}"),
        };
        // Whole milliseconds: the clock's own digits say nothing more.
        let t = (self.now() * 1000.0).round() / 1000.0;
        let reason = format!(
            "a cycle of signals at one instant: {}{line}, started again {n} times at t = {t} s by what its own firings raised, without time passing",
            h.body.path
        );
        self.end_with(Status::Failed, reason, true);
    }

    /// The innermost handler instance (of an exception, or a signal's firing) whose body
    /// `from` is in, if it was made at this instant: no time has passed since, or the
    /// engine has not waited since (with the wall clock, time passes between any two
    /// readings).
    fn cause(&self, from: &Rc<Scope<'m>>) -> Option<Rc<Entry>> {
        let entered = self.entered.borrow();
        if entered.is_empty() {
            return None;
        }
        let innermost = from.chain().find_map(|s| entered.get(&(Rc::as_ptr(s) as usize)))?;
        (innermost.at == Instant::now() || innermost.poll == self.polls.get())
            .then(|| innermost.clone())
    }

    /// Knows `body`, the scope of a handler's body, by `entry` while the guard lives.
    pub fn enter<'e>(&'e self, body: &Rc<Scope<'m>>, entry: Rc<Entry>) -> Entered<'e, 'm> {
        let key = Rc::as_ptr(body) as usize;
        self.entered.borrow_mut().insert(key, entry);
        Entered { engine: self, key }
    }
}
