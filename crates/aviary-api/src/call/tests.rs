use std::sync::Arc;

use proptest::prelude::*;

use super::*;
use crate::{Kind, Names};

fn number() -> impl Strategy<Value = f64> {
    -1e6..1e6f64
}

fn corners() -> impl Strategy<Value = Vec<[f64; 2]>> {
    proptest::collection::vec([number(), number()], 0..5)
}

fn point() -> impl Strategy<Value = Point> {
    (number(), number(), proptest::option::of(number())).prop_map(|(x, y, z)| Point { x, y, z })
}

fn remainder() -> impl Strategy<Value = Arc<Remainder>> {
    prop_oneof![
        Just(Arc::new(Remainder::Nothing)),
        (proptest::collection::vec([[number(), number()], [number(), number()]], 1..3), number())
            .prop_map(|(lanes, spacing)| Arc::new(Remainder::lanes(lanes, spacing))),
        proptest::collection::vec(point(), 1..3).prop_map(|p| Arc::new(Remainder::points(p))),
    ]
}

/// A value of a kind that a parameter of kind `kind` takes.
fn value(kind: Kind) -> BoxedStrategy<Value> {
    match kind {
        Kind::Length | Kind::Duration | Kind::Speed | Kind::Number => {
            number().prop_map(Value::Number).boxed()
        }
        Kind::Position => {
            prop_oneof![point().prop_map(Value::Position), corners().prop_map(Value::Area)].boxed()
        }
        Kind::Area => {
            prop_oneof![corners().prop_map(Value::Area), remainder().prop_map(Value::Remainder)]
                .boxed()
        }
        Kind::Symbol => prop_oneof![
            "[A-Z][a-z]{0,6}".prop_map(Value::Symbol),
            "[a-z ]{0,6}".prop_map(Value::Text)
        ]
        .boxed(),
        Kind::Path => prop_oneof![
            point().prop_map(Value::Position),
            corners().prop_map(Value::Area),
            remainder().prop_map(Value::Remainder)
        ]
        .boxed(),
        other => unreachable!("no function takes a {other:?}"),
    }
}

/// Arguments `function`'s signature takes: each required one, each optional one or not,
/// a repeated one one to three times, and the trailing one or not.
fn args(function: Function) -> BoxedStrategy<Vec<Value>> {
    let sig = function.signature();
    let mut parts: Vec<BoxedStrategy<Vec<Value>>> = Vec::new();
    for (i, p) in sig.params.iter().enumerate() {
        let one = value(p.kind);
        parts.push(if sig.variadic && i + 1 == sig.params.len() {
            proptest::collection::vec(one, 1..4).boxed()
        } else if p.optional {
            proptest::option::of(one).prop_map(|v| v.into_iter().collect()).boxed()
        } else {
            one.prop_map(|v| vec![v]).boxed()
        });
    }
    if let Some(t) = &sig.trailing {
        parts.push(
            proptest::option::of(value(t.kind)).prop_map(|v| v.into_iter().collect()).boxed(),
        );
    }
    // An optional parameter is only given when the one before it is: a prefix.
    parts.into_iter().fold(Just(Vec::new()).boxed(), |acc, part| {
        (acc, part)
            .prop_map(|(mut a, b): (Vec<Value>, Vec<Value>)| {
                a.extend(b);
                a
            })
            .boxed()
    })
}

fn call_args() -> impl Strategy<Value = (Function, Vec<Value>)> {
    proptest::sample::select(Function::ALL.to_vec()).prop_flat_map(|f| (Just(f), args(f)))
}

proptest! {
    #[test]
    fn every_signature_is_read_and_shown_as_given((f, args) in call_args()) {
        let call = FunctionCall::new(f, &args).map_err(TestCaseError::fail)?;
        prop_assert_eq!(call.function(), f);
        let drones = Names::default();
        prop_assert_eq!(call.shown(), Shown::all(&args, &drones));
        prop_assert_eq!(FunctionCall::new(f, &call.args()), Ok(call.clone()));
    }

    #[test]
    fn one_argument_too_many_is_refused((f, mut args) in call_args()) {
        // A flag: never a point, a number or a kind.
        args.push(Value::Bool(true));
        let err = FunctionCall::new(f, &args).unwrap_err();
        prop_assert!(!err.is_empty());
    }
}

