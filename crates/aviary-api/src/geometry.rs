//! Geometry of the values the middle layer passes: one definition for every crate.

/// Shoelace centroid; the corners' mean when the polygon encloses (almost) no area.
pub fn centroid(polygon: &[[f64; 2]]) -> [f64; 2] {
    if polygon.is_empty() {
        return [0.0, 0.0];
    }
    let n = polygon.len() as f64;
    let mean = [
        polygon.iter().map(|p| p[0]).sum::<f64>() / n,
        polygon.iter().map(|p| p[1]).sum::<f64>() / n,
    ];
    // Relative to the mean, for precision far from the origin.
    let (mut twice_area, mut cx, mut cy) = (0.0, 0.0, 0.0);
    let mut extent: f64 = 0.0;
    for (i, a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        let (ax, ay) = (a[0] - mean[0], a[1] - mean[1]);
        let (bx, by) = (b[0] - mean[0], b[1] - mean[1]);
        let cross = ax * by - bx * ay;
        twice_area += cross;
        cx += (ax + bx) * cross;
        cy += (ay + by) * cross;
        extent = extent.max(ax.abs()).max(ay.abs());
    }
    if !twice_area.is_finite() || twice_area.abs() <= 1e-12 * extent * extent {
        return mean;
    }
    [
        mean[0] + cx / (3.0 * twice_area),
        mean[1] + cy / (3.0 * twice_area),
    ]
}
