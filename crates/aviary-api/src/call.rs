//! A middle-layer call with its arguments read: [`FunctionCall`], one variant per
//! [`Function`], each argument a named, typed field (`FunctionCall::TakeOff { alt }`).
//!
//! Arguments are read from the values a mission gives in one place,
//! [`FunctionCall::new`]: the engine reads them once as it makes the call, and every
//! backend (and the coverage of a path, [`crate::coverage`]) matches on the variants.
//! Reading checks what the checker checks, each value's kind against the function's
//! [`crate::Signature`], and no more: whether a number is finite, an area encloses
//! something or an altitude is allowed is each backend's to refuse, with its reasons.
//! A value the checker could not judge (a signal's value passed on) and of the wrong
//! kind is refused here, in the words the backends used when they read arguments
//! themselves (`` `duration` must be a finite number, not (1, 2.5) ``).
//!
//! A call keeps each value as given (an area given for a position is kept as the area),
//! so the trace shows its arguments as the mission gave them ([`FunctionCall::shown`]).

use std::fmt;
use std::sync::Arc;

use crate::trace::Shown;
use crate::{Function, Point, Remainder, Value};

/// A position argument: a position, or an area, which stands for its centroid.
#[derive(Clone, Debug, PartialEq)]
pub enum Place {
    Point(Point),
    Area(Vec<[f64; 2]>),
}

/// What `Sweep` sweeps: an area, or what a `Sweep` left (`drone.remaining`).
#[derive(Clone, Debug, PartialEq)]
pub enum Region {
    Area(Vec<[f64; 2]>),
    Left(Arc<Remainder>),
}

/// One of `FollowPath`'s points: a position, an area (its centroid), or what a `Sweep`
/// or `FollowPath` left (the points of its path).
#[derive(Clone, Debug, PartialEq)]
pub enum Waypoint {
    Point(Point),
    Area(Vec<[f64; 2]>),
    Left(Arc<Remainder>),
}

/// When a call's arguments are read, and so what one argument is: in flight, a value
/// ([`Flown`]); before it, in the plan, a value that may be known only in flight
/// ([`Planned`]). One reading of the signature ([`CallOf::new`]) serves both.
pub trait Stage: Clone + fmt::Debug + PartialEq {
    /// An argument as the caller has it.
    type Arg;
    /// A field read from one argument: the value (in flight), or the value if known.
    type Of<T: Clone + fmt::Debug + PartialEq>: Clone + fmt::Debug + PartialEq;
    /// Reads one argument with `read`, which refuses a value of the wrong kind.
    fn read<T: Clone + fmt::Debug + PartialEq>(
        arg: &Self::Arg,
        read: impl FnOnce(&Value) -> Result<T, String>,
    ) -> Result<Self::Of<T>, String>;
    /// The argument's value, where it is known.
    fn known(arg: &Self::Arg) -> Option<&Value>;
}

/// In flight: every argument is a value, and one of the wrong kind refuses the call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Flown {}

/// Before the flight (the plan): an argument is `None` when its value is known only in
/// flight (a signal's value passed on). A value of the wrong kind is read as unknown: the
/// flight would refuse the call, and the plan does not guess which way.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Planned {}

impl Stage for Flown {
    type Arg = Value;
    type Of<T: Clone + fmt::Debug + PartialEq> = T;
    #[inline]
    fn read<T: Clone + fmt::Debug + PartialEq>(
        arg: &Value,
        read: impl FnOnce(&Value) -> Result<T, String>,
    ) -> Result<T, String> {
        read(arg)
    }
    #[inline]
    fn known(arg: &Value) -> Option<&Value> {
        Some(arg)
    }
}

impl Stage for Planned {
    type Arg = Option<Value>;
    type Of<T: Clone + fmt::Debug + PartialEq> = Option<T>;
    fn read<T: Clone + fmt::Debug + PartialEq>(
        arg: &Option<Value>,
        read: impl FnOnce(&Value) -> Result<T, String>,
    ) -> Result<Option<T>, String> {
        Ok(arg.as_ref().and_then(|v| read(v).ok()))
    }
    fn known(arg: &Option<Value>) -> Option<&Value> {
        arg.as_ref()
    }
}

/// A middle-layer call as flown: its function and its arguments, read
/// ([`CallOf::new`]).
pub type FunctionCall = CallOf<Flown>;

/// A middle-layer call as the plan reads it before the flight: each argument's value
/// where it is known then.
pub type PlannedCall = CallOf<Planned>;

