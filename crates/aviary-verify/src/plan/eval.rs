//! Values and conditions as the estimate can know them before flight: `None` is unknown
//! (a binding of a signal nobody can predict, telemetry the model does not follow).

use aviary_api::{arith, DroneId, FlightState, Point, Value};
use aviary_ir::{ActorRef, Expr, Field, Mission, SignalId, Slots, TiSlice};

use super::model::Flyer;

pub type Frame = Vec<Option<Value>>;

/// What an expression reads: the frame, the drones as estimated at `t`, the signals'
/// first raise times.
pub struct Scope<'a> {
    pub mission: &'a Mission,
    pub frame: &'a Frame,
    pub drones: &'a TiSlice<DroneId, Flyer>,
    pub raised: &'a TiSlice<SignalId, Option<f64>>,
    /// The first raise times of the walk before, for a signal this walk has not raised
    /// yet (a branch walked later may raise it earlier in time), and whether they were read.
    pub known: &'a TiSlice<SignalId, Option<f64>>,
    pub read_known: &'a std::cell::Cell<bool>,
    /// When the walk first guessed; a drone read ahead of `t` is a guess.
    pub guessed: &'a std::cell::Cell<f64>,
    pub t: f64,
}

impl Scope<'_> {
    pub fn actor(&self, actor: &ActorRef) -> Option<DroneId> {
        match actor {
            ActorRef::Drone(d) => Some(*d),
            ActorRef::Group(g) => g.first().copied(),
            ActorRef::Slot(s) => match self.frame.slot(*s)? {
                Some(Value::Actor(d)) => Some(*d),
                _ => None,
            },
        }
    }

    pub fn eval(&self, e: &Expr) -> Option<Value> {
        Some(match e {
            Expr::Const(v) => v.clone(),
            Expr::Slot(s) => self.frame.slot(*s)?.clone()?,
            Expr::Actor(a) => Value::Actor(self.actor(a)?),
            Expr::Telemetry(a, field) => self.telemetry(self.actor(a)?, *field)?,
            // The world says which drones have the attribute: one without reads no value.
            Expr::Attribute(a, i) => {
                self.mission.attribute(*i, self.actor(a)?).unwrap_or(Value::Absent)
            }
            Expr::Point(parts) => {
                let n = parts.borrowed().try_map(|p| number(&self.eval(p)?))?;
                Value::Position(Point { x: n.x, y: n.y, z: n.z })
            }
            Expr::Geo(parts) => {
                let n = parts.borrowed().try_map(|p| number(&self.eval(p)?))?;
                let p = self.mission.origin?.place(n.x, n.y, n.z);
                Value::Position(Point { x: p[0], y: p[1], z: n.z.map(|_| p[2]) })
            }
            Expr::Distance(a, b) => {
                let (p, q) = (self.position(a)?, self.position(b)?);
                Value::Number(((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt())
            }
            Expr::Add(a, b) | Expr::Sub(a, b) => {
                let sign = if matches!(e, Expr::Add(..)) { 1.0 } else { -1.0 };
                arith::add(&self.placed(a)?, &self.eval(b)?, sign)?
            }
            Expr::Offset(p, d, b) => {
                let p = arith::point_of(&self.placed(p)?)?;
                let (d, b) = (number(&self.eval(d)?)?, number(&self.eval(b)?)?);
                Value::Position(arith::offset(p, d, b))
            }
            Expr::Midpoint(a, b) => {
                let (a, b) =
                    (arith::point_of(&self.placed(a)?)?, arith::point_of(&self.placed(b)?)?);
                Value::Position(arith::midpoint(a, b))
            }
            Expr::Elapsed => Value::Number(self.t),
            Expr::Received(s) => {
                let at = match self.raised.get(*s).copied().flatten() {
                    Some(at) => Some(at),
                    None => {
                        self.read_known.set(true);
                        self.known.get(*s).copied().flatten()
                    }
                };
                Value::Bool(at.is_some_and(|at| at <= self.t))
            }
            Expr::Not(x) => Value::Bool(!truth(&self.eval(x)?)?),
            Expr::And(x, y) => {
                match (self.eval(x).as_ref().and_then(truth), self.eval(y).as_ref().and_then(truth))
                {
                    (Some(false), _) | (_, Some(false)) => Value::Bool(false),
                    (Some(true), Some(true)) => Value::Bool(true),
                    _ => return None,
                }
            }
            Expr::Or(x, y) => {
                match (self.eval(x).as_ref().and_then(truth), self.eval(y).as_ref().and_then(truth))
                {
                    (Some(true), _) | (_, Some(true)) => Value::Bool(true),
                    (Some(false), Some(false)) => Value::Bool(false),
                    _ => return None,
                }
            }
            Expr::Compare(x, op, y) => Value::Bool(op.holds(&self.eval(x)?, &self.eval(y)?)),
        })
    }

    pub fn condition(&self, e: &Expr) -> Option<bool> {
        truth(&self.eval(e)?)
    }

    /// A value where a drone stands for where the estimate has it, as the engine reads
    /// `drone.position`: what position arithmetic starts from.
    fn placed(&self, e: &Expr) -> Option<Value> {
        match self.eval(e)? {
            Value::Actor(d) => self.telemetry(d, Field::Position),
            v @ (Value::Number(_)
            | Value::Text(_)
            | Value::Symbol(_)
            | Value::Bool(_)
            | Value::Position(_)
            | Value::Area(_)
            | Value::Remainder(_)
            | Value::Absent) => Some(v),
        }
    }

    fn position(&self, e: &Expr) -> Option<[f64; 2]> {
        match self.eval(e)? {
            Value::Position(p) => Some([p.x, p.y]),
            Value::Actor(d) => self.flyer(d).map(|f| [f.pos[0], f.pos[1]]),
            Value::Number(_)
            | Value::Text(_)
            | Value::Symbol(_)
            | Value::Bool(_)
            | Value::Area(_)
            | Value::Remainder(_)
            | Value::Absent => None,
        }
    }

    /// A drone as the walk has it. A branch walked before may have taken it past `t`
    /// (the walk goes branch by branch, not in time): what is read then is its state
    /// later on, a guess.
    fn flyer(&self, d: DroneId) -> Option<&Flyer> {
        let f = self.drones.get(d)?;
        if f.free_at > self.t + 1e-9 {
            self.guessed.set(self.guessed.get().min(self.t));
        }
        Some(f)
    }

    fn telemetry(&self, d: DroneId, field: Field) -> Option<Value> {
        let f = self.flyer(d)?;
        Some(match field {
            Field::Position => {
                Value::Position(Point { x: f.pos[0], y: f.pos[1], z: Some(f.pos[2]) })
            }
            Field::Altitude => Value::Number(f.pos[2]),
            Field::Battery => Value::Number(f.battery_at(self.t)),
            Field::State => Value::Symbol(
                if f.airborne { FlightState::Flying } else { FlightState::Landed }
                    .as_str()
                    .to_string(),
            ),
            // Between activities the estimate has the drone at rest.
            Field::Speed => Value::Number(0.0),
            // What a Sweep will leave is known only in flight.
            // The wind a sensor will read is known only in flight.
            Field::Heading | Field::Link | Field::Remaining | Field::Wind | Field::Payload => {
                return None
            }
        })
    }
}

fn number(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => Some(*n),
        Value::Text(_)
        | Value::Symbol(_)
        | Value::Bool(_)
        | Value::Position(_)
        | Value::Area(_)
        | Value::Actor(_)
        | Value::Remainder(_)
        | Value::Absent => None,
    }
}

fn truth(v: &Value) -> Option<bool> {
    match v {
        Value::Bool(b) => Some(*b),
        // What a drone does not have is not true, as the engine reads it.
        Value::Absent => Some(false),
        Value::Number(_)
        | Value::Text(_)
        | Value::Symbol(_)
        | Value::Position(_)
        | Value::Area(_)
        | Value::Actor(_)
        | Value::Remainder(_) => None,
    }
}
