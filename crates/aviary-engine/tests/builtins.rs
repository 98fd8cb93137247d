//! What a backend raises reaches the mission as the built-in it is: every built-in
//! exception, whether a call is refused with it or a fault reports it, is raised under its
//! own name and taken by the handler of that name, and every built-in signal starts its
//! handler. The compiler resolved each built-in's id, so the engine looks no name up.

use std::sync::Mutex;
use std::time::Duration;

use aviary_api::trace::{Event, Record, Shown};
use aviary_api::{
    Backend, BuiltinException, BuiltinSignal, CallEnd, CallId, DroneEvent, DroneId, Ending,
    Failure, FlightState, FunctionCall, Interrupt, PendingCall, Telemetry,
};
use aviary_engine::{RunOptions, Status};
use aviary_test_support::harness;
use aviary_test_support::trace::{is, Trace};
use tokio::sync::{mpsc, oneshot};

/// A backend that answers every call as it is told, and reports the drone events it is
/// given: a drone on the ground that never moves.
struct Scripted {
    /// A call is refused with this exception; without one it ends after a second.
    refuse: Option<BuiltinException>,
    events: Mutex<Option<mpsc::UnboundedReceiver<DroneEvent>>>,
}

impl Scripted {
    fn new(refuse: Option<BuiltinException>, events: Vec<DroneEvent>) -> Scripted {
        let (tx, rx) = mpsc::unbounded_channel();
        for e in events {
            tx.send(e).expect("the receiver is here");
        }
        Scripted { refuse, events: Mutex::new(Some(rx)) }
    }
}

impl Backend for Scripted {
    fn call(&self, _: DroneId, _: &FunctionCall) -> PendingCall {
        let end = match self.refuse {
            Some(exception) => Ending::Now(CallEnd::Failed(Failure::new(
                exception,
                format!("refused with {exception}"),
            ))),
            None => {
                let (tx, rx) = oneshot::channel();
                tokio::spawn(async move {
                    aviary_clock::sleep(Duration::from_secs(1)).await;
                    let _ = tx.send(CallEnd::Done);
                });
                Ending::Later(rx)
            }
        };
        PendingCall { id: CallId(0), end }
    }

    fn interrupt(&self, _: CallId, _: Interrupt) {}

    fn stopped(&self, _: DroneId) -> Option<aviary_api::Progress> {
        None
    }

    fn payload(&self, _: DroneId) -> Option<String> {
        None
    }

    fn telemetry(&self, _: DroneId) -> Telemetry {
        Telemetry { state: FlightState::Landed, link: true, battery: 1.0, ..Telemetry::LOST }
    }

    fn events(&self) -> Option<mpsc::UnboundedReceiver<DroneEvent>> {
        self.events.lock().unwrap_or_else(|p| p.into_inner()).take()
    }
}

fn run(mission: &str, backend: &Scripted) -> (Status, Trace) {
    let (mission, _) = harness::compile(mission, harness::WORLD);
    let runtime = harness::simulated_runtime();
    let mut trace = Vec::new();
    let mut sink = |r: &aviary_engine::Record| trace.push(Trace::line(r));
    let outcome =
        runtime.block_on(aviary_engine::run(&mission, backend, &mut sink, &RunOptions::default()));
    (outcome.status, Trace(trace))
}

fn signalled(trace: &Trace, name: &str) -> bool {
    !trace.find(is::signal(name)).is_empty()
}

#[test]
fn a_call_refused_with_any_builtin_exception_raises_that_exception() {
    for exception in BuiltinException::ALL {
        let mission = format!(
            "MISSION M:\n    SEQUENTIAL Try:\n        a Hover WITH 1s\n        ON EXCEPTION {exception} BY a:\n            SIGNAL Caught\n"
        );
        let (status, trace) = run(&mission, &Scripted::new(Some(exception), vec![]));
        assert_eq!(status, Status::Ok, "{exception}: {trace:#?}");
        let raised: Vec<&Record> = trace.find(|e| matches!(e, Event::Exception { .. }));
        assert_eq!(raised.len(), 1, "{exception}: {trace:#?}");
        let Event::Exception { name, handled, args, .. } = &raised[0].event else { unreachable!() };
        assert_eq!(name, exception.name());
        assert!(*handled);
        assert_eq!(args, &[Shown::Text(format!("refused with {exception}").into())]);
        assert!(signalled(&trace, "Caught"), "{exception}: the handler ran");
    }
}

#[test]
fn faults_and_signals_a_backend_reports_start_their_handlers() {
    let events = vec![
        DroneEvent::Signal { drone: DroneId(0), signal: BuiltinSignal::BatteryLow },
        DroneEvent::Signal { drone: DroneId(0), signal: BuiltinSignal::ConnectionRestored },
        DroneEvent::Fault {
            drone: DroneId(0),
            failure: Failure::new(BuiltinException::MotorFailure, "motor"),
        },
    ];
    let mission = "MISSION M:\n    PARALLEL Watch:\n        a Hover WITH 5s\n        ON BatteryLow BY a:\n            SIGNAL Low\n        ON ConnectionRestored BY a:\n            SIGNAL Back\n        ON EXCEPTION MotorFailure BY a:\n            SIGNAL Broken\n";
    let (status, trace) = run(mission, &Scripted::new(None, events));
    assert_eq!(status, Status::Ok, "{trace:#?}");
    for name in ["BatteryLow", "ConnectionRestored", "Low", "Back", "Broken"] {
        assert!(signalled(&trace, name), "{name}: {trace:#?}");
    }
    let e = trace.iter().find(|e| matches!(e.event, Event::Exception { .. }));
    let Event::Exception { name, actor, handled, .. } = &e.expect("an exception").event else {
        unreachable!()
    };
    assert_eq!((&**name, actor.as_deref(), *handled), ("MotorFailure", Some("a"), true));
}
