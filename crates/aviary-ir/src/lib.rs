//! The compiled mission: what the engine runs.
//!
//! Everything a run needs is resolved here, once: capabilities, signals, exceptions and
//! tags are indices; middle-layer functions are the contract's `Function`s, and every
//! built-in signal and exception a backend raises has its id in [`Builtins`]; drones are
//! `DroneId`s; numbers are SI;
//! defaults are filled in; each handler sits on the block whose subtree it hears; each
//! capability knows every resource its body can use. The engine looks nothing up by
//! name. Spans survive, so a run-time problem can still point into the source.
//!
//! The types only: the lowering from the checked syntax tree is `aviary-lower`'s, so the IR
//! (and the engine) need neither the parser, the checker nor the world.
//!
//! Invariant: no IO; no panic.

// A pure stage: no unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]
// A pass says what it does with every kind of node: a new statement, expression or IR
// node is then a compile error in each pass (with clippy), not one it silently skips. An
// enum that is no language construct may be matched with `_`, allowed where it is.
#![deny(clippy::wildcard_enum_match_arm)]

use aviary_api::{
    BuiltinException, BuiltinSignal, DroneId, Function, FunctionCall, Kind, Resource, Value,
};
use aviary_diagnostics::{FileId, Span};

pub use typed_index_collections::{TiSlice, TiVec};

/// An index into one table of [`Mission`], of a type of its own: a table is a [`TiVec`]
/// that takes only its own kind of id, so that a signal's id cannot pick a capability.
macro_rules! id {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub struct $name(pub usize);

        impl From<usize> for $name {
            fn from(i: usize) -> $name {
                $name(i)
            }
        }

        impl From<$name> for usize {
            fn from(id: $name) -> usize {
                id.0
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                self.0.fmt(f)
            }
        }
    };
}

id!(
    /// A capability: [`Mission::capabilities`].
    CapId
);
id!(
    /// A signal: [`Mission::signals`].
    SignalId
);
id!(
    /// An exception: [`Mission::exceptions`].
    ExceptionId
);
id!(
    /// A capability's tag: [`Mission::tags`].
    TagId
);
id!(
    /// A variable of the frame a node runs in (`Mission::frame_size`,
    /// `Capability::frame_size` of them).
    Slot
);

/// A frame's variables, read by [`Slot`]: the engine's values, the plan's known values.
pub trait Slots<V> {
    fn slot(&self, s: Slot) -> Option<&V>;
    fn slot_mut(&mut self, s: Slot) -> Option<&mut V>;
}

impl<V> Slots<V> for [V] {
    fn slot(&self, s: Slot) -> Option<&V> {
        self.get(s.0)
    }
    fn slot_mut(&mut self, s: Slot) -> Option<&mut V> {
        self.get_mut(s.0)
    }
}

impl Slot {
    /// In a capability's frame the `BY` actors come first (`Capability::actors` of them):
    /// which of them this slot holds, if it holds one.
    pub fn actor(self, actors: usize) -> Option<usize> {
        (self.0 < actors).then_some(self.0)
    }

    /// The slot of parameter `i` of a capability with `actors` `BY` actors: they come
    /// first, its parameters after them, in order.
    pub fn param(actors: usize, i: usize) -> Slot {
        Slot(actors + i)
    }
}

