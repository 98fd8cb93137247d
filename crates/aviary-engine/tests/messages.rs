//! Reasons reach people in the language's notation, never as Rust's debug text: a value
//! that the checker cannot judge (here, a signal's value passed on) and the middle layer
//! refuses is shown as it would be written.

use aviary_engine::Status;
use aviary_test_support::harness;

/// `ON X WITH v` hands `v` to a capability whose parameter goes to `call`.
fn refused(value: &str, call: &str) -> String {
    let mission = format!("MISSION M:\n    a TakeOff WITH 10m\n    ON X WITH v:\n        a Go WITH v\n    SIGNAL X WITH {value}\n\nCAPABILITY Go BY d WITH x:\n    PERFORM:\n        d.{call}(x)\n");
    let r = harness::run(&mission);
    assert_eq!(r.outcome.status, Status::Failed, "{}", r.dump());
    r.outcome.reason.unwrap_or_default()
}

#[test]
fn refused_values_are_written_as_the_language_writes_them() {
    assert_eq!(
        refused("abc", "FlyToPosition"),
        "unhandled exception CommandFailed on a: `pos` must be a position, not abc"
    );
    assert_eq!(
        refused("\"abc\"", "FlyToPosition"),
        "unhandled exception CommandFailed on a: `pos` must be a position, not \"abc\""
    );
    assert_eq!(
        refused("(1, 2.5)", "Hover"),
        "unhandled exception CommandFailed on a: `duration` must be a finite number, not (1, 2.5)"
    );
    assert_eq!(refused("Field", "Hover"), "unhandled exception CommandFailed on a: `duration` must be a finite number, not an area of 4 corners");
}
