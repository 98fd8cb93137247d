//! The boustrophedon ("lawnmower") path of `Sweep(area, spacing)`.
//!
//! Passes run along the longer side of the polygon's bounding box, `spacing` apart and
//! centred in it, so every point of the polygon lies within `spacing / 2` (across the
//! passes) of the nearest pass. Each pass covers the polygon's *band* around it (the
//! points within `spacing / 2` across): its extent along the pass is the projection of the
//! band's slice of the polygon, which for slanted edges reaches a little past the polygon
//! at the pass itself; that is what makes the `spacing / 2` guarantee hold everywhere.
//! A pass that the polygon splits in several pieces (a U shape) flies them in order; the
//! passes alternate direction.
//!
//! Part of the contract rather than of a backend, so that the simulator and the MAVLink
//! backend fly the same path and the plan costs the path they fly.

/// A lane: a piece of one pass, from where the drone enters it to where it leaves it.
pub type Lane = [[f64; 2]; 2];

/// The path, as `[x, y]` points in flying order. Empty for fewer than 3 corners or a
/// spacing that is not positive.
pub fn lawnmower(polygon: &[[f64; 2]], spacing: f64) -> Vec<[f64; 2]> {
    path(&lanes(polygon, spacing))
}

/// The lanes of the path, in flying order: each pass's pieces, the passes alternating
/// direction. Empty for fewer than 3 corners or a spacing that is not positive.
pub fn lanes(polygon: &[[f64; 2]], spacing: f64) -> Vec<Lane> {
    if polygon.len() < 3 || spacing.is_nan() || spacing <= 0.0 {
        return Vec::new();
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in polygon {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    // (u, w): u along the passes, w across them.
    let along_x = hi[0] - lo[0] >= hi[1] - lo[1];
    let to_uw = |p: [f64; 2]| if along_x { p } else { [p[1], p[0]] };
    let uw: Vec<[f64; 2]> = polygon.iter().map(|&p| to_uw(p)).collect();
    let (w_min, w_max) = if along_x { (lo[1], hi[1]) } else { (lo[0], hi[0]) };
    let extent = w_max - w_min;
    let passes = ((extent / spacing) - 1e-9).ceil().max(1.0) as usize;
    let first = w_min + (extent - (passes - 1) as f64 * spacing) / 2.0;

    let mut lanes: Vec<Lane> = Vec::new();
    let mut forward = true;
    for i in 0..passes {
        let w = first + i as f64 * spacing;
        let band = ((w - spacing / 2.0).max(w_min), (w + spacing / 2.0).min(w_max));
        let mut pieces = projection(&uw, band.0, band.1);
        if pieces.is_empty() {
            continue;
        }
        if !forward {
            pieces.reverse();
        }
        for (a, b) in pieces {
            let (s, e) = if forward { (a, b) } else { (b, a) };
            lanes.push([to_uw([s, w]), to_uw([e, w])]);
        }
        forward = !forward;
    }
    lanes
}

/// The points a drone flies through to fly `lanes` in order: each lane's start and end,
/// a point equal to the one before it given once.
pub fn path(lanes: &[Lane]) -> Vec<[f64; 2]> {
    points(lanes).into_iter().map(|(p, _)| p).collect()
}

/// What a point of [`path`] is: the start of lane `i`, or (`true`) its end.
pub type Role = (usize, bool);

/// [`path`]'s points, each with what it is. A lane's start that equals the point before
/// it (a lane of no length after another's end) is that point; a lane's end that equals
/// its start is its start.
pub fn points(lanes: &[Lane]) -> Vec<([f64; 2], Role)> {
    let mut out: Vec<([f64; 2], Role)> = Vec::new();
    for (i, lane) in lanes.iter().enumerate() {
        for (k, &p) in lane.iter().enumerate() {
            if out.last().map(|(q, _)| *q) != Some(p) {
                out.push((p, (i, k == 1)));
            }
        }
    }
    out
}

/// The intervals of `u` that the polygon (in (u, w) coordinates) covers for some `w` in
/// `[lo, hi]`, sorted and merged.
fn projection(poly: &[[f64; 2]], lo: f64, hi: f64) -> Vec<(f64, f64)> {
    let mut cuts: Vec<f64> = vec![lo, hi];
    cuts.extend(poly.iter().map(|p| p[1]).filter(|&w| w > lo && w < hi));
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let mut intervals: Vec<(f64, f64)> = Vec::new();
    if cuts.len() == 1 {
        // A band of no width: the polygon has no area.
        return intervals;
    }
    for pair in cuts.windows(2) {
        let (c0, c1) = (pair[0], pair[1]);
        let mid = (c0 + c1) / 2.0;
        // No corner lies strictly between c0 and c1, so every edge that crosses `mid`
        // spans the whole range, and the edges keep their order along u.
        let mut crossing: Vec<(f64, f64, f64)> = Vec::new();
        for (i, &a) in poly.iter().enumerate() {
            let b = poly[(i + 1) % poly.len()];
            if (a[1] > mid) != (b[1] > mid) {
                let at = |w: f64| a[0] + (w - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
                crossing.push((at(mid), at(c0), at(c1)));
            }
        }
        crossing.sort_by(|x, y| x.0.total_cmp(&y.0));
        for pair in crossing.chunks_exact(2) {
            let (l, r) = (pair[0], pair[1]);
            intervals.push((l.1.min(l.2), r.1.max(r.2)));
        }
    }
    intervals.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (a, b) in intervals {
        match merged.last_mut() {
            Some(last) if a <= last.1 + 1e-9 => last.1 = last.1.max(b),
            _ => merged.push((a, b)),
        }
    }
    merged
}