#[test]
fn a_missing_or_wrong_argument_is_refused_with_its_name() {
    assert_eq!(FunctionCall::new(Function::TakeOff, &[]), Err("missing argument `alt`".into()));
    assert_eq!(
        FunctionCall::new(Function::TakeOff, &[Value::Text("up".into())]),
        Err("`alt` must be a finite number, not \"up\"".into())
    );
    assert_eq!(
        FunctionCall::new(Function::FlyToPosition, &[Value::Number(3.0)]),
        Err("`pos` must be a position, not 3".into())
    );
    assert_eq!(
        FunctionCall::new(Function::Arm, &[Value::Number(3.0)]),
        Err("Arm() takes no arguments, not 1".into())
    );
    assert_eq!(
        FunctionCall::new(Function::TakeOff, &[Value::Number(3.0), Value::Number(4.0)]),
        Err("TakeOff(alt) takes at most 1 argument, not 2".into())
    );
    assert_eq!(
        FunctionCall::new(Function::Sweep, &[Value::Position(Point::flat(1.0, 2.0))]),
        Err("`area` must be an area of at least 3 corners, not (1, 2)".into())
    );
    assert_eq!(
        FunctionCall::new(Function::StartDetection, &[Value::Bool(true)]),
        Err("`kind` must be a kind such as Body, not true".into())
    );
    let p = Value::Position(Point::flat(1.0, 2.0));
    assert_eq!(
        FunctionCall::new(Function::FollowPath, &[p.clone(), Value::Bool(true), p]),
        Err("`points[1]` must be a position, or what a Sweep or FollowPath left, not true".into())
    );
}

#[test]
fn follow_path_takes_a_last_number_as_its_speed() {
    let p = Point::flat(1.0, 2.0);
    let call = FunctionCall::new(
        Function::FollowPath,
        &[Value::Position(p), Value::Area(vec![[0.0, 0.0]]), Value::Number(3.0)],
    );
    assert_eq!(
        call,
        Ok(FunctionCall::FollowPath {
            points: vec![Waypoint::Point(p), Waypoint::Area(vec![[0.0, 0.0]])],
            speed: Some(3.0)
        })
    );
    assert_eq!(
        FunctionCall::new(Function::FollowPath, &[Value::Position(p)]),
        Ok(FunctionCall::FollowPath { points: vec![Waypoint::Point(p)], speed: None })
    );
}

