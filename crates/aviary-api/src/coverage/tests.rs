use std::sync::Arc;

use super::*;
use crate::{Function, Value};

/// What a call of `function` with `args` left, read as the engine reads a call.
fn left(function: Function, args: &[Value], progress: Option<Progress>) -> Option<Remainder> {
    super::left(&FunctionCall::new(function, args).ok()?, progress)
}

fn region(v: &Value) -> Region {
    match FunctionCall::new(Function::Sweep, &[v.clone(), Value::Number(1.0)]) {
        Ok(FunctionCall::Sweep { area, .. }) => area,
        other => panic!("{other:?}"),
    }
}

fn waypoints(args: &[Value]) -> (Vec<Waypoint>, Option<f64>) {
    match FunctionCall::new(Function::FollowPath, args) {
        Ok(FunctionCall::FollowPath { points, speed }) => (points, speed),
        other => panic!("{other:?}"),
    }
}

const FIELD: [[f64; 2]; 4] = [[0.0, 0.0], [200.0, 0.0], [200.0, 100.0], [0.0, 100.0]];

fn len(l: &Lane) -> f64 {
    (l[1][0] - l[0][0]).hypot(l[1][1] - l[0][1])
}

fn sweep_args(area: Value, spacing: f64) -> Vec<Value> {
    vec![area, Value::Number(spacing)]
}

#[test]
fn the_path_is_the_lanes_in_order() {
    let lanes = sweep::lanes(&FIELD, 20.0);
    // 100 m across at 20 m: 5 passes along x, alternating.
    assert_eq!(lanes.len(), 5);
    assert_eq!(lanes[0], [[0.0, 10.0], [200.0, 10.0]]);
    assert_eq!(lanes[1], [[200.0, 30.0], [0.0, 30.0]]);
    let path = sweep::lawnmower(&FIELD, 20.0);
    assert_eq!(path, lanes.iter().flatten().copied().collect::<Vec<_>>());
}

#[test]
fn a_sweep_stopped_on_a_lane_leaves_the_rest_of_that_lane_and_every_lane_after() {
    let args = sweep_args(Value::Area(FIELD.to_vec()), 20.0);
    // Flying to point 3, the end of lane 1 (from (200, 30) to (0, 30)), stopped at x = 120.
    let left = left(Function::Sweep, &args, Some(Progress { next: 3, at: [120.0, 31.0, 30.0] }));
    let Some(Remainder::Lanes { lanes, spacing }) = left else { panic!("{left:?}") };
    assert_eq!(spacing, 20.0);
    assert_eq!(lanes.len(), 4);
    assert_eq!(lanes[0], [[120.0, 30.0], [0.0, 30.0]], "brought onto the lane");
    assert_eq!(lanes[1..], sweep::lanes(&FIELD, 20.0)[2..]);
}

#[test]
fn a_sweep_stopped_between_lanes_leaves_the_next_lane_whole() {
    let args = sweep_args(Value::Area(FIELD.to_vec()), 20.0);
    // Flying to point 2, the start of lane 1: on the turn after lane 0.
    let left = left(Function::Sweep, &args, Some(Progress { next: 2, at: [200.0, 20.0, 30.0] }));
    assert_eq!(left, Some(Remainder::lanes(sweep::lanes(&FIELD, 20.0)[1..].to_vec(), 20.0)));
    // On its way to the first point: everything.
    let all = left_all(&args, Progress { next: 0, at: [-50.0, -50.0, 30.0] });
    assert_eq!(all, Remainder::lanes(sweep::lanes(&FIELD, 20.0), 20.0));
    // Refused before it moved: everything too.
    assert_eq!(self::left(Function::Sweep, &args, None), Some(all));
}

fn left_all(args: &[Value], p: Progress) -> Remainder {
    left(Function::Sweep, args, Some(p)).expect("a sweep")
}

/// Wherever a sweep stops, what it flew and what it left are every lane's length once:
/// no lane twice, none missed. Stops are taken along the whole path, on lanes and turns,
/// and the remainder is itself stopped again (a remainder of a remainder).
#[test]
fn what_was_flown_and_what_is_left_make_every_lane_once() {
    let l_shape =
        [[0.0, 0.0], [120.0, 0.0], [120.0, 40.0], [50.0, 40.0], [50.0, 90.0], [0.0, 90.0]];
    for (polygon, spacing) in [(FIELD.to_vec(), 20.0), (l_shape.to_vec(), 15.0)] {
        let lanes = sweep::lanes(&polygon, spacing);
        let total: f64 = lanes.iter().map(len).sum();
        let path = sweep::path(&lanes);
        for next in 0..path.len() {
            for frac in [0.0, 0.3, 0.999] {
                let from = if next == 0 { [-30.0, -30.0] } else { path[next - 1] };
                let to = path[next];
                let at =
                    [from[0] + frac * (to[0] - from[0]), from[1] + frac * (to[1] - from[1]), 20.0];
                let args = sweep_args(Value::Area(polygon.clone()), spacing);
                let left = left_all(&args, Progress { next, at });
                let left_len: f64 = match &left {
                    Remainder::Lanes { lanes, .. } => lanes.iter().map(len).sum(),
                    _ => 0.0,
                };
                // Flown: the lanes whose end was passed, and the part of the lane begun.
                let flown: f64 = lanes
                    .iter()
                    .enumerate()
                    .map(|(i, lane)| {
                        let points = sweep::points(&lanes);
                        let end = points.iter().position(|(_, r)| *r == (i, true));
                        match end {
                            Some(k) if k < next => len(lane),
                            Some(k) if k == next => len(lane) * frac,
                            // A lane of no length, or one not reached yet.
                            _ => 0.0,
                        }
                    })
                    .sum();
                assert!(
                    (flown + left_len - total).abs() < 1e-6,
                    "stop at {next}/{frac}: flown {flown} + left {left_len} != {total}"
                );
                // And stopped again half way through what was left.
                let again = sweep_args(Value::Remainder(Arc::new(left.clone())), spacing);
                let rest = left_all(&again, Progress { next: 0, at });
                assert_eq!(rest, left, "stopped before it moved, all of it is left");
            }
        }
    }
}