/// A middle-layer call's function and its arguments, read ([`CallOf::new`]) at a
/// [`Stage`]. An optional argument not given is `None`; the field names are the
/// parameters' names of [`Function::signature`].
#[derive(Clone, Debug, PartialEq)]
pub enum CallOf<S: Stage> {
    Arm,
    Disarm,
    TakeOff {
        alt: S::Of<f64>,
    },
    Land,
    ReturnToLaunch,
    FlyToPosition {
        pos: S::Of<Place>,
        speed: Option<S::Of<f64>>,
    },
    DescendTo {
        alt: S::Of<f64>,
    },
    AscendTo {
        alt: S::Of<f64>,
    },
    Hover {
        duration: S::Of<f64>,
    },
    Orbit {
        center: S::Of<Place>,
        radius: S::Of<f64>,
        laps: Option<S::Of<f64>>,
    },
    Sweep {
        area: S::Of<Region>,
        spacing: S::Of<f64>,
    },
    StartStreaming,
    StopStreaming,
    /// `kind`: a kind of target, a symbol (or a text).
    StartDetection {
        kind: S::Of<String>,
    },
    StopDetection {
        kind: S::Of<String>,
    },
    /// `kind`: a kind of payload, a symbol (or a text).
    LoadPayload {
        kind: S::Of<String>,
    },
    ReleasePayload,
    /// `points...[, speed]`: the speed is a last argument that is a number.
    FollowPath {
        points: Vec<S::Of<Waypoint>>,
        speed: Option<S::Of<f64>>,
    },
}

/// `FollowPath`'s points and its speed, as read at a stage.
type Path<S> = (Vec<<S as Stage>::Of<Waypoint>>, Option<<S as Stage>::Of<f64>>);

/// The arguments of one call, read in order; each reader says what it wanted.
struct Reader<'a, S: Stage> {
    function: Function,
    args: &'a [S::Arg],
    next: usize,
}