#[test]
fn a_place_stands_for_a_finite_point_or_an_area_s_centroid() {
    let p = Point { x: 1.0, y: 2.0, z: Some(3.0) };
    assert_eq!(Place::Point(p).point(), Some(p));
    assert_eq!(Place::Point(Point::flat(f64::NAN, 0.0)).point(), None);
    let square = vec![[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
    assert_eq!(Place::Area(square).point(), Some(Point::flat(1.0, 1.0)));
    assert_eq!(Place::Area(Vec::new()).point(), None);
    assert_eq!(Place::Area(Vec::new()).to_string(), "an area of 0 corners");
}

/// A call is made, moved and kept for every middle-layer call of a run (a million in
/// W(100k, 10)): it stays the size of its largest variant's fields, nothing boxed in.
#[test]
fn a_call_is_no_larger_than_its_largest_arguments() {
    assert_eq!(std::mem::size_of::<Place>(), std::mem::size_of::<Point>());
    assert!(std::mem::size_of::<FunctionCall>() <= 56);
    assert_eq!(
        std::mem::size_of::<Result<FunctionCall, String>>(),
        std::mem::size_of::<FunctionCall>()
    );
}

/// The flown call with every field known: what the plan reads when every argument is
/// known before the flight.
fn foreseen(call: &FunctionCall) -> PlannedCall {
    match call {
        CallOf::Arm => CallOf::Arm,
        CallOf::Disarm => CallOf::Disarm,
        CallOf::TakeOff { alt } => CallOf::TakeOff { alt: Some(*alt) },
        CallOf::Land => CallOf::Land,
        CallOf::ReturnToLaunch => CallOf::ReturnToLaunch,
        CallOf::FlyToPosition { pos, speed } => {
            CallOf::FlyToPosition { pos: Some(pos.clone()), speed: speed.map(Some) }
        }
        CallOf::DescendTo { alt } => CallOf::DescendTo { alt: Some(*alt) },
        CallOf::AscendTo { alt } => CallOf::AscendTo { alt: Some(*alt) },
        CallOf::Hover { duration } => CallOf::Hover { duration: Some(*duration) },
        CallOf::Orbit { center, radius, laps } => CallOf::Orbit {
            center: Some(center.clone()),
            radius: Some(*radius),
            laps: laps.map(Some),
        },
        CallOf::Sweep { area, spacing } => {
            CallOf::Sweep { area: Some(area.clone()), spacing: Some(*spacing) }
        }
        CallOf::StartStreaming => CallOf::StartStreaming,
        CallOf::StopStreaming => CallOf::StopStreaming,
        CallOf::StartDetection { kind } => CallOf::StartDetection { kind: Some(kind.clone()) },
        CallOf::StopDetection { kind } => CallOf::StopDetection { kind: Some(kind.clone()) },
        CallOf::LoadPayload { kind } => CallOf::LoadPayload { kind: Some(kind.clone()) },
        CallOf::ReleasePayload => CallOf::ReleasePayload,
        CallOf::FollowPath { points, speed } => CallOf::FollowPath {
            points: points.iter().cloned().map(Some).collect(),
            speed: speed.map(Some),
        },
    }
}

proptest! {
    /// The plan and the flight read one signature: with every argument known before the
    /// flight, the plan's call is the flown one.
    #[test]
    fn a_call_known_before_the_flight_is_planned_as_it_is_flown((f, args) in call_args()) {
        let flown = FunctionCall::new(f, &args).map_err(TestCaseError::fail)?;
        let known: Vec<Option<Value>> = args.into_iter().map(Some).collect();
        prop_assert_eq!(PlannedCall::new(f, &known), Ok(foreseen(&flown)));
    }
}

#[test]
fn an_argument_known_only_in_flight_is_planned_as_unknown_and_the_others_are_read() {
    let n = |x: f64| Some(Value::Number(x));
    assert_eq!(
        PlannedCall::new(Function::Orbit, &[None, n(20.0)]),
        Ok(CallOf::Orbit { center: None, radius: Some(20.0), laps: None })
    );
    // A value of the wrong kind (a signal's value the checker could not judge): unknown.
    assert_eq!(
        PlannedCall::new(Function::TakeOff, &[Some(Value::Symbol("high".into()))]),
        Ok(CallOf::TakeOff { alt: None })
    );
    // FollowPath: a last number is the speed; a last argument known only in flight is a
    // point.
    let p = Point::flat(1.0, 2.0);
    assert_eq!(
        PlannedCall::new(Function::FollowPath, &[Some(Value::Position(p)), None]),
        Ok(CallOf::FollowPath { points: vec![Some(Waypoint::Point(p)), None], speed: None })
    );
    assert_eq!(
        PlannedCall::new(Function::FollowPath, &[None, n(4.0)]),
        Ok(CallOf::FollowPath { points: vec![None], speed: Some(Some(4.0)) })
    );
    // The count of arguments is known before the flight: a missing or an extra one is
    // refused, as in flight.
    assert_eq!(PlannedCall::new(Function::TakeOff, &[]), Err("missing argument `alt`".into()));
    assert!(PlannedCall::new(Function::Land, &[None]).is_err());
}
