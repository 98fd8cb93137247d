use std::borrow::Cow;

use proptest::prelude::*;

use super::*;
use crate::{Names, Point, Value};

/// Lines of real traces (the docs/TRACE.md tour, as `aviary run` wrote it before the
/// events were typed) and hand-written lines for the rarer shapes: several actors, a
/// fault on the way home, a handler passed over, numbers that are not finite, escapes,
/// every status, every action of the operator.
const EXAMPLES: &str = include_str!("examples.jsonl");

#[test]
fn every_example_line_reads_back_and_is_written_byte_for_byte() {
    let mut kinds = Vec::new();
    for (i, line) in EXAMPLES.lines().enumerate() {
        let record: Record = serde_json::from_str(line)
            .unwrap_or_else(|e| panic!("line {} does not read: {e}\n{line}", i + 1));
        assert_eq!(serde_json::to_string(&record).unwrap(), line, "line {}", i + 1);
        let json: serde_json::Value = serde_json::from_str(line).unwrap();
        assert_eq!(json["event"], record.event.kind().as_str(), "line {}", i + 1);
        kinds.push(record.event.kind());
    }
    for kind in EventKind::ALL {
        assert!(kinds.contains(&kind), "no example of {kind:?}");
    }
}

#[test]
fn every_operator_action_has_an_example_written_as_its_name() {
    use OperatorAction::*;
    let mut seen = Vec::new();
    for line in EXAMPLES.lines() {
        if let Event::Operator { action, .. } = serde_json::from_str::<Record>(line).unwrap().event
        {
            let json: serde_json::Value = serde_json::from_str(line).unwrap();
            assert_eq!(json["action"], action.as_str(), "{line}");
            seen.push(action);
        }
    }
    for action in [Pause, Resume, Abort, Hold, ReturnHome, Land] {
        assert!(seen.contains(&action), "no example of {action:?}");
    }
}

#[test]
fn what_is_not_a_trace_line_is_an_error() {
    for line in [
        "",
        "{}",
        r#"{"t":1.0}"#,
        r#"{"t":1.0,"event":"landing"}"#,
        r#"{"t":1.0,"event":"block_start"}"#,
        r#"{"t":"1","event":"block_start","block":"B"}"#,
        r#"{"t":1.0,"event":"api_call","actor":"a","function":"Jump","args":[]}"#,
        r#"{"t":1.0,"event":"signal","name":"S","actor":null,"args":[[1.0,[2.0,3.0]]]}"#,
        r#"{"t":1.0,"event":"signal","name":"S","actor":null,"args":[[1.0,2.0,3.0,4.0]]}"#,
        r#"{"t":1.0,"event":"mission_end","status":"fine","reason":null}"#,
        r#"{"t":1.0,"event":"operator","action":"jump","drone":null}"#,
        r#"{"t":1.0,"event":"operator","action":"hold","drone":7}"#,
    ] {
        assert!(serde_json::from_str::<Record>(line).is_err(), "{line}");
    }
}

#[test]
fn a_value_is_shown_with_its_text_borrowed_and_a_drone_by_name() {
    let drones = Names::new(["scout"].into_iter());
    let values = [
        Value::Actor(crate::DroneId(0)),
        Value::Actor(crate::DroneId(7)),
        Value::Symbol("Body".into()),
        Value::Position(Point::flat(1.0, 2.0)),
        Value::Area(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]),
    ];
    let shown = Shown::all(&values, &drones);
    assert!(matches!(&shown[0], Shown::Text(Cow::Borrowed("scout"))));
    assert_eq!(shown[1], Shown::Null, "a drone the fleet does not have");
    assert!(matches!(&shown[2], Shown::Text(Cow::Borrowed("Body"))));
    assert!(matches!(&shown[4], Shown::Area(Cow::Borrowed(_))));
    assert_eq!(
        serde_json::to_string(&shown).unwrap(),
        r#"["scout",null,"Body",[1.0,2.0],[[0.0,0.0],[1.0,0.0],[1.0,1.0]]]"#
    );
}

#[test]
fn every_kind_is_listed_once_at_its_own_index() {
    for (i, kind) in EventKind::ALL.iter().enumerate() {
        assert_eq!(*kind as usize, i, "{kind:?}");
    }
    let mut names: Vec<&str> = EventKind::ALL.iter().map(|k| k.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), EventKind::ALL.len());
}

fn line() -> impl Strategy<Value = Option<u32>> {
    proptest::option::of(1u32..100_000)
}

fn text() -> impl Strategy<Value = Text<'static>> {
    "[a-zA-Z0-9 _/é\"\\\\\n\u{1}]{0,8}".prop_map(Cow::Owned)
}

fn number() -> impl Strategy<Value = f64> {
    any::<f64>().prop_filter("finite", |n| n.is_finite())
}

fn shown() -> impl Strategy<Value = Shown<'static>> {
    prop_oneof![
        number().prop_map(Shown::Number),
        text().prop_map(Shown::Text),
        any::<bool>().prop_map(Shown::Bool),
        (number(), number(), proptest::option::of(number()))
            .prop_map(|(x, y, z)| Shown::Position(Point { x, y, z })),
        proptest::collection::vec([number(), number()], 0..4)
            .prop_map(|c| Shown::Area(Cow::Owned(c))),
        (proptest::collection::vec([[number(), number()], [number(), number()]], 0..3), number())
            .prop_map(|(lanes, spacing)| Shown::Remainder(Cow::Owned(crate::Remainder::lanes(
                lanes, spacing
            )))),
        proptest::collection::vec((number(), number(), proptest::option::of(number())), 0..3)
            .prop_map(|p| Shown::Remainder(Cow::Owned(crate::Remainder::points(
                p.into_iter().map(|(x, y, z)| Point { x, y, z }).collect()
            )))),
        Just(Shown::Null),
    ]
}

