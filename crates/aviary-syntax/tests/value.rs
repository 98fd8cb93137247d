//! `parse_value`: one value by the language's rules, as `aviary ctl` reads its arguments.

use aviary_syntax::ast::{ExprKind, Unit};
use aviary_syntax::parse_value;

fn kind(text: &str) -> ExprKind {
    parse_value(text)
        .unwrap_or_else(|e| {
            panic!("{text}: {:?}", e.iter().map(|d| &d.message).collect::<Vec<_>>())
        })
        .kind
}

fn refused(text: &str) -> String {
    match parse_value(text) {
        Ok(e) => panic!("{text} was read as {e:?}"),
        Err(d) => d[0].message.clone(),
    }
}

#[test]
fn numbers_keep_their_units() {
    assert!(
        matches!(kind("20m"), ExprKind::Number { value, unit: Some(Unit::Metre), .. } if value == 20.0)
    );
    assert!(
        matches!(kind("-3.5km"), ExprKind::Number { value, unit: Some(Unit::Kilometre), .. } if value == -3.5)
    );
    assert!(matches!(kind("10s"), ExprKind::Number { unit: Some(Unit::Second), .. }));
    assert!(matches!(kind("5 m/s"), ExprKind::Number { unit: Some(Unit::MetrePerSecond), .. }));
    assert!(matches!(kind("25%"), ExprKind::Number { unit: Some(Unit::Percent), .. }));
    assert!(matches!(kind(" 3 "), ExprKind::Number { value, unit: None, .. } if value == 3.0));
}

#[test]
fn positions_names_strings_and_truth() {
    assert!(matches!(kind("(1, 2)"), ExprKind::Coordinates(p) if p.len() == 2));
    assert!(matches!(kind("(1, -2, 30m)"), ExprKind::Coordinates(p) if p.len() == 3));
    assert!(matches!(kind("Body"), ExprKind::Name(id) if id.name == "Body"));
    assert!(
        matches!(kind("nan"), ExprKind::Name(id) if id.name == "nan"),
        "nan is a name, not a number"
    );
    assert!(matches!(kind("\"two words\""), ExprKind::String(s) if s == "two words"));
    assert!(matches!(kind("TRUE"), ExprKind::Bool(true)));
}

#[test]
fn what_is_not_one_value_is_refused() {
    assert!(refused("10 parsecs").contains("end of the value"));
    assert!(refused("10furlongs").contains("unknown unit"));
    assert!(refused("(1, 2").contains("`)`"));
    assert!(refused("(1, 2, 3, 4)").contains("2 or 3 numbers"));
    assert!(refused("1 2").contains("end of the value"));
    assert!(refused("").contains("a value"));
    assert!(refused("a\nb").contains("one line"));
    assert!(refused("1e308").contains("unknown unit"), "the language has no exponent");
}
