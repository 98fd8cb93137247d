//! Resumable coverage: what a `Sweep` or a `FollowPath` had not flown yet when it ended
//! early (a fault, an abort, a failure on the way), as a value a mission reads
//! (`drone.remaining`) and gives to another `Sweep` or `FollowPath` (docs/LANGUAGE.md,
//! section 19).
//!
//! One truth: the path a call flies is made here and in [`crate::sweep`] (both backends
//! and the plan fly [`sweep_lanes`] and [`follow_points`]), and what is left of it is
//! computed here from where the backend says the drone had got to ([`Progress`]: the
//! point of that same path it was flying to, and where it was). A backend never computes
//! a remainder itself, so the simulator and MAVLink leave the same remainder for the same
//! stop.
//!
//! What is left of a sweep is lanes, not a polygon: the lanes not flown yet, the first
//! of them cut where the drone stopped when it stopped on a lane (between two lanes, the
//! next lane is left whole). Flown again (by any drone), those lanes are flown as they
//! were laid out, so the two flights together fly every lane once. The spacing is the
//! one they were laid out at: a sweep of a remainder at another spacing is refused,
//! since lanes laid out for one spacing leave gaps, or overlap, at another.

use serde::{Deserialize, Serialize};

use crate::call::{FunctionCall, Region, Waypoint};
use crate::sweep::{self, Lane};
use crate::Point;

/// What a `Sweep` or `FollowPath` left: the lanes of a sweep, or the rest of a path.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Remainder {
    /// Nothing is left: the drone's last `Sweep` or `FollowPath` finished, or it has
    /// flown none.
    #[default]
    Nothing,
    /// A sweep's lanes not flown yet, in flying order, laid out `spacing` metres apart.
    Lanes { lanes: Vec<Lane>, spacing: f64 },
    /// The rest of a path: where the drone stopped, then the points it had not reached.
    /// A point without a height keeps the altitude of the drone that flies it.
    Points(Vec<Point>),
}

/// Where a path call (`Sweep`, `FollowPath`) had got to when it stopped: the index of the
/// point of its path it was flying to (0: still on its way to the first), and where the
/// drone was then (local metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    pub next: usize,
    pub at: [f64; 3],
}

impl Remainder {
    /// Lanes, or [`Remainder::Nothing`] when there are none.
    pub fn lanes(lanes: Vec<Lane>, spacing: f64) -> Remainder {
        if lanes.is_empty() {
            Remainder::Nothing
        } else {
            Remainder::Lanes { lanes, spacing }
        }
    }

    /// Points, or [`Remainder::Nothing`] when there are none.
    pub fn points(points: Vec<Point>) -> Remainder {
        if points.is_empty() {
            Remainder::Nothing
        } else {
            Remainder::Points(points)
        }
    }

    pub fn is_empty(&self) -> bool {
        *self == Remainder::Nothing
    }

    /// The points a drone flies through to fly it, in order.
    pub fn path(&self) -> Vec<Point> {
        match self {
            Remainder::Nothing => Vec::new(),
            Remainder::Lanes { lanes, .. } => {
                sweep::path(lanes).into_iter().map(|p| Point::flat(p[0], p[1])).collect()
            }
            Remainder::Points(points) => points.clone(),
        }
    }

    /// Its length over the ground, in metres: the lanes and the turns between them, or
    /// the rest of the path from where the drone stopped.
    pub fn length(&self) -> f64 {
        let path = self.path();
        path.windows(2).map(|w| (w[1].x - w[0].x).hypot(w[1].y - w[0].y)).sum()
    }

    /// How many lanes are left (a lane begun counts as one); `None` for a path.
    pub fn lane_count(&self) -> Option<usize> {
        match self {
            Remainder::Nothing => Some(0),
            Remainder::Lanes { lanes, .. } => Some(lanes.len()),
            Remainder::Points(_) => None,
        }
    }
}

