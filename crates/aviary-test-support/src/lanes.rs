//! Lane by lane: which drone flew which part of each lane of a sweep, read from a run's
//! telemetry. The tests of resumable coverage (a sweep cut short and finished by another
//! drone) hold a run to "every lane once: no lane twice, none missed" with it.
//!
//! A drone flies over a point of a lane when a piece of its track (two telemetry samples
//! in a row) runs along the lane (within [`ALONG`] of its direction), within [`NEAR`] of
//! the point, with the point between the two samples. Consecutive pieces that fly over
//! one point are one pass; a drone that comes back over it makes a second pass. A drone
//! that hovers, or crosses a lane on its way somewhere, flies over nothing. Points are
//! taken every [`STEP`] along each lane, leaving [`MARGIN`] out at each end, where a
//! drone turns onto and off the lane between two samples.

use aviary_api::sweep::Lane;

/// Each drone's track in a trace: its telemetry positions, for [`passes`] and
/// [`each_lane_once`].
pub fn tracks(
    trace: &[aviary_api::trace::Record<'static>],
    drones: &[&str],
) -> Vec<(String, Vec<[f64; 3]>)> {
    drones
        .iter()
        .map(|d| {
            let track = crate::trace::positions_in(trace, d).into_iter().map(|(_, p)| p);
            (d.to_string(), track.collect())
        })
        .collect()
}

/// Metres between two points looked at along a lane.
pub const STEP: f64 = 0.5;
/// Metres left out at each end of a lane.
pub const MARGIN: f64 = 1.0;
/// How far (metres) a track may pass from a point and still fly over it.
pub const NEAR: f64 = 1.0;
/// How far (radians) a track's direction may turn from the lane's.
pub const ALONG: f64 = 0.05;

/// Who flew over each point of one lane: per point (from the lane's start), the drones,
/// once per pass.
pub type LanePasses = Vec<Vec<String>>;

/// For each lane, who flew over each of its points. `tracks`: each drone's telemetry
/// positions in time order.
pub fn passes(lanes: &[Lane], tracks: &[(String, Vec<[f64; 3]>)]) -> Vec<LanePasses> {
    lanes.iter().map(|lane| lane_passes(*lane, tracks)).collect()
}

fn lane_passes(lane: Lane, tracks: &[(String, Vec<[f64; 3]>)]) -> LanePasses {
    let [s, e] = lane;
    let len = (e[0] - s[0]).hypot(e[1] - s[1]);
    let dir = [(e[0] - s[0]) / len, (e[1] - s[1]) / len];
    let mut points = Vec::new();
    let mut at = MARGIN;
    while at <= len - MARGIN {
        points.push([s[0] + dir[0] * at, s[1] + dir[1] * at]);
        at += STEP;
    }
    let mut out: LanePasses = vec![Vec::new(); points.len()];
    for (drone, track) in tracks {
        for (i, p) in points.iter().enumerate() {
            let mut in_pass = false;
            for w in track.windows(2) {
                if (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]) < 1e-6 {
                    // Holding still (a hover, a pause) neither begins nor ends a pass.
                    continue;
                }
                let over = flies_over([w[0][0], w[0][1]], [w[1][0], w[1][1]], *p, dir);
                if over && !in_pass {
                    out[i].push(drone.clone());
                }
                in_pass = over;
            }
        }
    }
    out
}

/// Whether the piece from `a` to `b` (not counting `b`) runs along `dir` (either way) and
/// over `p`.
///
/// Where along the piece it passes `p` is measured along the lane (`dir`), not along the
/// piece: consecutive pieces then cover the lane end to end with no gap and no overlap,
/// however slightly each leans. Measured along a leaning piece, a point a little to one
/// side falls past the piece's end and before the next one's start, and is missed.
fn flies_over(a: [f64; 2], b: [f64; 2], p: [f64; 2], dir: [f64; 2]) -> bool {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len = d[0].hypot(d[1]);
    if len < 1e-6 {
        return false;
    }
    let along = d[0] * dir[0] + d[1] * dir[1];
    if (along / len).abs() < ALONG.cos() {
        return false;
    }
    let t = ((p[0] - a[0]) * dir[0] + (p[1] - a[1]) * dir[1]) / along;
    // Half open: where one piece ends and the next begins (a drone stopping where another
    // goes on) is flown over once.
    if !(0.0..1.0).contains(&t) {
        return false;
    }
    let q = [a[0] + t * d[0], a[1] + t * d[1]];
    (q[0] - p[0]).hypot(q[1] - p[1]) <= NEAR
}