#[test]
fn a_remainder_is_swept_at_its_own_spacing_only() {
    let lanes = sweep::lanes(&FIELD, 20.0);
    let r = Value::Remainder(Arc::new(Remainder::lanes(lanes.clone(), 20.0)));
    assert_eq!(sweep_lanes(&region(&r), 20.0), Ok(lanes));
    let wrong = sweep_lanes(&region(&r), 15.0).unwrap_err();
    assert!(wrong.contains("20 m apart") && wrong.contains("not 15 m"), "{wrong}");
    let path = Value::Remainder(Arc::new(Remainder::points(vec![Point::flat(1.0, 2.0)])));
    assert!(sweep_lanes(&region(&path), 20.0).unwrap_err().contains("FollowPath"));
    assert_eq!(sweep_lanes(&region(&Value::Remainder(Arc::default())), 20.0), Ok(Vec::new()));
}

#[test]
fn a_path_left_starts_where_the_drone_stopped_with_the_heights_it_would_have_flown() {
    let args = vec![
        Value::Position(Point::flat(0.0, 0.0)),
        Value::Position(Point { x: 100.0, y: 0.0, z: Some(40.0) }),
        Value::Position(Point::flat(100.0, 100.0)),
        Value::Position(Point::flat(0.0, 100.0)),
    ];
    let left =
        left(Function::FollowPath, &args, Some(Progress { next: 2, at: [100.0, 30.0, 40.0] }));
    assert_eq!(
        left,
        Some(Remainder::Points(vec![
            Point { x: 100.0, y: 30.0, z: Some(40.0) },
            Point { x: 100.0, y: 100.0, z: Some(40.0) },
            Point { x: 0.0, y: 100.0, z: Some(40.0) },
        ]))
    );
    let Some(left) = left else { unreachable!() };
    assert_eq!(left.length(), 170.0);
    // Flown again by FollowPath: its points, in order.
    let (points, _) = waypoints(&[Value::Remainder(Arc::new(left.clone()))]);
    assert_eq!(follow_points(&points), Ok(left.path()));
    // Nothing left once the last point was reached.
    assert_eq!(
        self::left(Function::FollowPath, &args, Some(Progress { next: 4, at: [0.0; 3] })),
        Some(Remainder::Nothing)
    );
    assert_eq!(self::left(Function::Hover, &[Value::Number(1.0)], None), None);
}

#[test]
fn a_remainder_is_written_and_read_back_as_it_was() {
    let cases = [
        Remainder::Nothing,
        Remainder::lanes(vec![[[1.5, 2.0], [3.0, 4.0]]], 20.0),
        Remainder::points(vec![Point::flat(1.0, 2.0), Point { x: 3.0, y: 4.0, z: Some(5.0) }]),
    ];
    let written = [
        r#"{"points":[]}"#,
        r#"{"lanes":[[[1.5,2.0],[3.0,4.0]]],"spacing":20.0}"#,
        r#"{"points":[[1.0,2.0],[3.0,4.0,5.0]]}"#,
    ];
    for (r, w) in cases.iter().zip(written) {
        assert_eq!(serde_json::to_string(r).unwrap(), w);
        assert_eq!(&serde_json::from_str::<Remainder>(w).unwrap(), r);
    }
}

#[test]
fn a_last_number_of_follow_path_is_its_speed_and_no_point() {
    use crate::coverage::{follow_points, follow_speed};
    let a = Value::Position(Point::flat(1.0, 2.0));
    let (points, speed) = waypoints(&[a.clone(), Value::Number(3.0)]);
    assert_eq!(follow_points(&points), Ok(vec![Point::flat(1.0, 2.0)]));
    assert_eq!(follow_speed(speed), Ok(Some(3.0)));
    assert_eq!(waypoints(std::slice::from_ref(&a)).1, None);
    assert_eq!(follow_speed(None), Ok(None));
    assert!(follow_speed(Some(0.0)).is_err());
    // A number among the points is no point.
    assert!(FunctionCall::new(Function::FollowPath, &[Value::Number(3.0), a]).is_err());
    // Nor is a position that is not finite.
    assert!(follow_points(&[Waypoint::Point(Point::flat(f64::NAN, 0.0))]).is_err());
    let f = crate::Function::FollowPath.signature();
    assert_eq!(f.signature(), "FollowPath(points...[, speed])");
    assert_eq!(f.param_at(1, 2, Some(crate::Kind::Speed)).map(|p| p.name), Some("speed"));
    assert_eq!(f.param_at(1, 2, Some(crate::Kind::Position)).map(|p| p.name), Some("points"));
    assert_eq!(f.param_at(0, 1, Some(crate::Kind::Speed)).map(|p| p.name), Some("points"));
}
