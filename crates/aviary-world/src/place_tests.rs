//! Where things are: homes and targets inside the geofence, nothing below the ground,
//! fences and areas that enclose an area without crossing themselves. Each problem is
//! an E119 at the value at fault.

use aviary_diagnostics::FileId;

use crate::parse_world;

/// The messages and the text under each diagnostic's span.
fn problems(text: &str) -> Vec<(String, String)> {
    let (world, diags) = parse_world(FileId(0), text);
    assert!(world.is_none() || diags.iter().all(|d| !d.is_error()));
    diags.iter().map(|d| (d.message.clone(), text[d.primary.span.range()].to_string())).collect()
}

const FENCE: &str = "[site]\ngeofence = [[-100, -100], [100, -100], [100, 100], [-100, 100]]\n";

#[test]
fn a_home_outside_the_fence_is_an_error_at_the_home() {
    let text = format!("{FENCE}[drones.far]\nhome = [5000, 0]\n[drones.near]\nhome = [100, 100]\n");
    assert_eq!(
        problems(&text),
        vec![(
            "drone `far`'s home (5000, 0) is outside the geofence".to_string(),
            "[5000, 0]".to_string()
        )]
    );
}

#[test]
fn a_target_outside_the_fence_or_below_the_ground_is_an_error() {
    let text = format!("{FENCE}[drones.d]\nhome = [0, 0]\n[[targets]]\nkind = \"Body\"\nat = [0, 300]\n[[targets]]\nkind = \"Body\"\nat = [0, 0, -1]\n");
    assert_eq!(
        problems(&text),
        vec![
            (
                "the target at (0, 300) is outside the geofence, where no drone may fly to find it"
                    .to_string(),
                "[0, 300]".to_string()
            ),
            ("a target is below the ground: z = -1 m".to_string(), "[0, 0, -1]".to_string()),
        ]
    );
}

#[test]
fn a_place_or_home_below_the_ground_is_an_error_and_on_it_is_fine() {
    let text = "[places]\nDeep = [0, 0, -0.5]\nFlat = [0, 0, 0]\n[drones.d]\nhome = [0, 0, -3]\n";
    assert_eq!(
        problems(text),
        vec![
            (
                "place `Deep` is below the ground: z = -0.5 m".to_string(),
                "[0, 0, -0.5]".to_string()
            ),
            (
                "`home` of drone `d` is below the ground: z = -3 m".to_string(),
                "[0, 0, -3]".to_string()
            ),
        ]
    );
}

#[test]
fn a_fence_must_enclose_an_area_and_not_cross_itself() {
    let line = "[site]\ngeofence = [[0, 0], [50, 50], [100, 100]]\n[drones.d]\nhome = [0, 0]\n";
    assert_eq!(
        problems(line),
        vec![(
            "the geofence encloses no area: its corners lie on one line".to_string(),
            "[[0, 0], [50, 50], [100, 100]]".to_string()
        )]
    );
    let bowtie =
        "[site]\ngeofence = [[0, 0], [100, 100], [100, 0], [0, 100]]\n[drones.d]\nhome = [0, 0]\n";
    let found = problems(bowtie);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(
        found[0]
            .0
            .starts_with("the geofence crosses itself: its edge from (0, 0) to (100, 100) crosses"),
        "{found:?}"
    );
    // Without a valid fence, homes are not held to it: one problem, not one per drone.
    let ok = "[site]\ngeofence = [[0, 0], [100, 0], [100, 100], [0, 100]]\n[areas]\nA = [[10, 10], [20, 10], [20, 20]]\n[drones.d]\nhome = [100, 50]\n";
    assert!(problems(ok).is_empty());
}

#[test]
fn a_line_is_points_in_order_each_with_or_without_a_height() {
    let text =
        "[lines]\nPipeline = [[0, 0], [100, 0, 30], [100, 200]]\n[drones.d]\nhome = [0, 0]\n";
    let (world, diags) = parse_world(FileId(0), text);
    assert!(diags.is_empty(), "{diags:?}");
    let line = world.unwrap().line("Pipeline").cloned().unwrap();
    assert_eq!(
        line.points,
        vec![([0.0, 0.0, 0.0], false), ([100.0, 0.0, 30.0], true), ([100.0, 200.0, 0.0], false)]
    );
    assert_eq!(line.path()[1].z, Some(30.0));
    assert_eq!(line.path()[2].z, None);
}

#[test]
fn a_line_of_one_point_or_of_bad_points_is_an_error_at_it() {
    let text = "[lines]\nShort = [[0, 0]]\nDeep = [[0, 0], [5, 5, -1]]\nFlat = [0, 0]\nBad-name = [[0, 0], [1, 1]]\n[drones.d]\nhome = [0, 0]\n";
    let found = problems(text);
    assert_eq!(
        found,
        vec![
            (
                "line `Short` has 1 point; a line needs at least 2".to_string(),
                "[[0, 0]]".to_string()
            ),
            (
                "a point of line `Deep` is below the ground: z = -1 m".to_string(),
                "[5, 5, -1]".to_string()
            ),
            (
                "a point of line `Flat` must be a position [x, y] or [x, y, z], found an integer"
                    .to_string(),
                "0".to_string()
            ),
            (
                "a point of line `Flat` must be a position [x, y] or [x, y, z], found an integer"
                    .to_string(),
                "0".to_string()
            ),
            (
                "line `Bad-name` is not a valid name, so mission code could not refer to it"
                    .to_string(),
                "Bad-name".to_string()
            ),
        ]
    );
}

#[test]
fn a_line_shares_the_names_of_places_and_areas() {
    let text =
        "[places]\nRiver = [0, 0]\n[lines]\nRiver = [[0, 0], [1, 1]]\n[drones.d]\nhome = [0, 0]\n";
    let found = problems(text);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].0.contains("used for a place and for a line"), "{found:?}");
}
