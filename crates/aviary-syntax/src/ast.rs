//! The syntax tree. Every node keeps its span so that any later stage can point back
//! into the source. Derived `Debug` output with spans removed is the tree's identity
//! (see `tests/properties.rs`): formatting must not change it.

use aviary_diagnostics::Span;

#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommentKind {
    Line,
    Block,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Comment {
    pub span: Span,
    pub kind: CommentKind,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct SourceFile {
    pub items: Vec<Item>,
    pub comments: Vec<Comment>,
    /// Where each physical line starts, as a byte offset: what turns a span into a line
    /// once the text is gone (a run-time report names the line of a handler).
    pub line_offsets: Vec<u32>,
}

impl SourceFile {
    /// The line (from 1) that the byte at `offset` is on; 0 for a tree made without its
    /// text.
    pub fn line_of(&self, offset: u32) -> u32 {
        self.line_offsets.partition_point(|&start| start <= offset) as u32
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    Use(Use),
    Capability(Capability),
    Mission(Mission),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Use {
    pub path: String,
    pub path_span: Span,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Mission {
    pub name: Ident,
    pub body: Body,
    pub span: Span,
}

/// The items of an indented body, with where its header ended (after the `:`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Body {
    pub items: Vec<Stmt>,
    pub header_end: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Capability {
    pub name: Ident,
    /// The `BY` parameters: the actors the capability runs on.
    pub actors: Vec<Ident>,
    /// The `WITH` parameters.
    pub params: Vec<Ident>,
    pub sections: Vec<Section>,
    /// Where the header ended (after the `:`).
    pub header_end: u32,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum Section {
    Requirements {
        conditions: Vec<Expr>,
        body_header_end: u32,
        span: Span,
    },
    Defaults {
        entries: Vec<DefaultEntry>,
        body_header_end: u32,
        span: Span,
    },
    /// `PERFORM:` has no name; `PERFORM X:` is a leash section (`ABORT`, `PAUSE`,
    /// `RESUME` or a name of the user's).
    Perform {
        name: Option<Ident>,
        body: Body,
        span: Span,
    },
    Exceptions {
        handlers: Vec<ExceptionHandler>,
        body_header_end: u32,
        span: Span,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct DefaultEntry {
    pub name: Ident,
    pub value: Expr,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockKind {
    Sequential,
    Parallel,
}

impl BlockKind {
    pub fn as_str(self) -> &'static str {
        match self {
            BlockKind::Sequential => "SEQUENTIAL",
            BlockKind::Parallel => "PARALLEL",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Stmt {
    Block(Block),
    Statement(Statement),
    Leash(LeashCall),
    Api(ApiCall),
    Requirement(Requirement),
    For(ForBlock),
    Signal(Raise),
    Throw(Raise),
    Handler(Handler),
    ExceptionHandler(ExceptionHandler),
    If(IfChain),
    /// `OPERATOR SIGNAL A, B`: the signals an operator may raise while the mission runs.
    /// Allowed only directly in the MISSION body (the checker says so elsewhere).
    OperatorSignals(OperatorSignals),
    /// `ANY d IN group WHERE c NEAREST TO p WITHIN t:`: a drone chosen at run time.
    Any(Box<AnyBlock>),
    /// `LET name = value`: an immutable name for a value, taken once when reached.
    Let(Let),
    /// `ALLOW W203 "reason"`: the warning is acknowledged on the item after it. The
    /// checker and the pre-flight analyses read it; the lowering and the engine skip it.
    Allow(Allow),
    /// `Block_Name ABORT`: every running instance of the named block is ended.
    StopBlock(StopBlock),
    /// A line that could not be read. It was reported; later stages skip it.
    Error(Span),
}

impl Stmt {
    /// The item's whole text, its body included.
    pub fn span(&self) -> Span {
        match self {
            Stmt::Block(b) => b.span,
            Stmt::Statement(s) => s.span,
            Stmt::Leash(l) => l.span,
            Stmt::Api(a) => a.span,
            Stmt::Requirement(r) => r.span,
            Stmt::For(f) => f.span,
            Stmt::Any(a) => a.span,
            Stmt::Signal(r) | Stmt::Throw(r) => r.span,
            Stmt::Handler(h) => h.span,
            Stmt::ExceptionHandler(h) => h.span,
            Stmt::If(i) => i.span,
            Stmt::OperatorSignals(o) => o.span,
            Stmt::Let(l) => l.span,
            Stmt::Allow(a) => a.span,
            Stmt::StopBlock(s) => s.span,
            Stmt::Error(span) => *span,
        }
    }

    /// Calls `f` on each body directly inside this item, in source order.
    pub fn for_each_body<'a>(&'a self, f: impl FnMut(&'a Body)) {
        crate::visit::stmt_bodies(self, f)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Block {
    pub kind: BlockKind,
    pub name: Option<Ident>,
    pub body: Body,
    pub span: Span,
}

/// `actor+ Capability[-Tag] WITH args`.
#[derive(Clone, Debug, PartialEq)]
pub struct Statement {
    pub actors: Vec<Ident>,
    pub capability: Ident,
    pub tag: Option<Ident>,
    pub args: Vec<Arg>,
    pub span: Span,
}

/// `Capability-Tag ACTION WITH args`.
#[derive(Clone, Debug, PartialEq)]
pub struct LeashCall {
    pub capability: Ident,
    pub tag: Ident,
    /// `ABORT`, `PAUSE`, `RESUME` or a section name, as written.
    pub action: Ident,
    pub args: Vec<Arg>,
    pub span: Span,
}

/// `actor.Function(args)`.
#[derive(Clone, Debug, PartialEq)]
pub struct ApiCall {
    pub actor: Ident,
    pub function: Ident,
    pub args: Vec<Expr>,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RequirementKind {
    StartIf,
    WaitFor,
    DoWhile,
}

impl RequirementKind {
    pub fn as_str(self) -> &'static str {
        match self {
            RequirementKind::StartIf => "STARTIF",
            RequirementKind::WaitFor => "WAITFOR",
            RequirementKind::DoWhile => "DOWHILE",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Requirement {
    pub kind: RequirementKind,
    pub condition: Expr,
    pub body: Option<Body>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ForBlock {
    pub kind: BlockKind,
    pub instances: Vec<Instance>,
    pub alias: Ident,
    pub params: Vec<Ident>,
    pub body: Body,
    pub span: Span,
}

/// `ANY [k] d IN group [WHERE c] [NEAREST TO p] [WITHIN t]: body`: waits until `k` drones
/// of the group are free of every other `ANY` and meet `c`, takes the `k` nearest to `p`,
/// and runs the body once for each, with `d` bound to it, holding it until the body ends.
/// `ANY`, `IN`, `WHERE`, `NEAREST TO` and `WITHIN` are words only in such a header.
#[derive(Clone, Debug, PartialEq)]
pub struct AnyBlock {
    /// How many drones (`ANY 2 d IN ...`); `None` for one.
    pub count: Option<Expr>,
    pub alias: Ident,
    pub group: Ident,
    pub condition: Option<Expr>,
    pub nearest: Option<Expr>,
    pub within: Option<Expr>,
    pub body: Body,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    pub actor: Ident,
    pub values: Vec<Expr>,
    pub span: Span,
}

/// `SIGNAL Name WITH args` or `THROW EXCEPTION Name WITH args`.
#[derive(Clone, Debug, PartialEq)]
pub struct Raise {
    pub name: Ident,
    pub args: Vec<Arg>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Handler {
    /// `SEQUENTIAL ON` or `PARALLEL ON`; `None` when written as plain `ON` (parallel).
    pub mode: Option<BlockKind>,
    pub every: bool,
    pub signal: Ident,
    pub by: Option<Ident>,
    pub bindings: Vec<Ident>,
    /// `ONE AT A TIME` at the end of the header (only with `ON EVERY`): each firing starts
    /// when the previous firing of this handler has finished. The span of the phrase.
    pub one_at_a_time: Option<Span>,
    pub body: Body,
    pub span: Span,
}

/// `OPERATOR SIGNAL Name, Name`: `OPERATOR` is a word only at the start of such a line.
#[derive(Clone, Debug, PartialEq)]
pub struct OperatorSignals {
    pub names: Vec<Ident>,
    pub span: Span,
}

/// `LET name = value`: `LET` is a word only at the start of such a line, so a drone or
/// capability called `LET` stays what it was. The name is visible from the next item of
/// its body to the end of that body (docs/LANGUAGE.md, section 3).
#[derive(Clone, Debug, PartialEq)]
pub struct Let {
    pub name: Ident,
    pub value: Expr,
    pub span: Span,
}

/// `ALLOW CODE "reason"`: `ALLOW` is a word only at the start of a line, before a code.
#[derive(Clone, Debug, PartialEq)]
pub struct Allow {
    /// The code as written (`W203`); the checker says whether it is a warning's.
    pub code: Ident,
    /// Why the warning is acknowledged, without its quotes.
    pub reason: String,
    pub span: Span,
}

/// `Block_Name ABORT`: stops the named SEQUENTIAL or PARALLEL block wherever it runs.
#[derive(Clone, Debug, PartialEq)]
pub struct StopBlock {
    pub block: Ident,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ExceptionHandler {
    pub exception: Ident,
    pub by: Option<Ident>,
    pub bindings: Vec<Ident>,
    pub body: Body,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct IfChain {
    /// `IF c:` then every `ELSE IF c:`, in order.
    pub branches: Vec<(Expr, Body)>,
    pub otherwise: Option<Body>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Arg {
    pub name: Option<Ident>,
    pub value: Expr,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Unit {
    Metre,
    Kilometre,
    Second,
    Minute,
    Hour,
    MetrePerSecond,
    KilometrePerHour,
    Degree,
    Percent,
}

impl Unit {
    pub const ALL: &'static [Unit] = &[
        Unit::Metre,
        Unit::Kilometre,
        Unit::Second,
        Unit::Minute,
        Unit::Hour,
        Unit::MetrePerSecond,
        Unit::KilometrePerHour,
        Unit::Degree,
        Unit::Percent,
    ];
    pub fn as_str(self) -> &'static str {
        match self {
            Unit::Metre => "m",
            Unit::Kilometre => "km",
            Unit::Second => "s",
            Unit::Minute => "min",
            Unit::Hour => "h",
            Unit::MetrePerSecond => "m/s",
            Unit::KilometrePerHour => "km/h",
            Unit::Degree => "deg",
            Unit::Percent => "%",
        }
    }
    pub fn parse(text: &str) -> Option<Unit> {
        Unit::ALL.iter().copied().find(|u| u.as_str() == text)
    }
    /// The factor to SI (m, s, m/s, degrees; a percentage becomes a fraction).
    pub fn to_si(self) -> f64 {
        match self {
            Unit::Metre | Unit::Second | Unit::MetrePerSecond | Unit::Degree => 1.0,
            Unit::Kilometre => 1000.0,
            Unit::Minute => 60.0,
            Unit::Hour => 3600.0,
            Unit::KilometrePerHour => 1000.0 / 3600.0,
            Unit::Percent => 0.01,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    Or,
    And,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

impl BinaryOp {
    pub fn as_str(self) -> &'static str {
        match self {
            BinaryOp::Or => "OR",
            BinaryOp::And => "AND",
            BinaryOp::Eq => "=",
            BinaryOp::Ne => "!=",
            BinaryOp::Lt => "<",
            BinaryOp::Le => "<=",
            BinaryOp::Gt => ">",
            BinaryOp::Ge => ">=",
        }
    }
}

/// `+` and `-` between values: a position and an offset `(east, north[, up])` in metres,
/// or two quantities of one kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArithOp {
    Add,
    Sub,
}

impl ArithOp {
    pub fn as_str(self) -> &'static str {
        match self {
            ArithOp::Add => "+",
            ArithOp::Sub => "-",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    /// `digits` is the number as written, sign included, without its unit.
    Number {
        digits: String,
        value: f64,
        unit: Option<Unit>,
    },
    String(String),
    Bool(bool),
    /// `(x, y)` or `(x, y, z)`, local metres.
    Coordinates(Vec<Expr>),
    /// `GEO(lat, lon)` or `GEO(lat, lon, alt)`.
    Geo(Vec<Expr>),
    Name(Ident),
    /// `a.b`: telemetry or an attribute.
    Path(Ident, Ident),
    Distance(Box<Expr>, Box<Expr>),
    /// `a + b`, `a - b`: left-associative, looser than everything but comparisons.
    Arith(Box<Expr>, ArithOp, Box<Expr>),
    /// `OFFSET(position, distance, bearing)`: the point `distance` away on the ground,
    /// the bearing in degrees clockwise from north.
    Offset(Box<Expr>, Box<Expr>, Box<Expr>),
    /// `MIDPOINT(a, b)`: the point halfway between two positions.
    Midpoint(Box<Expr>, Box<Expr>),
    Received(Ident),
    Elapsed,
    Not(Box<Expr>),
    Binary(Box<Expr>, BinaryOp, Box<Expr>),
    Paren(Box<Expr>),
    /// Could not be read; already reported.
    Error,
}