/// A place in the source.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Origin {
    pub file: FileId,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Mission {
    pub name: String,
    pub body: Block,
    /// Variables of the mission frame (FOR aliases and parameters, handler bindings, LETs).
    pub frame_size: usize,
    pub capabilities: TiVec<CapId, Capability>,
    /// Drone names, by `DroneId`.
    pub drones: aviary_api::Names,
    pub signals: TiVec<SignalId, String>,
    /// By `SignalId`: the values the signal carries, each one's kind where the checker
    /// knows it. The engine does not need them; the operator API checks a signal raised
    /// from outside against them.
    pub signal_values: TiVec<SignalId, Vec<Option<Kind>>>,
    /// The signals the mission declares with `OPERATOR SIGNAL`, each once, in the order
    /// written: the only ones an operator may raise while it runs.
    pub operator_signals: Vec<SignalId>,
    pub exceptions: TiVec<ExceptionId, String>,
    /// `Capability-Tag` names, as written after the dash.
    pub tags: TiVec<TagId, String>,
    /// `attributes[a][d]`: attribute `a` of drone `d`, from the world file.
    pub attribute_names: Vec<String>,
    pub attributes: Vec<Column>,
    /// The world's geodetic origin, for `GEO(...)` evaluated at run time.
    pub origin: Option<aviary_api::geo::Origin>,
    /// The ids of the built-in signals and exceptions, resolved here so that the engine
    /// looks up no name when a backend or the engine itself raises one.
    pub builtins: Builtins,
    /// The lines of the file that holds the MISSION: a trace event of a statement of that
    /// file names its line, which is what identifies the statement to a page that follows
    /// the run (one statement a line).
    pub lines: Lines,
}

/// Where each line of one file starts (byte offsets), and which file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lines {
    pub file: FileId,
    pub starts: Vec<u32>,
}

/// Every built-in signal and exception's id in this mission, whether or not the mission
/// names it: a backend may raise any of them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Builtins {
    /// By `BuiltinSignal as usize`.
    pub signals: [SignalId; BuiltinSignal::ALL.len()],
    /// By `BuiltinException as usize`.
    pub exceptions: [ExceptionId; BuiltinException::ALL.len()],
}

impl Builtins {
    pub fn signal(&self, s: BuiltinSignal) -> SignalId {
        self.signals[s as usize]
    }
    pub fn exception(&self, e: BuiltinException) -> ExceptionId {
        self.exceptions[e as usize]
    }
}

/// Why an operator may not raise `name`, when the mission declares `declared` (in the
/// order written) as its operator signals.
pub fn undeclared_signal(name: &str, declared: &[&str]) -> String {
    if declared.is_empty() {
        return format!("the mission declares no signal an operator may raise, so not {name}");
    }
    let list = declared.join(", ");
    match aviary_diagnostics::suggest::did_you_mean(name, declared.iter().copied()) {
        Some(mean) => format!(
            "the mission does not declare {name} as an operator signal: {mean} It declares {list}"
        ),
        None => {
            format!("the mission does not declare {name} as an operator signal: it declares {list}")
        }
    }
}

impl Mission {
    /// The line (from 1) of a statement at `origin`, when it is in the MISSION's file.
    pub fn line_of(&self, origin: &Origin) -> Option<u32> {
        let lines = &self.lines;
        (origin.file == lines.file && !lines.starts.is_empty())
            .then(|| lines.starts.partition_point(|&s| s <= origin.span.start) as u32)
    }

    /// Attribute `a` of drone `d`, if the world gives the drone one.
    pub fn attribute(&self, a: usize, d: DroneId) -> Option<Value> {
        match self.attributes.get(a)? {
            Column::Numbers { values, present } => {
                present.get(d.0)?.then(|| Value::Number(values[d.0]))
            }
            Column::Values(values) => values.get(d.0)?.clone(),
        }
    }
}

/// One attribute of every drone. A number is 8 bytes where a `Value` is 40, and most
/// attributes (an index, a weight) are numbers: a fleet of 100,000 keeps 3 MB less.
#[derive(Clone, Debug, PartialEq)]
pub enum Column {
    /// Every drone that has the attribute has a number.
    Numbers {
        values: Vec<f64>,
        present: Vec<bool>,
    },
    Values(Vec<Option<Value>>),
}

