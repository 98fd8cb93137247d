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

/// A middle-layer call's function and its arguments, read ([`FunctionCall::new`]). An
/// optional argument not given is `None`; the field names are the parameters' names of
/// [`Function::signature`].
#[derive(Clone, Debug, PartialEq)]
pub enum FunctionCall {
    Arm,
    Disarm,
    TakeOff {
        alt: f64,
    },
    Land,
    ReturnToLaunch,
    FlyToPosition {
        pos: Place,
        speed: Option<f64>,
    },
    DescendTo {
        alt: f64,
    },
    AscendTo {
        alt: f64,
    },
    Hover {
        duration: f64,
    },
    Orbit {
        center: Place,
        radius: f64,
        laps: Option<f64>,
    },
    Sweep {
        area: Region,
        spacing: f64,
    },
    StartStreaming,
    StopStreaming,
    /// `kind`: a kind of target, a symbol (or a text).
    StartDetection {
        kind: String,
    },
    StopDetection {
        kind: String,
    },
    /// `kind`: a kind of payload, a symbol (or a text).
    LoadPayload {
        kind: String,
    },
    ReleasePayload,
    /// `points...[, speed]`: the speed is a last argument that is a number.
    FollowPath {
        points: Vec<Waypoint>,
        speed: Option<f64>,
    },
}

/// The arguments of one call, read in order; each reader says what it wanted.
struct Reader<'a> {
    function: Function,
    args: &'a [Value],
    next: usize,
}

