//! How numbers and values are written for people: in messages, reasons and diagnostics,
//! in the language's own notation, never Rust's debug text. One rule for every crate,
//! so that a number reads the same in `aviary check`, a trace's reason and a summary.
//!
//! The rule for a number ([`number`]): at most [`DIGITS`] significant digits, rounded,
//! trailing zeros dropped, so the shortest text that says the value to that precision
//! (0.1 + 0.2 is `0.3`, 120.0 is `120`, 2.5 is `2.5`). Magnitudes from 10⁻⁶ to under
//! 10¹⁵ are written out; others as `1e308`, `1.5e-7`. `NaN`, `infinity`, `-infinity`
//! for what is not a finite number; -0 is `0`.

use std::fmt;

use crate::{Point, Value};

/// Significant digits a number is shown with at most: more than any measured quantity
/// has, few enough to hide the binary rounding of decimal fractions (0.1 + 0.2 =
/// 0.30000000000000004 is the 17th digit).
pub const DIGITS: usize = 12;

/// Written out below this magnitude (and from [`SMALL`] up); in exponent form above.
const LARGE: i32 = 15;
/// The smallest decimal exponent written out: 0.000001.
const SMALL: i32 = -6;

/// `x` as people read it; see the module's rule.
pub fn number(x: f64) -> String {
    if x.is_nan() {
        return "NaN".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "infinity" } else { "-infinity" }.into();
    }
    if x == 0.0 {
        return "0".into();
    }
    // Rust's exponent form rounds exactly: `d.ddddddddddde±x` with DIGITS digits.
    let e = format!("{:.*e}", DIGITS - 1, x);
    let (mantissa, exp) = e.split_once('e').unwrap_or((&e, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let (sign, mantissa) = match mantissa.strip_prefix('-') {
        Some(m) => ("-", m),
        None => ("", mantissa),
    };
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    let digits = digits.trim_end_matches('0');
    let digits = if digits.is_empty() { "0" } else { digits };
    if !(SMALL..LARGE).contains(&exp) {
        let (first, rest) = digits.split_at(1);
        let dot = if rest.is_empty() { "" } else { "." };
        return format!("{sign}{first}{dot}{rest}e{exp}");
    }
    if exp < 0 {
        let zeros = "0".repeat((-exp - 1) as usize);
        return format!("{sign}0.{zeros}{digits}");
    }
    let whole = exp as usize + 1;
    if digits.len() <= whole {
        format!("{sign}{digits}{}", "0".repeat(whole - digits.len()))
    } else {
        format!("{sign}{}.{}", &digits[..whole], &digits[whole..])
    }
}

/// `x` with exactly `places` decimals, as measured quantities are shown (`12.5 m`,
/// `(120.0, 80.0)`), while that is short; a magnitude of 10¹⁵ or more, or what is not a
/// finite number, as [`number`] writes it (never 309 digits).
pub fn fixed(x: f64, places: usize) -> String {
    if !x.is_finite() || x.abs() >= 10f64.powi(LARGE) {
        return number(x);
    }
    let text = format!("{x:.places$}");
    // -0.0 rounds to "-0.0": a sign with no meaning.
    match text.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_string(),
        _ => text,
    }
}

/// A point as the language writes coordinates: `(x, y)` or `(x, y, z)`.
pub fn point(p: &Point) -> String {
    match p.z {
        Some(z) => format!("({}, {}, {})", number(p.x), number(p.y), number(z)),
        None => format!("({}, {})", number(p.x), number(p.y)),
    }
}