impl<'a, S: Stage> Reader<'a, S> {
    fn value(&mut self, name: &str) -> Result<&'a S::Arg, String> {
        let v = self.args.get(self.next).ok_or_else(|| format!("missing argument `{name}`"))?;
        self.next += 1;
        Ok(v)
    }

    fn optional(&mut self) -> Option<&'a S::Arg> {
        let v = self.args.get(self.next)?;
        self.next += 1;
        Some(v)
    }

    fn number(&mut self, name: &str) -> Result<S::Of<f64>, String> {
        S::read(self.value(name)?, |v| number(v, name))
    }

    fn opt_number(&mut self, name: &str) -> Result<Option<S::Of<f64>>, String> {
        self.optional().map(|v| S::read(v, |v| number(v, name))).transpose()
    }

    fn place(&mut self, name: &str) -> Result<S::Of<Place>, String> {
        S::read(self.value(name)?, |v| match v {
            Value::Position(p) => Ok(Place::Point(*p)),
            Value::Area(corners) => Ok(Place::Area(corners.clone())),
            other => Err(format!("`{name}` must be a position, not {other}")),
        })
    }

    fn region(&mut self, name: &str) -> Result<S::Of<Region>, String> {
        S::read(self.value(name)?, |v| match v {
            Value::Area(corners) => Ok(Region::Area(corners.clone())),
            Value::Remainder(left) => Ok(Region::Left(left.clone())),
            other => Err(format!("`{name}` must be an area of at least 3 corners, not {other}")),
        })
    }

    fn kind(&mut self, name: &str) -> Result<S::Of<String>, String> {
        S::read(self.value(name)?, |v| match v {
            Value::Symbol(s) | Value::Text(s) => Ok(s.clone()),
            other => Err(format!("`{name}` must be a kind such as Body, not {other}")),
        })
    }

    /// `FollowPath`'s arguments: every one a point, but a last number, the speed (a last
    /// argument known only in flight is read as a point).
    fn path(&mut self) -> Result<Path<S>, String> {
        let rest = &self.args[self.next.min(self.args.len())..];
        self.next += rest.len();
        let (points, speed) = match rest.split_last() {
            Some((last, points)) if matches!(S::known(last), Some(Value::Number(_))) => {
                (points, Some(S::read(last, |v| number(v, "speed"))?))
            }
            _ => (rest, None),
        };
        let points = points
            .iter()
            .enumerate()
            .map(|(i, v)| {
                S::read(v, |v| match v {
                    Value::Position(p) => Ok(Waypoint::Point(*p)),
                    Value::Area(corners) => Ok(Waypoint::Area(corners.clone())),
                    Value::Remainder(left) => Ok(Waypoint::Left(left.clone())),
                    other => Err(format!(
                        "`points[{i}]` must be a position, or what a Sweep or FollowPath left, not {other}"
                    )),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok((points, speed))
    }

    /// Every argument was read: one more is refused.
    #[inline]
    fn done(self) -> Result<(), String> {
        if self.next < self.args.len() {
            return Err(self.too_many());
        }
        Ok(())
    }

    #[cold]
    fn too_many(&self) -> String {
        format!(
            "{} takes {} argument{}, not {}",
            self.function.signature().signature(),
            if self.next == 0 { "no".to_string() } else { format!("at most {}", self.next) },
            if self.next == 1 { "" } else { "s" },
            self.args.len()
        )
    }
}

fn number(v: &Value, name: &str) -> Result<f64, String> {
    match v {
        Value::Number(n) => Ok(*n),
        other => Err(format!("`{name}` must be a finite number, not {other}")),
    }
}

impl<S: Stage> CallOf<S> {
    /// Reads the arguments a mission gave `function`, in the order of its signature
    /// ([`Function::signature`]). The one place they are read: refused, with the reason,
    /// when one is missing, one too many, or (in flight) one of a kind the parameter does
    /// not take. (Inline: the engine reads every call it makes with it.)
    #[inline]
    pub fn new(function: Function, args: &[S::Arg]) -> Result<CallOf<S>, String> {
        let mut r = Reader::<S> { function, args, next: 0 };
        let call = match function {
            Function::Arm => CallOf::Arm,
            Function::Disarm => CallOf::Disarm,
            Function::TakeOff => CallOf::TakeOff { alt: r.number("alt")? },
            Function::Land => CallOf::Land,
            Function::ReturnToLaunch => CallOf::ReturnToLaunch,
            Function::FlyToPosition => {
                CallOf::FlyToPosition { pos: r.place("pos")?, speed: r.opt_number("speed")? }
            }
            Function::DescendTo => CallOf::DescendTo { alt: r.number("alt")? },
            Function::AscendTo => CallOf::AscendTo { alt: r.number("alt")? },
            Function::Hover => CallOf::Hover { duration: r.number("duration")? },
            Function::Orbit => CallOf::Orbit {
                center: r.place("center")?,
                radius: r.number("radius")?,
                laps: r.opt_number("laps")?,
            },
            Function::Sweep => {
                CallOf::Sweep { area: r.region("area")?, spacing: r.number("spacing")? }
            }
            Function::StartStreaming => CallOf::StartStreaming,
            Function::StopStreaming => CallOf::StopStreaming,
            Function::StartDetection => CallOf::StartDetection { kind: r.kind("kind")? },
            Function::StopDetection => CallOf::StopDetection { kind: r.kind("kind")? },
            Function::LoadPayload => CallOf::LoadPayload { kind: r.kind("kind")? },
            Function::ReleasePayload => CallOf::ReleasePayload,
            Function::FollowPath => {
                let (points, speed) = r.path()?;
                CallOf::FollowPath { points, speed }
            }
        };
        r.done()?;
        Ok(call)
    }

    /// The function called.
    #[inline]
    pub fn function(&self) -> Function {
        match self {
            CallOf::Arm => Function::Arm,
            CallOf::Disarm => Function::Disarm,
            CallOf::TakeOff { .. } => Function::TakeOff,
            CallOf::Land => Function::Land,
            CallOf::ReturnToLaunch => Function::ReturnToLaunch,
            CallOf::FlyToPosition { .. } => Function::FlyToPosition,
            CallOf::DescendTo { .. } => Function::DescendTo,
            CallOf::AscendTo { .. } => Function::AscendTo,
            CallOf::Hover { .. } => Function::Hover,
            CallOf::Orbit { .. } => Function::Orbit,
            CallOf::Sweep { .. } => Function::Sweep,
            CallOf::StartStreaming => Function::StartStreaming,
            CallOf::StopStreaming => Function::StopStreaming,
            CallOf::StartDetection { .. } => Function::StartDetection,
            CallOf::StopDetection { .. } => Function::StopDetection,
            CallOf::LoadPayload { .. } => Function::LoadPayload,
            CallOf::ReleasePayload => Function::ReleasePayload,
            CallOf::FollowPath { .. } => Function::FollowPath,
        }
    }
}

/// One argument of a flown call, as read: what [`FunctionCall::shown`] and
/// [`FunctionCall::args`] each turn into their form, so the two cannot disagree on the
/// order.
enum Part<'a> {
    Number(f64),
    Place(&'a Place),
    Region(&'a Region),
    Kind(&'a str),
    Waypoint(&'a Waypoint),
}

impl FunctionCall {
    /// Each argument given, in order.
    fn parts<'a>(&'a self, mut each: impl FnMut(Part<'a>)) {
        fn opt<'a>(n: &Option<f64>, each: &mut impl FnMut(Part<'a>)) {
            if let Some(n) = n {
                each(Part::Number(*n));
            }
        }
        match self {
            CallOf::Arm
            | CallOf::Disarm
            | CallOf::Land
            | CallOf::ReturnToLaunch
            | CallOf::StartStreaming
            | CallOf::StopStreaming
            | CallOf::ReleasePayload => {}
            CallOf::TakeOff { alt } | CallOf::DescendTo { alt } | CallOf::AscendTo { alt } => {
                each(Part::Number(*alt))
            }
            CallOf::Hover { duration } => each(Part::Number(*duration)),
            CallOf::FlyToPosition { pos, speed } => {
                each(Part::Place(pos));
                opt(speed, &mut each);
            }
            CallOf::Orbit { center, radius, laps } => {
                each(Part::Place(center));
                each(Part::Number(*radius));
                opt(laps, &mut each);
            }
            CallOf::Sweep { area, spacing } => {
                each(Part::Region(area));
                each(Part::Number(*spacing));
            }
            CallOf::StartDetection { kind }
            | CallOf::StopDetection { kind }
            | CallOf::LoadPayload { kind } => each(Part::Kind(kind)),
            CallOf::FollowPath { points, speed } => {
                points.iter().for_each(|p| each(Part::Waypoint(p)));
                opt(speed, &mut each);
            }
        }
    }

    /// The arguments as the trace's `args` shows them: those given, in order, each as
    /// the mission gave it (a kind given as a text and as a symbol show alike).
    pub fn shown(&self) -> Vec<Shown<'_>> {
        let mut out = Vec::new();
        self.parts(|p| {
            out.push(match p {
                Part::Number(n) => Shown::Number(n),
                Part::Place(place) => place.shown(),
                Part::Region(region) => region.shown(),
                Part::Kind(kind) => Shown::Text(kind.into()),
                Part::Waypoint(point) => point.shown(),
            })
        });
        out
    }

    /// The arguments as values, in order: what [`FunctionCall::new`] reads back as this
    /// call (a kind is a symbol).
    pub fn args(&self) -> Vec<Value> {
        let mut out = Vec::new();
        self.parts(|p| {
            out.push(match p {
                Part::Number(n) => Value::Number(n),
                Part::Place(place) => place.value(),
                Part::Region(region) => region.value(),
                Part::Kind(kind) => Value::Symbol(kind.to_string()),
                Part::Waypoint(point) => point.value(),
            })
        });
        out
    }
}

impl Place {
    /// The point it stands for: a position itself, an area its centroid (without an
    /// altitude). `None` for an area without corners, or a position whose coordinates
    /// are not finite.
    pub fn point(&self) -> Option<Point> {
        match self {
            Place::Point(p) if finite(p) => Some(*p),
            Place::Point(_) => None,
            Place::Area(corners) if !corners.is_empty() => {
                let c = crate::centroid(corners);
                Some(Point::flat(c[0], c[1]))
            }
            Place::Area(_) => None,
        }
    }
    pub fn value(&self) -> Value {
        match self {
            Place::Point(p) => Value::Position(*p),
            Place::Area(corners) => Value::Area(corners.clone()),
        }
    }
    fn shown(&self) -> Shown<'_> {
        match self {
            Place::Point(p) => Shown::Position(*p),
            Place::Area(corners) => Shown::Area(corners.into()),
        }
    }
}

impl Region {
    pub fn value(&self) -> Value {
        match self {
            Region::Area(corners) => Value::Area(corners.clone()),
            Region::Left(left) => Value::Remainder(left.clone()),
        }
    }
    fn shown(&self) -> Shown<'_> {
        match self {
            Region::Area(corners) => Shown::Area(corners.into()),
            Region::Left(left) => Shown::Remainder(std::borrow::Cow::Borrowed(left)),
        }
    }
}

impl Waypoint {
    pub fn value(&self) -> Value {
        match self {
            Waypoint::Point(p) => Value::Position(*p),
            Waypoint::Area(corners) => Value::Area(corners.clone()),
            Waypoint::Left(left) => Value::Remainder(left.clone()),
        }
    }
    fn shown(&self) -> Shown<'_> {
        match self {
            Waypoint::Point(p) => Shown::Position(*p),
            Waypoint::Area(corners) => Shown::Area(corners.into()),
            Waypoint::Left(left) => Shown::Remainder(std::borrow::Cow::Borrowed(left)),
        }
    }
}

/// A position whose coordinates are finite (an altitude, when it has one).
pub(crate) fn finite(p: &Point) -> bool {
    p.x.is_finite() && p.y.is_finite() && !matches!(p.z, Some(z) if !z.is_finite())
}

/// As the value it is, in messages (`an area of 2 corners`).
impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.value().fmt(f)
    }
}

impl fmt::Display for Region {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.value().fmt(f)
    }
}

impl fmt::Display for Waypoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.value().fmt(f)
    }
}

#[cfg(test)]
mod tests;