impl Column {
    pub fn new(values: Vec<Option<Value>>) -> Column {
        if !values.iter().flatten().all(|v| matches!(v, Value::Number(_))) {
            return Column::Values(values);
        }
        let present = values.iter().map(Option::is_some).collect();
        let values =
            values.iter().map(|v| if let Some(Value::Number(n)) = v { *n } else { 0.0 }).collect();
        Column::Numbers { values, present }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Capability {
    pub name: String,
    /// Slots 0..actors hold the `BY` actors; the next `params.len()` slots the parameters.
    pub actors: usize,
    pub params: Vec<String>,
    /// Each parameter's kind, as the checker inferred it (`None`: any). The engine does
    /// not need them; the operator API checks a leash's arguments against them.
    pub param_kinds: Vec<Option<Kind>>,
    pub frame_size: usize,
    pub requirements: Vec<Expr>,
    pub perform: Block,
    /// Named `PERFORM X:` sections (leashes), by name as written.
    pub sections: Vec<(String, Block)>,
    /// The `PERFORM ABORT:` section (an index in `sections`): what aborting the activity
    /// by its leash also does.
    pub abort_section: Option<usize>,
    pub exception_handlers: Vec<ExceptionHandler>,
    /// Every resource of every `BY` actor that the body can use, through the capabilities
    /// it calls: what a statement claims when it starts (docs/LANGUAGE.md, section 6).
    pub claims: Vec<(usize, Resource)>,
}

impl Capability {
    /// Every body: PERFORM, its named sections, its exception handlers.
    pub fn bodies(&self) -> impl Iterator<Item = &Block> {
        std::iter::once(&self.perform)
            .chain(self.sections.iter().map(|(_, b)| b))
            .chain(self.exception_handlers.iter().map(|h| &h.body))
    }

    /// How a leash names `action`, as the trace writes it: `PAUSE`, or a section's name
    /// as the capability writes it; `None` for a section it does not have.
    pub fn action_name(&self, action: LeashAction) -> Option<&str> {
        match action {
            LeashAction::Builtin(builtin) => Some(builtin.as_str()),
            LeashAction::Section(i) => self.sections.get(i).map(|(name, _)| name.as_str()),
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockKind {
    Sequential,
    Parallel,
}

/// A body: its items run in sequence or in parallel; its handlers listen while it runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    pub kind: BlockKind,
    /// The block's name in the trace: its own name, or a path such as
    /// `Start_Mission/ON Video1_Ready`.
    pub path: String,
    /// Whether the block is a named or written `SEQUENTIAL`/`PARALLEL` block (traced), or
    /// the body of some other construct.
    pub traced: bool,
    pub items: Vec<Node>,
    pub handlers: Vec<Handler>,
    pub exception_handlers: Vec<ExceptionHandler>,
}

impl Block {
    /// Calls `f` on every node below this block: items, nested bodies, and the bodies of
    /// its handlers and exception handlers. The one walk over the IR: it names every kind
    /// of node, so a new one is a compile error here rather than a body left unvisited.
    pub fn visit<'b>(&'b self, f: &mut dyn FnMut(&'b Node)) {
        for body in self
            .handlers
            .iter()
            .map(|h| &h.body)
            .chain(self.exception_handlers.iter().map(|h| &h.body))
        {
            body.visit(f);
        }
        for node in &self.items {
            f(node);
            match node {
                Node::Block(b)
                | Node::StartIf { body: b, .. }
                | Node::DoWhile { body: b, .. }
                | Node::WaitFor { body: Some(b), .. } => b.visit(f),
                Node::For(x) => x.body.visit(f),
                Node::Any(x) => x.body.visit(f),
                Node::If { branches, otherwise } => {
                    for (_, b) in branches {
                        b.visit(f);
                    }
                    if let Some(b) = otherwise {
                        b.visit(f);
                    }
                }
                Node::WaitFor { body: None, .. }
                | Node::Call(_)
                | Node::Leash(_)
                | Node::Api(_)
                | Node::Signal { .. }
                | Node::Throw { .. }
                | Node::Let { .. }
                | Node::StopBlock { .. } => {}
            }
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Node {
    Block(Block),
    Call(Call),
    Leash(Leash),
    Api(ApiCall),
    Signal {
        signal: SignalId,
        args: Vec<Expr>,
        origin: Origin,
    },
    Throw {
        exception: ExceptionId,
        args: Vec<Expr>,
        origin: Origin,
    },
    StartIf {
        condition: Expr,
        body: Block,
    },
    WaitFor {
        condition: Expr,
        body: Option<Block>,
    },
    DoWhile {
        condition: Expr,
        body: Block,
    },
    For(For),
    Any(Any),
    If {
        branches: Vec<(Expr, Block)>,
        otherwise: Option<Block>,
    },
    /// `LET name = value`: `value` taken once, when reached, into `slot` of the frame,
    /// which the items after it (and the handlers of its body) read.
    Let {
        slot: Slot,
        value: Expr,
        origin: Origin,
    },
    /// `Name ABORT`: ends every running instance of the traced block whose path is
    /// `block` (a named block's path is its name).
    StopBlock {
        block: String,
        origin: Origin,
    },
}

/// Who a statement or a call is about.
#[derive(Clone, Debug, PartialEq)]
pub enum ActorRef {
    Drone(DroneId),
    /// A group: each member, in parallel, in world order.
    Group(Vec<DroneId>),
    /// An alias or `BY` parameter of the frame.
    Slot(Slot),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Call {
    pub actors: Vec<ActorRef>,
    pub capability: CapId,
    /// One per parameter, defaults filled in.
    pub args: Vec<Expr>,
    pub tag: Option<TagId>,
    pub origin: Origin,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LeashAction {
    /// `ABORT`, `PAUSE` or `RESUME`, which every capability understands.
    Builtin(aviary_api::BuiltinLeash),
    /// A named `PERFORM` section, by its index in [`Capability::sections`].
    Section(usize),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Leash {
    pub capability: CapId,
    pub tag: TagId,
    /// Its name, for the trace, is the capability's to say ([`Capability::action_name`]).
    pub action: LeashAction,
    /// Parameter index and value, for a section's arguments.
    pub args: Vec<(usize, Expr)>,
    pub origin: Origin,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ApiCall {
    pub actor: ActorRef,
    pub function: Function,
    pub args: Vec<Expr>,
    /// The call read when compiled ([`FunctionCall::new`] on `args`' values), when every
    /// argument is a constant and reads: the engine makes it as it is, with nothing to
    /// evaluate or read. Derived from `args` by the lowering and by nothing else.
    pub read: Option<FunctionCall>,
    pub origin: Origin,
}

#[derive(Clone, Debug, PartialEq)]
pub struct For {
    pub parallel: bool,
    /// Each instance's actor and values. A group instance stands for each member.
    pub instances: Vec<(ActorRef, Vec<Expr>)>,
    pub alias: Slot,
    pub params: Vec<Slot>,
    pub body: Block,
}

/// `ANY [k] d IN group WHERE c NEAREST TO p WITHIN t:`: waits until `count` of
/// `candidates` are held by no other `ANY` and meet `condition` (read with `alias` bound
/// to each), holds the `count` nearest to `nearest` (ties: the group's order), and runs
/// `body` once for each, at once, with `alias` bound to it; each is let go as its body
/// ends. Past `within` seconds without them, `NoDroneAvailable` is thrown where it stands.
#[derive(Clone, Debug, PartialEq)]
pub struct Any {
    /// The group's name, for the reason of a `NoDroneAvailable`.
    pub group: String,
    pub candidates: Vec<DroneId>,
    pub count: usize,
    pub alias: Slot,
    pub condition: Option<Expr>,
    pub nearest: Option<Expr>,
    pub within: Option<Expr>,
    pub body: Block,
    pub origin: Origin,
}

/// Which signalling actors a `BY` accepts.
#[derive(Clone, Debug, PartialEq)]
pub enum ActorFilter {
    Drones(Vec<DroneId>),
    Slot(Slot),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Handler {
    pub signal: SignalId,
    pub every: bool,
    /// `SEQUENTIAL ON`: starts when the signalling block has finished.
    pub sequential: bool,
    /// `ONE AT A TIME` (only with `every`): a firing starts when the previous firing of
    /// this handler, in the same running block, has finished; firings that come
    /// meanwhile wait in the order of their signals.
    pub one_at_a_time: bool,
    pub by: Option<ActorFilter>,
    pub bindings: Vec<Slot>,
    pub body: Block,
    /// The line of its `ON` in the file that declares it (from 1; 0 unknown), for a
    /// run-time report that names the handler (a cycle of signals at one instant).
    pub line: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ExceptionHandler {
    pub exception: ExceptionId,
    pub by: Option<ActorFilter>,
    pub bindings: Vec<Slot>,
    pub body: Block,
    /// The line of its `ON EXCEPTION` in the file that declares it (from 1; 0 unknown),
    /// for a run-time report that names the handler.
    pub line: u32,
}

/// Telemetry a condition may read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Field {
    Position,
    Altitude,
    Speed,
    Heading,
    Battery,
    State,
    Link,
    /// The wind's speed at the drone, read with its `wind` sensor.
    Wind,
    /// The kind of payload the drone carries, if any.
    Payload,
    /// What the drone's last `Sweep` or `FollowPath` left: the engine's, not telemetry.
    Remaining,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

impl Compare {
    /// Whether `a op b` holds. Numbers compare as numbers; anything else only by equality,
    /// where a symbol and a string are equal when they spell the same (docs/LANGUAGE.md,
    /// section 3: symbols only equal themselves). The engine and the pre-flight plan both decide
    /// conditions with it.
    pub fn holds(self, a: &Value, b: &Value) -> bool {
        // What a drone does not have equals nothing (so it differs from everything).
        if matches!(a, Value::Absent) || matches!(b, Value::Absent) {
            return self == Compare::Ne;
        }
        if let (Value::Number(x), Value::Number(y)) = (a, b) {
            return match self {
                Compare::Eq => x == y,
                Compare::Ne => x != y,
                Compare::Lt => x < y,
                Compare::Le => x <= y,
                Compare::Gt => x > y,
                Compare::Ge => x >= y,
            };
        }
        fn text(v: &Value) -> Option<&str> {
            match v {
                Value::Text(s) | Value::Symbol(s) => Some(s),
                Value::Number(_)
                | Value::Bool(_)
                | Value::Position(_)
                | Value::Area(_)
                | Value::Actor(_)
                | Value::Remainder(_)
                | Value::Absent => None,
            }
        }
        let equal = match (text(a), text(b)) {
            (Some(x), Some(y)) => x == y,
            _ => a == b,
        };
        match self {
            Compare::Eq => equal,
            Compare::Ne => !equal,
            Compare::Lt | Compare::Le | Compare::Gt | Compare::Ge => false,
        }
    }
}

/// The two or three parts of coordinates, `(x, y[, z])`, or of `GEO(lat, lon[, alt])`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Parts<T> {
    pub x: T,
    pub y: T,
    pub z: Option<T>,
}

impl<T> Parts<T> {
    /// Two or three parts, in order; `None` for another number of them (which the
    /// checker refuses).
    pub fn of(parts: Vec<T>) -> Option<Parts<T>> {
        let mut parts = parts.into_iter();
        let (x, y, z) = (parts.next()?, parts.next()?, parts.next());
        parts.next().is_none().then_some(Parts { x, y, z })
    }

    pub fn map<U>(self, mut f: impl FnMut(T) -> U) -> Parts<U> {
        Parts { x: f(self.x), y: f(self.y), z: self.z.map(f) }
    }

    pub fn borrowed(&self) -> Parts<&T> {
        Parts { x: &self.x, y: &self.y, z: self.z.as_ref() }
    }

    /// Each part through `f`, or `None` when one of them gives none.
    pub fn try_map<U>(self, mut f: impl FnMut(T) -> Option<U>) -> Option<Parts<U>> {
        let z = match self.z {
            Some(z) => Some(f(z)?),
            None => None,
        };
        Some(Parts { x: f(self.x)?, y: f(self.y)?, z })
    }
}

/// A value or condition, evaluated in a frame at run time.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    Const(Value),
    Slot(Slot),
    Actor(ActorRef),
    Telemetry(ActorRef, Field),
    /// `attributes[index]` of the actor: an attribute some drone of the world has.
    Attribute(ActorRef, usize),
    /// Coordinates with a part that is not a literal: `(x, 20)`.
    Point(Box<Parts<Expr>>),
    /// `GEO(lat, lon[, alt])` with a part that is not a literal.
    Geo(Box<Parts<Expr>>),
    Distance(Box<Expr>, Box<Expr>),
    /// `a + b`: two quantities of one kind, or a position and an offset in metres
    /// (`aviary_api::arith::add`).
    Add(Box<Expr>, Box<Expr>),
    /// `a - b`, as `Add`.
    Sub(Box<Expr>, Box<Expr>),
    /// `OFFSET(position, distance, bearing)` (`aviary_api::arith::offset`).
    Offset(Box<Expr>, Box<Expr>, Box<Expr>),
    /// `MIDPOINT(a, b)` (`aviary_api::arith::midpoint`).
    Midpoint(Box<Expr>, Box<Expr>),
    Elapsed,
    Received(SignalId),
    Not(Box<Expr>),
    And(Box<Expr>, Box<Expr>),
    Or(Box<Expr>, Box<Expr>),
    Compare(Box<Expr>, Compare, Box<Expr>),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_symbol_equals_a_string_of_the_same_spelling_and_only_numbers_order() {
        let (sym, text) = (Value::Symbol("Body".into()), Value::Text("Body".into()));
        assert!(Compare::Eq.holds(&sym, &text));
        assert!(!Compare::Ne.holds(&sym, &text));
        assert!(!Compare::Lt.holds(&sym, &text));
        assert!(Compare::Le.holds(&Value::Number(1.0), &Value::Number(1.0)));
        assert!(!Compare::Eq.holds(&Value::Number(f64::NAN), &Value::Number(f64::NAN)));
        assert!(Compare::Ne.holds(&Value::Actor(DroneId(0)), &Value::Actor(DroneId(1))));
    }
}

#[cfg(test)]
mod column_tests {
    use super::*;

    fn mission(attributes: Vec<Column>) -> Mission {
        Mission {
            name: "M".into(),
            body: Block {
                kind: BlockKind::Sequential,
                path: "M".into(),
                traced: false,
                items: vec![],
                handlers: vec![],
                exception_handlers: vec![],
            },
            frame_size: 0,
            capabilities: TiVec::new(),
            drones: aviary_api::Names::new(["a", "b", "c"].into_iter()),
            signals: TiVec::new(),
            signal_values: TiVec::new(),
            operator_signals: vec![],
            exceptions: TiVec::new(),
            tags: TiVec::new(),
            attribute_names: vec![],
            attributes,
            origin: None,
            builtins: Builtins { signals: [SignalId(0); 3], exceptions: [ExceptionId(0); 10] },
            lines: Lines::default(),
        }
    }

    #[test]
    fn an_attribute_reads_the_same_however_it_is_kept() {
        let numbers = vec![Some(Value::Number(2.5)), None, Some(Value::Number(-1.0))];
        let mixed = vec![Some(Value::Number(1.0)), Some(Value::Text("x".into())), None];
        let columns = vec![Column::new(numbers.clone()), Column::new(mixed.clone())];
        assert!(matches!(columns[0], Column::Numbers { .. }), "numbers only: a column of numbers");
        assert!(matches!(columns[1], Column::Values(_)));
        let m = mission(columns);
        for d in 0..3 {
            assert_eq!(m.attribute(0, DroneId(d)), numbers[d]);
            assert_eq!(m.attribute(1, DroneId(d)), mixed[d]);
        }
        assert_eq!(
            (m.attribute(0, DroneId(3)), m.attribute(2, DroneId(0))),
            (None, None),
            "no such drone, no such attribute"
        );
    }
}