/// A value in the language's notation: numbers by [`number`] (in SI units), `(x, y)`,
/// symbols as written, texts quoted. An area is shown by its size (a run-time area
/// keeps its corners, not its name); a drone by its index, since names are the
/// mission's (the engine's trace shows them).
impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Number(n) => f.write_str(&number(*n)),
            Value::Text(s) => write!(f, "\"{s}\""),
            Value::Symbol(s) => f.write_str(s),
            Value::Bool(b) => write!(f, "{b}"),
            Value::Position(p) => f.write_str(&point(p)),
            Value::Area(corners) if corners.len() == 1 => f.write_str("an area of 1 corner"),
            Value::Area(corners) => write!(f, "an area of {} corners", corners.len()),
            Value::Actor(d) => write!(f, "drone #{d}"),
            Value::Remainder(left) => match (left.lane_count(), left.length()) {
                (Some(0), _) => f.write_str("nothing left"),
                (Some(1), m) => write!(f, "1 lane left ({} m)", fixed(m, 1)),
                (Some(n), m) => write!(f, "{n} lanes left ({} m)", fixed(m, 1)),
                (None, m) => write!(f, "a path left ({} m)", fixed(m, 1)),
            },
            Value::Absent => f.write_str("no value"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_read_as_written() {
        let cases: &[(f64, &str)] = &[
            (0.1 + 0.2, "0.3"),
            (1e308, "1e308"),
            (-1e308, "-1e308"),
            (f64::MAX, "1.79769313486e308"),
            (120.0, "120"),
            (2.5, "2.5"),
            (-0.0, "0"),
            (0.0, "0"),
            (1e12, "1000000000000"),
            (1e15, "1e15"),
            (123456789012345.0, "123456789012000"),
            (0.000001, "0.000001"),
            (1.5e-7, "1.5e-7"),
            (5e-324, "4.94065645841e-324"),
            (1.0 / 3.0, "0.333333333333"),
            (f64::NAN, "NaN"),
            (f64::INFINITY, "infinity"),
            (f64::NEG_INFINITY, "-infinity"),
            (99.9999999999999, "100"),
            (-42.125, "-42.125"),
        ];
        for &(x, want) in cases {
            assert_eq!(number(x), want, "{x:e}");
        }
    }

    #[test]
    fn every_number_is_short_and_reads_back_close() {
        let mut x = 1.234_567_890_123_456_7e-300;
        while x < 1e300 {
            for v in [x, -x, x * 0.7, x * 3.3] {
                let text = number(v);
                // At most the digits and a sign, with a point and an exponent of four
                // characters, or with `0.` and the five zeros of the smallest written out.
                assert!(text.len() <= DIGITS + 8, "{text}");
                let back: f64 = text.parse().expect("a number Rust reads");
                assert!(((back - v) / v).abs() < 1e-11, "{v:e} -> {text}");
            }
            x *= 13.7;
        }
    }

    #[test]
    fn fixed_keeps_its_places_until_the_number_is_huge() {
        assert_eq!(fixed(120.0, 1), "120.0");
        assert_eq!(fixed(-0.04, 1), "0.0");
        assert_eq!(fixed(12.345, 2), "12.35");
        assert_eq!(fixed(1e308, 1), "1e308");
        assert_eq!(fixed(f64::NAN, 1), "NaN");
    }

    #[test]
    fn values_in_the_language_notation() {
        assert_eq!(Value::Symbol("abc".into()).to_string(), "abc");
        assert_eq!(Value::Text("abc".into()).to_string(), "\"abc\"");
        assert_eq!(Value::Position(Point { x: 1.0, y: 2.5, z: None }).to_string(), "(1, 2.5)");
        assert_eq!(
            Value::Position(Point { x: 1.0, y: 2.0, z: Some(0.1 + 0.2) }).to_string(),
            "(1, 2, 0.3)"
        );
        assert_eq!(Value::Number(f64::NAN).to_string(), "NaN");
        assert_eq!(Value::Number(1e308).to_string(), "1e308");
        assert_eq!(Value::Area(vec![[0.0, 0.0], [1.0, 0.0]]).to_string(), "an area of 2 corners");
        assert_eq!(Value::Bool(true).to_string(), "true");
    }
}
