//! Evaluating expressions at run time.

use aviary_api::{arith, Backend, DroneId, Point, Value};
use aviary_ir::{ActorRef, Expr, Field, Mission, SignalId, Slots, TiSlice};

/// What an expression needs from the run: the frame, telemetry, signals, the clock.
pub(crate) struct Env<'a> {
    pub mission: &'a Mission,
    pub backend: &'a dyn Backend,
    pub coverage: &'a crate::coverage::Coverage,
    pub frame: &'a [Value],
    pub received: &'a TiSlice<SignalId, bool>,
    /// When the mission started: `ELAPSED` is read from the clock only when evaluated
    /// (most expressions never ask, and reading tokio's clock is not free).
    pub start: aviary_clock::Instant,
}

impl Env<'_> {
    pub fn actor(&self, r: &ActorRef) -> Option<DroneId> {
        match r {
            ActorRef::Drone(d) => Some(*d),
            ActorRef::Group(g) => g.first().copied(),
            ActorRef::Slot(s) => match self.frame.slot(*s) {
                Some(Value::Actor(d)) => Some(*d),
                _ => None,
            },
        }
    }

    pub fn eval(&self, e: &Expr) -> Value {
        match e {
            Expr::Const(v) => v.clone(),
            Expr::Slot(s) => self.frame.slot(*s).cloned().unwrap_or(Value::Absent),
            Expr::Actor(r) => self.actor(r).map_or(Value::Absent, Value::Actor),
            Expr::Telemetry(r, field) => match self.actor(r) {
                Some(d) if *field == Field::Remaining => self.coverage.remaining(d),
                Some(d) => telemetry(self.backend, d, *field),
                None => Value::Absent,
            },
            Expr::Attribute(r, i) => {
                let d = self.actor(r);
                d.and_then(|d| self.mission.attribute(*i, d)).unwrap_or(Value::Absent)
            }
            Expr::Point(parts) => {
                let n = parts.borrowed().map(|p| number(&self.eval(p)));
                Value::Position(Point { x: n.x, y: n.y, z: n.z })
            }
            Expr::Geo(parts) => {
                let n = parts.borrowed().map(|p| number(&self.eval(p)));
                let origin = self.mission.origin.unwrap_or_default();
                let [x, y, z] = origin.place(n.x, n.y, n.z);
                Value::Position(Point { x, y, z: (!z.is_nan()).then_some(z) })
            }
            Expr::Distance(a, b) => {
                let (a, b) = (self.position(&self.eval(a)), self.position(&self.eval(b)));
                Value::Number(((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt())
            }
            Expr::Add(a, b) | Expr::Sub(a, b) => {
                let sign = if matches!(e, Expr::Add(..)) { 1.0 } else { -1.0 };
                let (a, b) = (self.placed(self.eval(a)), self.eval(b));
                arith::add(&a, &b, sign).unwrap_or(Value::Absent)
            }
            Expr::Offset(p, d, b) => {
                let p = arith::point_of(&self.placed(self.eval(p)));
                match (p, self.eval(d), self.eval(b)) {
                    (Some(p), Value::Number(d), Value::Number(b)) => {
                        Value::Position(arith::offset(p, d, b))
                    }
                    _ => Value::Absent,
                }
            }
            Expr::Midpoint(a, b) => {
                let a = arith::point_of(&self.placed(self.eval(a)));
                let b = arith::point_of(&self.placed(self.eval(b)));
                match (a, b) {
                    (Some(a), Some(b)) => Value::Position(arith::midpoint(a, b)),
                    _ => Value::Absent,
                }
            }
            Expr::Elapsed => {
                Value::Number((aviary_clock::Instant::now() - self.start).as_secs_f64())
            }
            Expr::Received(s) => Value::Bool(self.received.get(*s).copied().unwrap_or(false)),
            Expr::Not(x) => Value::Bool(!truth(&self.eval(x))),
            Expr::And(a, b) => Value::Bool(truth(&self.eval(a)) && truth(&self.eval(b))),
            Expr::Or(a, b) => Value::Bool(truth(&self.eval(a)) || truth(&self.eval(b))),
            Expr::Compare(a, op, b) => Value::Bool(op.holds(&self.eval(a), &self.eval(b))),
        }
    }

    pub fn truth(&self, e: &Expr) -> bool {
        truth(&self.eval(e))
    }

    /// A drone as where it is now (its position, as `drone.position` reads it); any
    /// other value as it is. What position arithmetic starts from.
    fn placed(&self, v: Value) -> Value {
        match v {
            Value::Actor(d) => telemetry(self.backend, d, Field::Position),
            v => v,
        }
    }

    /// Where a value is, on the ground: a drone now, an area's centroid, a point.
    pub fn position(&self, v: &Value) -> [f64; 2] {
        match v {
            Value::Position(p) => [p.x, p.y],
            Value::Actor(d) => {
                let p = self.backend.telemetry(*d).gps_position;
                [p[0], p[1]]
            }
            Value::Area(poly) => aviary_api::centroid(poly),
            _ => [f64::NAN, f64::NAN],
        }
    }
}

fn telemetry(backend: &dyn Backend, d: DroneId, field: Field) -> Value {
    let t = backend.telemetry(d);
    match field {
        // What the GPS says: the true position plus its error, when the backend has one.
        Field::Position => Value::Position(Point {
            x: t.gps_position[0],
            y: t.gps_position[1],
            z: Some(t.gps_position[2]),
        }),
        Field::Altitude => Value::Number(t.gps_position[2]),
        Field::Speed => Value::Number(t.speed),
        Field::Heading => Value::Number(t.heading),
        Field::Battery => Value::Number(t.battery),
        Field::State => Value::Symbol(t.state.as_str().to_string()),
        Field::Link => Value::Symbol(if t.link { "Connected" } else { "Lost" }.to_string()),
        // Without a wind sensor: no value, as for an attribute the drone does not have.
        Field::Wind => t.wind.map_or(Value::Absent, |w| Value::Number(w[0].hypot(w[1]))),
        // Carrying nothing: no value, as for an attribute the drone does not have.
        Field::Payload => backend.payload(d).map_or(Value::Absent, Value::Symbol),
        // The engine's, not the backend's: read in `Env::eval`.
        Field::Remaining => Value::Absent,
    }
}

pub(crate) fn truth(v: &Value) -> bool {
    matches!(v, Value::Bool(true))
}

fn number(v: &Value) -> f64 {
    match v {
        Value::Number(n) => *n,
        _ => f64::NAN,
    }
}