fn values() -> impl Strategy<Value = Vec<Shown<'static>>> {
    proptest::collection::vec(shown(), 0..4)
}

fn params() -> impl Strategy<Value = Params<'static>> {
    proptest::collection::vec((text(), shown()), 0..4).prop_map(Params)
}

fn status() -> impl Strategy<Value = Status> {
    prop_oneof![Just(Status::Ok), Just(Status::Failed), Just(Status::Aborted)]
}

fn call_status() -> impl Strategy<Value = CallStatus> {
    prop_oneof![
        Just(CallStatus::Ok),
        Just(CallStatus::Failed),
        Just(CallStatus::Interrupted),
        Just(CallStatus::Aborted)
    ]
}

fn function() -> impl Strategy<Value = Function> {
    proptest::sample::select(Function::ALL.to_vec())
}

fn state() -> impl Strategy<Value = FlightState> {
    use FlightState::*;
    proptest::sample::select(vec![Landed, TakingOff, Flying, Landing, Lost])
}

fn operator_action() -> impl Strategy<Value = OperatorAction> {
    use OperatorAction::*;
    proptest::sample::select(vec![Pause, Resume, Abort, Hold, ReturnHome, Land])
}

fn autopilot_action() -> impl Strategy<Value = AutopilotAction> {
    use AutopilotAction::*;
    proptest::sample::select(vec![Hold, ReturnHome, Land])
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    [number(), number(), number()]
}

fn opt(s: impl Strategy<Value = Text<'static>>) -> impl Strategy<Value = Option<Text<'static>>> {
    proptest::option::of(s)
}

fn event() -> impl Strategy<Value = Event<'static>> {
    prop_oneof![
        (text(), proptest::option::of((text(), text()))).prop_map(|(mission, world)| {
            Event::MissionStart {
                mission,
                world: world.map(|(file, sha256)| WorldStamp { file, sha256 }),
            }
        }),
        (status(), opt(text())).prop_map(|(status, reason)| Event::MissionEnd { status, reason }),
        text().prop_map(|block| Event::BlockStart { block }),
        (text(), status()).prop_map(|(block, status)| Event::BlockEnd { block, status }),
        (text(), text(), opt(text()), params(), line()).prop_map(
            |(actor, capability, tag, args, line)| Event::CapabilityStart {
                actor,
                capability,
                tag,
                args,
                line
            }
        ),
        (text(), text(), opt(text()), params(), status(), line()).prop_map(
            |(actor, capability, tag, args, status, line)| Event::CapabilityEnd {
                actor,
                capability,
                tag,
                args,
                status,
                line
            }
        ),
        (text(), text(), opt(text())).prop_map(|(signal, handler, actor)| Event::HandlerStart {
            signal,
            handler,
            actor
        }),
        (text(), text(), opt(text())).prop_map(|(signal, handler, actor)| Event::HandlerEnd {
            signal,
            handler,
            actor
        }),
        (text(), function(), values()).prop_map(|(actor, function, args)| Event::ApiCall {
            actor,
            function,
            args
        }),
        (text(), function(), values(), call_status(), point(), proptest::option::of(number()))
            .prop_map(|(actor, function, args, status, position, left)| Event::ApiDone {
                actor,
                function,
                args,
                status,
                position,
                left
            }),
        (text(), opt(text()), values(), any::<bool>(), line()).prop_map(
            |(name, actor, args, operator, line)| Event::Signal {
                name,
                actor,
                args,
                by: operator.then_some(RaisedBy::Operator),
                line
            }
        ),
        (
            (text(), opt(text()), values(), any::<bool>()),
            (opt(text()), opt(text()), opt(text()), line(), any::<bool>())
        )
            .prop_map(
                |((name, actor, args, handled), (handler, during, skipped, line, separation))| {
                    let cause = separation.then_some(crate::Cause::Separation);
                    Event::Exception {
                        name,
                        actor,
                        args,
                        handled,
                        handler,
                        during,
                        skipped,
                        line,
                        cause,
                    }
                }
            ),
        (text(), text(), text(), any::<bool>(), line()).prop_map(
            |(capability, tag, action, block, line)| Event::Leash {
                capability,
                tag,
                action,
                block,
                line
            }
        ),
        (text(), text(), point()).prop_map(|(actor, kind, location)| Event::Detection {
            actor,
            kind,
            location
        }),
        (text(), point(), number(), state()).prop_map(|(actor, position, battery, state)| {
            Event::Telemetry { actor, position, battery, state }
        }),
        (operator_action(), opt(text()))
            .prop_map(|(action, drone)| Event::Operator { action, drone }),
        (text(), autopilot_action(), text()).prop_map(|(actor, action, reason)| Event::Autopilot {
            actor,
            action,
            reason
        }),
    ]
}

proptest! {
    #[test]
    fn a_record_reads_back_as_it_was_written(t in number(), event in event()) {
        let record = Record { t, event };
        let line = serde_json::to_string(&record).unwrap();
        let back: Record = serde_json::from_str(&line).unwrap();
        prop_assert_eq!(&back, &record);
        prop_assert_eq!(serde_json::to_string(&back).unwrap(), line);
        let prefix = format!("{{\"t\":{},\"event\":\"{}\"", serde_json::to_string(&t).unwrap(), record.event.kind().as_str());
        prop_assert!(serde_json::to_string(&record).unwrap().starts_with(&prefix));
    }
}
