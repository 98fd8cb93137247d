//! The planner's laws: straight when nothing is in the way, never into a zone or its margin,
//! inside the fence, no longer than needed.

use super::*;
use aviary_api::geometry::dist_to_boundary;
use proptest::prelude::*;

fn square(x: f64, y: f64, side: f64) -> Vec<[f64; 2]> {
    vec![[x, y], [x + side, y], [x + side, y + side], [x, y + side]]
}

fn length(from: [f64; 2], way: &[[f64; 2]]) -> f64 {
    let mut prev = from;
    let mut total = 0.0;
    for &p in way {
        total += dist(prev, p);
        prev = p;
    }
    total
}

/// The distance from the segment `a`-`b` to the polygon (0 when it enters it), sampled
/// finely: an independent measure of what a drone on the line would come near.
fn nearest(polygon: &[[f64; 2]], a: [f64; 2], b: [f64; 2]) -> f64 {
    let n = (dist(a, b) / 0.05).ceil().max(1.0) as usize;
    (0..=n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            if contains(polygon, p) {
                0.0
            } else {
                dist_to_boundary(polygon, p)
            }
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_world_without_zones_and_a_clear_line_fly_straight() {
    let open = Airspace::new(None, std::iter::empty(), MARGIN);
    assert!(open.is_open());
    assert_eq!(open.route([0.0, 0.0], [500.0, 300.0], 10.0), Ok(vec![[500.0, 300.0]]));
    let zone = square(100.0, 100.0, 50.0);
    let space = Airspace::new(None, [(zone.as_slice(), None)], MARGIN);
    // Well south of the zone, and past its margin by a hair.
    assert_eq!(space.route([0.0, 0.0], [300.0, 0.0], 10.0), Ok(vec![[300.0, 0.0]]));
    assert_eq!(space.route([0.0, 89.0], [300.0, 89.0], 10.0), Ok(vec![[300.0, 89.0]]));
}

#[test]
fn the_way_around_one_square_is_the_shortest_that_keeps_the_margin() {
    let zone = square(0.0, 0.0, 100.0);
    let space = Airspace::new(None, [(zone.as_slice(), None)], MARGIN);
    let (from, to) = ([-100.0, 50.0], [200.0, 50.0]);
    let way = space.route(from, to, 10.0).unwrap();
    assert_eq!(way.last(), Some(&to));
    // Over the top or under the bottom (the same length): tangent to the rounded corner,
    // along the side at the margin, and tangent again.
    let r = MARGIN;
    let d = (100.0f64 * 100.0 + 50.0 * 50.0).sqrt();
    let tangent = (d * d - r * r).sqrt();
    let beta = (-50.0f64).atan2(-100.0);
    let touch = beta - (r / d).acos() + std::f64::consts::TAU;
    let arc = touch - std::f64::consts::FRAC_PI_2;
    let shortest = 2.0 * (tangent + r * arc) + 100.0;
    let flown = length(from, &way);
    assert!((flown - shortest).abs() <= shortest * 0.002, "{flown} m, not {shortest} m: {way:?}");
    let mut prev = from;
    for &p in &way {
        assert!(nearest(&zone, prev, p) >= MARGIN * 0.99, "{prev:?} to {p:?}");
        prev = p;
    }
}

#[test]
fn a_zone_the_flight_is_above_is_flown_over_and_one_at_its_height_is_not() {
    let zone = square(0.0, -50.0, 100.0);
    let space = Airspace::new(None, [(zone.as_slice(), Some(40.0))], MARGIN);
    let (from, to) = ([-50.0, 0.0], [150.0, 0.0]);
    assert_eq!(space.route(from, to, 40.5), Ok(vec![to]));
    assert!(space.route(from, to, 40.0).unwrap().len() > 1, "up_to is in the zone");
    assert_eq!(space.zone_at([50.0, 0.0], 40.0), Some(0));
    assert_eq!(space.zone_at([50.0, 0.0], 41.0), None);
}

#[test]
fn an_end_inside_a_zone_and_a_zone_that_closes_the_fence_are_blocked() {
    let fence = square(-200.0, -200.0, 400.0);
    // A wall from the fence's south side to its north side.
    let wall = vec![[-10.0, -250.0], [10.0, -250.0], [10.0, 250.0], [-10.0, 250.0]];
    let space = Airspace::new(Some(&fence), [(wall.as_slice(), None)], MARGIN);
    assert_eq!(space.route([-100.0, 0.0], [100.0, 0.0], 10.0), Err(Blocked::NoWay { zone: 0 }));
    assert_eq!(
        space.route([-100.0, 0.0], [0.0, 0.0], 10.0),
        Err(Blocked::Inside { zone: 0, start: false })
    );
    // Without the fence there is a way round the wall's ends.
    let open = Airspace::new(None, [(wall.as_slice(), None)], MARGIN);
    let way = open.route([-100.0, 0.0], [100.0, 0.0], 10.0).unwrap();
    assert!(way.iter().any(|p| p[1].abs() > 250.0), "{way:?}");
}

#[test]
fn a_route_keeps_to_a_concave_fence_and_bends_at_its_corner() {
    // An L-shaped fence; a zone (in the L's notch, outside the fence) blocks the
    // straight line across the L's corner, so the way goes by the fence's inner corner.
    let fence = vec![
        [0.0, 0.0],
        [400.0, 0.0],
        [400.0, 100.0],
        [100.0, 100.0],
        [100.0, 400.0],
        [0.0, 400.0],
    ];
    let zone = square(150.0, 150.0, 50.0);
    let space = Airspace::new(Some(&fence), [(zone.as_slice(), None)], MARGIN);
    let (from, to) = ([50.0, 300.0], [300.0, 50.0]);
    let way = space.route(from, to, 5.0).unwrap();
    let outline = Outline::new(fence.clone());
    let mut prev = from;
    for &p in &way {
        assert!(!outline.left_by(prev, p), "{prev:?} to {p:?} leaves the fence: {way:?}");
        assert!(nearest(&zone, prev, p) >= MARGIN * 0.99);
        prev = p;
    }
    assert!(way.contains(&[100.0, 100.0]), "{way:?}");
}

#[test]
fn an_end_in_the_margin_is_reached_keeping_out_of_the_zone_itself() {
    let zone = square(0.0, 0.0, 100.0);
    let space = Airspace::new(None, [(zone.as_slice(), None)], MARGIN);
    // 3 m south of the zone, going to 3 m north of it.
    let (from, to) = ([50.0, -3.0], [50.0, 103.0]);
    let way = space.route(from, to, 10.0).unwrap();
    let mut prev = from;
    for &p in &way {
        assert!(!Outline::new(zone.clone()).crossed_by(prev, p), "{way:?}");
        prev = p;
    }
    assert!(length(from, &way) < 106.0 + 2.0 * 50.0 + 2.0 * MARGIN, "{way:?}");
}

/// Zones on a coarse grid of cells, none touching another, and two ends outside every
/// grown zone.
fn scene() -> impl Strategy<Value = (Vec<Vec<[f64; 2]>>, [f64; 2], [f64; 2])> {
    let cell = (0i32..5, 0i32..5, 10.0f64..60.0, 10.0f64..60.0, any::<bool>());
    (
        prop::collection::vec(cell, 1..5),
        (-50.0f64..550.0, -50.0f64..550.0),
        (-50.0f64..550.0, -50.0f64..550.0),
    )
        .prop_map(|(cells, a, b)| {
            let mut seen = std::collections::BTreeSet::new();
            let zones = cells
                .into_iter()
                .filter(|c| seen.insert((c.0, c.1)))
                .map(|(i, j, w, h, ell)| {
                    let (x, y) = (f64::from(i) * 100.0 + 10.0, f64::from(j) * 100.0 + 10.0);
                    if ell {
                        // An L: concave.
                        vec![
                            [x, y],
                            [x + w, y],
                            [x + w, y + 10.0],
                            [x + 10.0, y + 10.0],
                            [x + 10.0, y + h],
                            [x, y + h],
                        ]
                    } else {
                        vec![[x, y], [x + w, y], [x + w, y + h], [x, y + h]]
                    }
                })
                .collect();
            (zones, [a.0, a.1], [b.0, b.1])
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    /// Every route keeps out of every grown zone, inside the fence; it bends only where
    /// it must (each corner's shortcut is blocked), and it is straight when the straight
    /// line is clear.
    #[test]
    fn routes_keep_the_margin_stay_in_the_fence_and_bend_only_where_they_must((zones, from, to) in scene()) {
        let fence = square(-60.0, -60.0, 620.0);
        let space = Airspace::new(Some(&fence), zones.iter().map(|z| (z.as_slice(), None)), MARGIN);
        let grown: Vec<Outline> = zones.iter().map(|z| Outline::new(grow(z, MARGIN))).collect();
        prop_assume!(!grown.iter().any(|g| contains(&g.corners, from) || contains(&g.corners, to)));
        let way = space.route(from, to, 10.0);
        let Ok(way) = way else {
            // Zones on separate cells never close the way.
            return Err(TestCaseError::fail(format!("no way: {way:?}")));
        };
        let fence = Outline::new(fence);
        let straight = !grown.iter().any(|g| g.crossed_by(from, to));
        if straight {
            prop_assert_eq!(&way, &vec![to]);
        }
        let mut points = vec![from];
        points.extend(&way);
        for pair in points.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            prop_assert!(!fence.left_by(a, b), "{:?} to {:?} leaves the fence", a, b);
            for (z, g) in zones.iter().zip(&grown) {
                prop_assert!(!g.crossed_by(a, b), "{:?} to {:?} enters a grown zone", a, b);
                prop_assert!(nearest(z, a, b) >= MARGIN * 0.99, "{:?} to {:?} comes near a zone", a, b);
            }
        }
        for k in 1..points.len() - 1 {
            let (a, c) = (points[k - 1], points[k + 1]);
            let shortcut = !grown.iter().any(|g| g.crossed_by(a, c)) && !fence.left_by(a, c);
            prop_assert!(!shortcut, "the bend at {:?} is not needed: {:?}", points[k], way);
        }
        prop_assert!(length(from, &way) >= dist(from, to) - 1e-9);
    }
}

#[test]
fn sweeps_and_orbits_that_enter_a_zone_are_found_and_an_orbit_around_one_is_not() {
    let zone = square(0.0, 0.0, 100.0);
    let space = Airspace::new(None, [(zone.as_slice(), Some(50.0))], MARGIN);
    // Circling the zone.
    assert_eq!(space.circle_enters([50.0, 50.0], 100.0, 20.0), None);
    // Through it.
    assert_eq!(space.circle_enters([50.0, 50.0], 60.0, 20.0), Some(0));
    assert_eq!(space.circle_enters([50.0, 50.0], 60.0, 60.0), None);
    // Beside it.
    assert_eq!(space.circle_enters([200.0, 50.0], 40.0, 20.0), None);
    let overlapping = square(90.0, 90.0, 50.0);
    assert_eq!(space.area_overlaps(&overlapping, 20.0), Some(0));
    assert_eq!(space.area_overlaps(&square(100.0, 0.0, 50.0), 20.0), None, "sharing a side");
    let around = square(-10.0, -10.0, 120.0);
    assert_eq!(space.area_overlaps(&around, 20.0), Some(0));
    assert_eq!(space.path_enters([-10.0, 50.0], &[[110.0, 50.0]], 20.0), Some(0));
    assert_eq!(space.path_enters([-10.0, 50.0], &[[-10.0, 150.0]], 20.0), None);
}

#[test]
fn only_a_zone_makes_a_detour_not_the_fence() {
    // An L-shaped fence whose inner corner the straight line cuts, and a zone far away:
    // the line is the transit (the backends refuse it as leaving the fence), as in a
    // world without zones; and so is a line to a point outside the fence.
    let fence = vec![
        [0.0, 0.0],
        [400.0, 0.0],
        [400.0, 100.0],
        [100.0, 100.0],
        [100.0, 400.0],
        [0.0, 400.0],
    ];
    let zone = square(20.0, 20.0, 20.0);
    let space = Airspace::new(Some(&fence), [(zone.as_slice(), None)], MARGIN);
    assert_eq!(space.route([50.0, 300.0], [300.0, 50.0], 5.0), Ok(vec![[300.0, 50.0]]));
    assert_eq!(space.route([50.0, 300.0], [900.0, 50.0], 5.0), Ok(vec![[900.0, 50.0]]));
}