/// Holds every lane to one pass over each of its points, and returns, per lane, the
/// drones that flew it in order along the lane (one name for a lane flown whole by one
/// drone, two for a lane one began and another finished). Panics with the lane and the
/// point otherwise.
pub fn each_lane_once(lanes: &[Lane], tracks: &[(String, Vec<[f64; 3]>)]) -> Vec<Vec<String>> {
    let all = passes(lanes, tracks);
    let mut owners = Vec::new();
    for (k, lane) in all.iter().enumerate() {
        let mut who: Vec<String> = Vec::new();
        for (i, point) in lane.iter().enumerate() {
            let at = MARGIN + i as f64 * STEP;
            assert!(
                !point.is_empty(),
                "lane {k} {:?}: nobody flew over it {at} m from its start",
                lanes[k]
            );
            assert!(
                point.len() == 1,
                "lane {k} {:?}: flown over {at} m from its start by {point:?}",
                lanes[k]
            );
            if who.last() != Some(&point[0]) {
                who.push(point[0].clone());
            }
        }
        owners.push(who);
    }
    owners
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lane_flown_half_by_each_drone_is_theirs_in_order_and_a_second_pass_is_seen() {
        let lane: Lane = [[0.0, 0.0], [100.0, 0.0]];
        let steps = |from: f64, to: f64| -> Vec<[f64; 3]> {
            (0..=100).map(|i| [from + (to - from) * i as f64 / 100.0, 0.0, 20.0]).collect()
        };
        // `b` comes across the lane from the side first: that is no pass.
        let mut b = vec![[60.0, -50.0, 20.0], [60.0, 50.0, 20.0], [60.0, 0.0, 20.0]];
        b.extend(steps(60.0, 100.0));
        let tracks = vec![("a".to_string(), steps(0.0, 60.0)), ("b".to_string(), b)];
        assert_eq!(each_lane_once(&[lane], &tracks), vec![vec!["a".to_string(), "b".to_string()]]);
        let twice = vec![("a".to_string(), [steps(0.0, 100.0), steps(100.0, 50.0)].concat())];
        let passes = passes(&[lane], &twice);
        assert!(passes[0].iter().any(|p| p.len() == 2));
    }

    /// Seen over MAVLink under load: a drone that came onto the lane 0.9 m to its side,
    /// telemetry positions whose sideways coordinate moves in steps (they are rounded to
    /// 1e-7 degrees), and a point 53.5 m along the lane that fell between two pieces.
    #[test]
    fn a_point_beside_a_leaning_piece_is_flown_over() {
        let lane: Lane = [[60.0, 50.0], [-60.0, 50.0]];
        let track = vec![
            [6.904489283471992, 49.114799098468325, 15.0],
            [6.484415267304385, 49.125918591262725, 15.0],
            [6.03379041364912, 49.125918591262725, 15.0],
        ];
        let passes = passes(&[lane], &[("buddy".to_string(), track)]);
        let at = ((53.5 - MARGIN) / STEP) as usize;
        assert_eq!(passes[0][at], vec!["buddy".to_string()]);
    }

    proptest::proptest! {
        /// A drone that flies a lane end to end, leaning each piece a little (within
        /// [`ALONG`]) and keeping within [`NEAR`] of it, flies over each of its points
        /// exactly once, however its samples fall.
        #[test]
        fn a_lane_flown_once_near_it_is_flown_over_once_at_every_point(
            steps in proptest::collection::vec((0.05f64..1.5, -0.9f64..0.9), 1..400),
        ) {
            let lane: Lane = [[0.0, 0.0], [100.0, 0.0]];
            let mut track = vec![[-1.0, 0.0, 20.0]];
            let mut x = -1.0;
            while x <= 101.0 {
                for &(dx, side) in &steps {
                    let [px, py, _] = *track.last().unwrap();
                    // Lean at most 0.9 of ALONG from the lane towards `side`.
                    let y = side.clamp(py - 0.9 * ALONG.tan() * dx, py + 0.9 * ALONG.tan() * dx);
                    x = px + dx;
                    track.push([x, y, 20.0]);
                    if x > 101.0 {
                        break;
                    }
                }
            }
            let passes = passes(&[lane], &[("a".to_string(), track)]);
            for (i, point) in passes[0].iter().enumerate() {
                proptest::prop_assert_eq!(point.len(), 1, "point {}", i);
            }
        }
    }
}
