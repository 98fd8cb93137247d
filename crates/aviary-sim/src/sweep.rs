//! `Sweep(area, spacing)` flies the middle layer's lawnmower path (`aviary_api::sweep`);
//! these tests hold the simulator's geometry to its guarantee.

pub use aviary_api::sweep::lawnmower;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{contains, dist_to_polyline};

    /// The largest distance from a grid of points inside the polygon to the path.
    fn worst_gap(polygon: &[[f64; 2]], path: &[[f64; 2]], step: f64) -> f64 {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in polygon {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let mut worst: f64 = 0.0;
        let nx = ((hi[0] - lo[0]) / step).ceil() as usize;
        let ny = ((hi[1] - lo[1]) / step).ceil() as usize;
        for i in 0..=nx {
            for j in 0..=ny {
                let p =
                    [(lo[0] + i as f64 * step).min(hi[0]), (lo[1] + j as f64 * step).min(hi[1])];
                if contains(polygon, p) {
                    worst = worst.max(dist_to_polyline(p, path));
                }
            }
        }
        worst
    }

    #[test]
    fn covers_a_rectangle() {
        let rect = [[50.0, 200.0], [350.0, 200.0], [350.0, 450.0], [50.0, 450.0]];
        let path = lawnmower(&rect, 30.0);
        // Passes along x (the longer side), 9 of them for 250 m.
        assert_eq!(path.len(), 18);
        assert!(path.iter().all(|p| contains(&rect, *p)));
        assert!(worst_gap(&rect, &path, 1.0) <= 15.0 + 1e-6);
    }

    #[test]
    fn covers_a_tall_rectangle_with_passes_along_y() {
        let rect = [[0.0, 0.0], [40.0, 0.0], [40.0, 300.0], [0.0, 300.0]];
        let path = lawnmower(&rect, 10.0);
        assert_eq!(path.len(), 8);
        assert_eq!(path[0], [5.0, 0.0]);
        assert_eq!(path[1], [5.0, 300.0]);
        assert!(worst_gap(&rect, &path, 1.0) <= 5.0 + 1e-6);
    }

    #[test]
    fn covers_an_l_shape() {
        let l = crate::geom::L_SHAPE;
        let path = lawnmower(&l, 15.0);
        assert!(worst_gap(&l, &path, 0.5) <= 7.5 + 1e-6, "gap {}", worst_gap(&l, &path, 0.5));
    }

    #[test]
    fn covers_a_u_shape_and_slanted_edges() {
        let u = [
            [0.0, 0.0],
            [90.0, 0.0],
            [90.0, 60.0],
            [60.0, 60.0],
            [60.0, 20.0],
            [30.0, 20.0],
            [30.0, 60.0],
            [0.0, 60.0],
        ];
        let path = lawnmower(&u, 10.0);
        assert!(worst_gap(&u, &path, 0.5) <= 5.0 + 1e-6);
        let tri = [[0.0, 0.0], [200.0, 30.0], [20.0, 90.0]];
        let path = lawnmower(&tri, 12.0);
        assert!(worst_gap(&tri, &path, 0.5) <= 6.0 + 1e-6);
    }

    #[test]
    fn degenerate_inputs_give_no_path() {
        assert!(lawnmower(&[[0.0, 0.0], [1.0, 1.0]], 5.0).is_empty());
        assert!(lawnmower(&[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]], 0.0).is_empty());
    }
}