impl<'a> Reader<'a> {
    fn value(&mut self, name: &str) -> Result<&'a Value, String> {
        let v = self.args.get(self.next).ok_or_else(|| format!("missing argument `{name}`"))?;
        self.next += 1;
        Ok(v)
    }

    fn optional(&mut self) -> Option<&'a Value> {
        let v = self.args.get(self.next)?;
        self.next += 1;
        Some(v)
    }

    fn number(&mut self, name: &str) -> Result<f64, String> {
        number(self.value(name)?, name)
    }

    fn opt_number(&mut self, name: &str) -> Result<Option<f64>, String> {
        self.optional().map(|v| number(v, name)).transpose()
    }

    fn place(&mut self, name: &str) -> Result<Place, String> {
        match self.value(name)? {
            Value::Position(p) => Ok(Place::Point(*p)),
            Value::Area(corners) => Ok(Place::Area(corners.clone())),
            other => Err(format!("`{name}` must be a position, not {other}")),
        }
    }

    fn region(&mut self, name: &str) -> Result<Region, String> {
        match self.value(name)? {
            Value::Area(corners) => Ok(Region::Area(corners.clone())),
            Value::Remainder(left) => Ok(Region::Left(left.clone())),
            other => Err(format!("`{name}` must be an area of at least 3 corners, not {other}")),
        }
    }

    fn kind(&mut self, name: &str) -> Result<String, String> {
        match self.value(name)? {
            Value::Symbol(s) | Value::Text(s) => Ok(s.clone()),
            other => Err(format!("`{name}` must be a kind such as Body, not {other}")),
        }
    }

    /// `FollowPath`'s arguments: every one a point, but a last number, the speed.
    fn path(&mut self) -> Result<(Vec<Waypoint>, Option<f64>), String> {
        let rest = &self.args[self.next.min(self.args.len())..];
        self.next += rest.len();
        let (points, speed) = match rest.split_last() {
            Some((Value::Number(s), points)) => (points, Some(*s)),
            _ => (rest, None),
        };
        let points = points
            .iter()
            .enumerate()
            .map(|(i, v)| match v {
                Value::Position(p) => Ok(Waypoint::Point(*p)),
                Value::Area(corners) => Ok(Waypoint::Area(corners.clone())),
                Value::Remainder(left) => Ok(Waypoint::Left(left.clone())),
                other => Err(format!(
                    "`points[{i}]` must be a position, or what a Sweep or FollowPath left, not {other}"
                )),
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

impl FunctionCall {
    /// Reads the arguments a mission gave `function`, in the order of its signature
    /// ([`Function::signature`]). The one place they are read: refused, with the reason,
    /// when one is missing, one too many, or one of a kind the parameter does not take.
    /// (Inline: the engine reads every call it makes with it.)
    #[inline]
    pub fn new(function: Function, args: &[Value]) -> Result<FunctionCall, String> {
        let mut r = Reader { function, args, next: 0 };
        let call = match function {
            Function::Arm => FunctionCall::Arm,
            Function::Disarm => FunctionCall::Disarm,
            Function::TakeOff => FunctionCall::TakeOff { alt: r.number("alt")? },
            Function::Land => FunctionCall::Land,
            Function::ReturnToLaunch => FunctionCall::ReturnToLaunch,
            Function::FlyToPosition => {
                FunctionCall::FlyToPosition { pos: r.place("pos")?, speed: r.opt_number("speed")? }
            }
            Function::DescendTo => FunctionCall::DescendTo { alt: r.number("alt")? },
            Function::AscendTo => FunctionCall::AscendTo { alt: r.number("alt")? },
            Function::Hover => FunctionCall::Hover { duration: r.number("duration")? },
            Function::Orbit => FunctionCall::Orbit {
                center: r.place("center")?,
                radius: r.number("radius")?,
                laps: r.opt_number("laps")?,
            },
            Function::Sweep => {
                FunctionCall::Sweep { area: r.region("area")?, spacing: r.number("spacing")? }
            }
            Function::StartStreaming => FunctionCall::StartStreaming,
            Function::StopStreaming => FunctionCall::StopStreaming,
            Function::StartDetection => FunctionCall::StartDetection { kind: r.kind("kind")? },
            Function::StopDetection => FunctionCall::StopDetection { kind: r.kind("kind")? },
            Function::LoadPayload => FunctionCall::LoadPayload { kind: r.kind("kind")? },
            Function::ReleasePayload => FunctionCall::ReleasePayload,
            Function::FollowPath => {
                let (points, speed) = r.path()?;
                FunctionCall::FollowPath { points, speed }
            }
        };
        r.done()?;
        Ok(call)
    }

    /// The function called.
    #[inline]
    pub fn function(&self) -> Function {
        match self {
            FunctionCall::Arm => Function::Arm,
            FunctionCall::Disarm => Function::Disarm,
            FunctionCall::TakeOff { .. } => Function::TakeOff,
            FunctionCall::Land => Function::Land,
            FunctionCall::ReturnToLaunch => Function::ReturnToLaunch,
            FunctionCall::FlyToPosition { .. } => Function::FlyToPosition,
            FunctionCall::DescendTo { .. } => Function::DescendTo,
            FunctionCall::AscendTo { .. } => Function::AscendTo,
            FunctionCall::Hover { .. } => Function::Hover,
            FunctionCall::Orbit { .. } => Function::Orbit,
            FunctionCall::Sweep { .. } => Function::Sweep,
            FunctionCall::StartStreaming => Function::StartStreaming,
            FunctionCall::StopStreaming => Function::StopStreaming,
            FunctionCall::StartDetection { .. } => Function::StartDetection,
            FunctionCall::StopDetection { .. } => Function::StopDetection,
            FunctionCall::LoadPayload { .. } => Function::LoadPayload,
            FunctionCall::ReleasePayload => Function::ReleasePayload,
            FunctionCall::FollowPath { .. } => Function::FollowPath,
        }
    }

    /// The arguments as the trace's `args` shows them: those given, in order, each as
    /// the mission gave it (a kind given as a text and as a symbol show alike).
    pub fn shown(&self) -> Vec<Shown<'_>> {
        let num = |n: &f64| Shown::Number(*n);
        let opt = |n: &Option<f64>| n.as_ref().map(num);
        match self {
            FunctionCall::Arm
            | FunctionCall::Disarm
            | FunctionCall::Land
            | FunctionCall::ReturnToLaunch
            | FunctionCall::StartStreaming
            | FunctionCall::StopStreaming
            | FunctionCall::ReleasePayload => Vec::new(),
            FunctionCall::TakeOff { alt }
            | FunctionCall::DescendTo { alt }
            | FunctionCall::AscendTo { alt } => vec![num(alt)],
            FunctionCall::Hover { duration } => vec![num(duration)],
            FunctionCall::FlyToPosition { pos, speed } => {
                std::iter::once(pos.shown()).chain(opt(speed)).collect()
            }
            FunctionCall::Orbit { center, radius, laps } => {
                [center.shown(), num(radius)].into_iter().chain(opt(laps)).collect()
            }
            FunctionCall::Sweep { area, spacing } => vec![area.shown(), num(spacing)],
            FunctionCall::StartDetection { kind }
            | FunctionCall::StopDetection { kind }
            | FunctionCall::LoadPayload { kind } => vec![Shown::Text(kind.as_str().into())],
            FunctionCall::FollowPath { points, speed } => {
                points.iter().map(Waypoint::shown).chain(opt(speed)).collect()
            }
        }
    }

    /// The arguments as values, in order: what [`FunctionCall::new`] reads back as this
    /// call (a kind is a symbol).
    pub fn args(&self) -> Vec<Value> {
        let opt = |n: &Option<f64>| n.map(Value::Number);
        match self {
            FunctionCall::Arm
            | FunctionCall::Disarm
            | FunctionCall::Land
            | FunctionCall::ReturnToLaunch
            | FunctionCall::StartStreaming
            | FunctionCall::StopStreaming
            | FunctionCall::ReleasePayload => Vec::new(),
            FunctionCall::TakeOff { alt }
            | FunctionCall::DescendTo { alt }
            | FunctionCall::AscendTo { alt } => vec![Value::Number(*alt)],
            FunctionCall::Hover { duration } => vec![Value::Number(*duration)],
            FunctionCall::FlyToPosition { pos, speed } => {
                std::iter::once(pos.value()).chain(opt(speed)).collect()
            }
            FunctionCall::Orbit { center, radius, laps } => {
                [center.value(), Value::Number(*radius)].into_iter().chain(opt(laps)).collect()
            }
            FunctionCall::Sweep { area, spacing } => vec![area.value(), Value::Number(*spacing)],
            FunctionCall::StartDetection { kind }
            | FunctionCall::StopDetection { kind }
            | FunctionCall::LoadPayload { kind } => vec![Value::Symbol(kind.clone())],
            FunctionCall::FollowPath { points, speed } => {
                points.iter().map(Waypoint::value).chain(opt(speed)).collect()
            }
        }
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