/// The lanes `Sweep(area, spacing)` flies: an area's ([`sweep::lanes`]), or those a
/// remainder left. A remainder of a path, or of a sweep laid out at another spacing, is
/// refused, with the reason.
pub fn sweep_lanes(area: &Region, spacing: f64) -> Result<Vec<Lane>, String> {
    match area {
        Region::Area(polygon) => Ok(sweep::lanes(polygon, spacing)),
        Region::Left(left) => match &**left {
            Remainder::Nothing => Ok(Vec::new()),
            Remainder::Lanes { lanes, spacing: laid } => {
                if (laid - spacing).abs() > 1e-6 * laid.abs().max(1.0) {
                    return Err(format!(
                        "these lanes were laid out {} m apart: sweep them with spacing {} m, not {} m",
                        crate::show::number(*laid),
                        crate::show::number(*laid),
                        crate::show::number(spacing)
                    ));
                }
                Ok(lanes.clone())
            }
            Remainder::Points(_) => {
                Err("this is what a FollowPath left, a path and not lanes: fly it with FollowPath"
                    .into())
            }
        },
    }
}

/// The points `FollowPath(points...)` flies through, in order: a position is itself, an
/// area its centroid, a remainder the points of its path. A position whose coordinates
/// are not finite, or an area without corners, is refused, with the reason.
pub fn follow_points(points: &[Waypoint]) -> Result<Vec<Point>, String> {
    let mut out = Vec::new();
    for (i, v) in points.iter().enumerate() {
        match v {
            Waypoint::Point(p) if crate::call::finite(p) => out.push(*p),
            Waypoint::Area(polygon) if !polygon.is_empty() => {
                let c = crate::centroid(polygon);
                out.push(Point::flat(c[0], c[1]));
            }
            Waypoint::Left(left) => out.extend(left.path()),
            other => {
                return Err(format!(
                "`points[{i}]` must be a position, or what a Sweep or FollowPath left, not {other}"
            ))
            }
        }
    }
    Ok(out)
}

/// The speed `FollowPath(points...[, speed])` was asked to fly at (m/s), above 0; `None`
/// when it has none (the drone's own speed).
pub fn follow_speed(speed: Option<f64>) -> Result<Option<f64>, String> {
    match speed {
        Some(s) if s.is_finite() && s > 0.0 => Ok(Some(s)),
        Some(s) => Err(format!("`speed` must be above 0 m/s, not {} m/s", crate::show::number(s))),
        None => Ok(None),
    }
}

/// What `call` left when it stopped at `progress` (`None`: it stopped before it moved,
/// so all of it is left). `None` for a function that flies no path, or arguments no
/// backend would fly. A sweep of a remainder leaves lanes at that remainder's own
/// spacing, whatever spacing it was given.
pub fn left(call: &FunctionCall, progress: Option<Progress>) -> Option<Remainder> {
    match call {
        FunctionCall::Sweep { area, spacing } => {
            let (lanes, spacing) = match area {
                Region::Left(left) => match &**left {
                    Remainder::Lanes { lanes, spacing } => (lanes.clone(), *spacing),
                    Remainder::Nothing => return Some(Remainder::Nothing),
                    // Refused: a path is not swept, so it is all still left.
                    Remainder::Points(_) => return Some((**left).clone()),
                },
                Region::Area(_) => (sweep_lanes(area, *spacing).ok()?, *spacing),
            };
            Some(lanes_left(lanes, spacing, progress))
        }
        FunctionCall::FollowPath { points, .. } => {
            Some(points_left(&follow_points(points).ok()?, progress))
        }
        _ => None,
    }
}

/// What is left of `lanes` flown up to `progress`: the lane begun from the point of it
/// nearest to where the drone stopped, and the lanes after it; between two lanes, the
/// next whole.
fn lanes_left(lanes: Vec<Lane>, spacing: f64, progress: Option<Progress>) -> Remainder {
    let Some(Progress { next, at }) = progress else {
        return Remainder::lanes(lanes, spacing);
    };
    let points = sweep::points(&lanes);
    let Some(&(_, (lane, is_end))) = points.get(next) else {
        // Past its last point: nothing is left.
        return Remainder::Nothing;
    };
    if next == 0 || !is_end {
        return Remainder::lanes(lanes[lane..].to_vec(), spacing);
    }
    // On lane `lane`: its start is the point before, flown; what is left of it starts
    // where the drone is, brought onto the lane.
    let [s, e] = lanes[lane];
    let from = onto_segment([at[0], at[1]], s, e);
    let mut out = Vec::with_capacity(lanes.len() - lane);
    if (e[0] - from[0]).hypot(e[1] - from[1]) > 1e-6 {
        out.push([from, e]);
    }
    out.extend_from_slice(&lanes[lane + 1..]);
    Remainder::lanes(out, spacing)
}

/// What is left of a path flown up to `progress`: where the drone stopped, then the
/// points it had not reached, each with the height it would have been flown at (its
/// own, or the last one given before it; none when none was given).
fn points_left(points: &[Point], progress: Option<Progress>) -> Remainder {
    // The height each point is flown at, when the path says one.
    let mut z = None;
    let resolved: Vec<Point> = points
        .iter()
        .map(|p| {
            z = p.z.or(z);
            Point { z, ..*p }
        })
        .collect();
    let Some(Progress { next, at }) = progress else {
        return Remainder::points(resolved);
    };
    if next >= resolved.len() {
        return Remainder::Nothing;
    }
    let mut out = Vec::with_capacity(resolved.len() - next + 1);
    if next > 0 {
        out.push(Point { x: at[0], y: at[1], z: resolved[next].z });
    }
    out.extend_from_slice(&resolved[next..]);
    Remainder::points(out)
}

/// The point of segment `a`–`b` nearest to `p`.
fn onto_segment(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    let d = [b[0] - a[0], b[1] - a[1]];
    let len2 = d[0] * d[0] + d[1] * d[1];
    if len2 <= 0.0 || !len2.is_finite() {
        return a;
    }
    let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0);
    if t.is_nan() {
        return a;
    }
    [a[0] + t * d[0], a[1] + t * d[1]]
}

/// How a remainder is written in the trace and read back: `{"lanes": [[[x, y], [x,
/// y]], ...], "spacing": s}`, `{"points": [[x, y], [x, y, z], ...]}`, and nothing left
/// as `{"points": []}`.
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum Written {
    Lanes { lanes: Vec<Lane>, spacing: f64 },
    Points { points: Vec<Vec<Option<f64>>> },
}

impl Serialize for Remainder {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let written = match self {
            Remainder::Nothing => Written::Points { points: Vec::new() },
            Remainder::Lanes { lanes, spacing } => {
                Written::Lanes { lanes: lanes.clone(), spacing: *spacing }
            }
            Remainder::Points(points) => Written::Points {
                points: points
                    .iter()
                    .map(|p| {
                        let mut c = vec![Some(p.x), Some(p.y)];
                        c.extend(p.z.map(Some));
                        c
                    })
                    .collect(),
            },
        };
        written.serialize(s)
    }
}

impl<'de> Deserialize<'de> for Remainder {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        Ok(match Written::deserialize(d)? {
            Written::Lanes { lanes, spacing } => Remainder::lanes(lanes, spacing),
            Written::Points { points } => {
                let mut out = Vec::with_capacity(points.len());
                for c in points {
                    let n = |i: usize| c.get(i).copied().flatten().unwrap_or(f64::NAN);
                    match c.len() {
                        2 => out.push(Point::flat(n(0), n(1))),
                        3 => out.push(Point { x: n(0), y: n(1), z: Some(n(2)) }),
                        k => return Err(D::Error::invalid_length(k, &"2 or 3 coordinates")),
                    }
                }
                Remainder::points(out)
            }
        })
    }
}

#[cfg(test)]
mod tests;
