//! `[fleets.NAME]`: many drones at once, named, placed and numbered by patterns, and each
//! problem an E119 at the value at fault.

use aviary_diagnostics::FileId;

use crate::{parse_world, AttributeValue, Drone, World};

fn ok(text: &str) -> World {
    let (world, diags) = parse_world(FileId(0), text);
    assert!(diags.is_empty(), "unexpected diagnostics: {diags:#?}");
    world.expect("a world when there are no diagnostics")
}

/// (message, the text under the span) of every diagnostic; there must be an error.
fn problems(text: &str) -> Vec<(String, String)> {
    let (world, diags) = parse_world(FileId(0), text);
    assert!(world.is_none(), "a world from {text}");
    for d in &diags {
        assert!(d.help.is_some(), "{d:?}");
    }
    diags.iter().map(|d| (d.message.clone(), text[d.primary.span.range()].to_string())).collect()
}

fn problem(text: &str) -> (String, String) {
    let mut all = problems(text);
    assert_eq!(all.len(), 1, "{all:#?}");
    all.remove(0)
}

fn index(d: &Drone) -> Option<f64> {
    match d.attribute("index") {
        Some(AttributeValue::Number(n)) => Some(*n),
        _ => None,
    }
}

fn homes(w: &World) -> Vec<[f64; 2]> {
    w.drones.iter().map(|d| [d.home[0], d.home[1]]).collect()
}

const SENSORS: &str = "[sensors.thermal]\ndetects = [\"Body\"]\nrange = 20\n";

#[test]
fn a_fleet_on_a_grid() {
    let w = ok(&format!(
        "[fleets.scout]\ncount = 5\ngroup = \"scouts\"\nhomes = {{ grid = [10, 20], spacing = [5, 7], columns = 2 }}\n\
         sensors = [\"thermal\", \"camera\"]\nmax_speed = 12\ncall_sign = \"S\"\n{SENSORS}"
    ));
    let names: Vec<&str> = w.drones.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, ["scout0", "scout1", "scout2", "scout3", "scout4"]);
    assert_eq!(homes(&w), [[10.0, 20.0], [15.0, 20.0], [10.0, 27.0], [15.0, 27.0], [10.0, 34.0]]);
    assert_eq!(w.groups.len(), 1);
    assert_eq!(
        (w.groups[0].name.as_str(), &w.groups[0].members[..]),
        ("scouts", &[0, 1, 2, 3, 4][..])
    );
    for (i, d) in w.drones.iter().enumerate() {
        assert_eq!(index(d), Some(i as f64));
        assert_eq!(d.max_speed, 12.0);
        assert_eq!(*d.sensors, ["thermal", "camera"]);
        assert_eq!(d.attribute("call_sign"), Some(&AttributeValue::Text("S".into())));
    }
    // One string for the group and for each attribute key, whatever the drone.
    let (a, b) = (&w.drones[0], &w.drones[4]);
    assert!(std::sync::Arc::ptr_eq(a.group.as_ref().unwrap(), b.group.as_ref().unwrap()));
    assert!(std::sync::Arc::ptr_eq(&a.attributes[0].0, &b.attributes[0].0));
}

#[test]
fn a_grid_is_square_unless_told() {
    let w = ok("[fleets.a]\ncount = 10\nhomes = { grid = [0, 0], spacing = 1 }\n");
    // ceil(sqrt(10)) = 4 columns.
    assert_eq!(homes(&w)[3..6], [[3.0, 0.0], [0.0, 1.0], [1.0, 1.0]]);
    let w = ok("[fleets.a]\ncount = 9\nhomes = { grid = [0, 0], spacing = 1 }\n");
    assert_eq!(homes(&w)[2..4], [[2.0, 0.0], [0.0, 1.0]]);
    let w = ok("[fleets.a]\ncount = 1\nhomes = { grid = [3, 4, 2], spacing = 1 }\n");
    assert_eq!(w.drones[0].home, [3.0, 4.0, 2.0]);
}

#[test]
fn a_fleet_on_a_ring() {
    let w = ok("[fleets.r]\ncount = 4\nhomes = { ring = [100, 50], radius = 10 }\n");
    let expected = [[110.0, 50.0], [100.0, 60.0], [90.0, 50.0], [100.0, 40.0]];
    for (got, want) in homes(&w).iter().zip(expected) {
        assert!((got[0] - want[0]).abs() < 1e-9 && (got[1] - want[1]).abs() < 1e-9, "{got:?}");
    }
}

#[test]
fn names_numbers_and_padding() {
    let w = ok("[fleets.f]\ncount = 3\nfirst = 9\nnames = \"uav_{i:03}_x{i}\"\nhomes = { grid = [0, 0], spacing = 5 }\n");
    let names: Vec<&str> = w.drones.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, ["uav_009_x9", "uav_010_x10", "uav_011_x11"]);
    assert_eq!(w.drones.iter().map(index).collect::<Vec<_>>(), [Some(9.0), Some(10.0), Some(11.0)]);
    // The place in the fleet, not the number, decides the home.
    assert_eq!(w.drones[0].home, [0.0, 0.0, 0.0]);
}

#[test]
fn drones_stand_in_file_order() {
    let w = ok("[drones.first]\nhome = [0, 0]\ngroup = \"g\"\n\
                [fleets.f]\ncount = 2\ngroup = \"g\"\nhomes = { grid = [0, 10], spacing = 5 }\n\
                [drones.last]\nhome = [0, 20]\ngroup = \"g\"\n");
    let names: Vec<&str> = w.drones.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, ["first", "f0", "f1", "last"]);
    assert_eq!(w.groups[0].members, [0, 1, 2, 3]);
    // A table drone has no `index` unless it sets one.
    assert_eq!(index(&w.drones[0]), None);
}

#[test]
fn each_drone_may_have_an_area_of_its_own() {
    let w = ok(
        "[areas]\nBase = [[0, 0], [1, 0], [0, 1]]\n\
                [fleets.s]\ncount = 2\nhomes = { grid = [5, 5], spacing = 300 }\n\
                areas = { names = \"Cell_{i}\", polygon = [[5, 5], [85, 5], [85, 85], [5, 85]] }\n",
    );
    let areas: Vec<(&str, &[[f64; 2]])> =
        w.areas.iter().map(|a| (a.name.as_str(), &a.polygon[..])).collect();
    assert_eq!(
        areas,
        [
            ("Base", &[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]][..]),
            ("Cell_0", &[[10.0, 10.0], [90.0, 10.0], [90.0, 90.0], [10.0, 90.0]][..]),
            ("Cell_1", &[[310.0, 10.0], [390.0, 10.0], [390.0, 90.0], [310.0, 90.0]][..]),
        ]
    );
}

#[test]
fn faults_and_missions_name_a_fleets_drones_as_any_other() {
    let w = ok("[fleets.f]\ncount = 3\nhomes = { grid = [0, 0], spacing = 5 }\n\
                [[faults]]\ndrone = \"f2\"\nat = 5\nkind = \"crash\"\n");
    assert_eq!(w.faults[0].drone, "f2");
    assert!(w.drone("f1").is_some());
    assert!(w.names().any(|n| n == "f2"));
}

#[test]
fn the_count_is_a_whole_number_within_limits() {
    let fleet = |count: &str| {
        format!("[fleets.f]\ncount = {count}\nhomes = {{ grid = [0, 0], spacing = 5 }}\n")
    };
    assert_eq!(
        problem(&fleet("1000000000000")),
        (
            "fleet `f` has 1000000000000 drones, more than a world may have: at most 10000000"
                .into(),
            "1000000000000".into()
        )
    );
    assert_eq!(problem(&fleet("0")).0, "`count` of fleet `f` must be at least 1, found 0");
    assert_eq!(problem(&fleet("2.5")).0, "`count` of fleet `f` must be a whole number, found 2.5");
    assert_eq!(
        problem(&fleet("\"9\"")).0,
        "`count` of fleet `f` must be a whole number, found \"9\""
    );
    assert_eq!(
        problem("[fleets.f]\nhomes = { grid = [0, 0], spacing = 5 }\n"),
        ("fleet `f` has no `count`".into(), "f".into())
    );
}

#[test]
fn names_must_hold_the_number_and_make_identifiers() {
    let fleet = |names: &str| {
        format!(
            "[fleets.f]\ncount = 2\nnames = {names}\nhomes = {{ grid = [0, 0], spacing = 5 }}\n"
        )
    };
    let (msg, at) = problem(&fleet("\"scout\""));
    assert_eq!(msg, "`names` of fleet `f` (`scout`) has no `{i}`, so every name would be the same");
    assert_eq!(at, "\"scout\"");
    assert!(problem(&fleet("\"a{j}\"")).0.contains("has `{j}`, which is not `{i}` or `{i:03}`"));
    assert!(problem(&fleet("\"a{i\"")).0.contains("closes nothing"));
    assert!(problem(&fleet("\"a}{i}\"")).0.contains("closes nothing"));
    assert!(problem(&fleet("\"a{i:099}\"")).0.contains("which is not"));
    assert_eq!(
        problem(&fleet("\"{i}a\"")).0,
        "the drones of fleet `f` would be named `0a` and so on, which mission code could not refer to"
    );
    assert_eq!(
        problem("[fleets.9f]\ncount = 2\nhomes = { grid = [0, 0], spacing = 5 }\n"),
        (
            "fleet `9f` names its drones `9f0` and so on, which mission code could not refer to"
                .into(),
            "9f".into()
        )
    );
}

#[test]
fn homes_are_a_grid_or_a_ring() {
    let fleet = |homes: &str| format!("[fleets.f]\ncount = 2\nhomes = {homes}\n");
    assert_eq!(problem("[fleets.f]\ncount = 2\n"), ("fleet `f` has no `homes`".into(), "f".into()));
    assert_eq!(
        problem(&fleet("{ grid = [0, 0] }")).0,
        "`homes` of fleet `f` has a `grid` but no `spacing`"
    );
    assert_eq!(
        problem(&fleet("{ ring = [0, 0] }")).0,
        "`homes` of fleet `f` has a `ring` but no `radius`"
    );
    assert_eq!(
        problem(&fleet("{ grid = [0, 0], ring = [0, 0], spacing = 1 }")),
        ("`homes` of fleet `f` has both a `grid` and a `ring`".into(), "ring".into())
    );
    assert_eq!(
        problem(&fleet("{ spacing = 1 }")).0,
        "`homes` of fleet `f` has neither a `grid` nor a `ring`"
    );
    assert_eq!(
        problem(&fleet("{ ring = [0, 0], radius = 5, columns = 3 }")),
        ("`columns` is for homes on a grid, not on a ring".into(), "columns".into())
    );
    assert_eq!(
        problem(&fleet("{ grid = [0, 0], spacing = 0 }")),
        ("`spacing` of `homes` of fleet `f` must be greater than zero, found 0".into(), "0".into())
    );
    assert_eq!(
        problem(&fleet("{ grid = [0, 0], spacing = [1, 2, 3] }")).0,
        "`spacing` of `homes` of fleet `f` must be a number or 2 numbers [east, north], found 3 numbers"
    );
    assert_eq!(
        problem(&fleet("{ grid = [0, 0], spacing = 1, columns = 0 }")).0,
        "`columns` of `homes` of fleet `f` must be at least 1, found 0"
    );
    assert_eq!(
        problem(&fleet("{ grid = [0, 0, -1], spacing = 1 }")).0,
        "`grid` of `homes` of fleet `f` is below the ground: z = -1 m"
    );
    assert!(problem(&fleet("{ grid = [0, 0], spacing = 1, colums = 3 }"))
        .0
        .contains("unknown key `colums`"));
    assert_eq!(problem(&fleet("[0, 0]")).0, "`homes` of fleet `f` must be a table, found a list");
    assert_eq!(
        problem("[fleets.f]\ncount = 9\nhomes = { grid = [0, 0], spacing = 1e308 }\n").0,
        "the homes of fleet `f` reach beyond the numbers a world can hold"
    );
}

#[test]
fn keys_a_fleet_cannot_set_for_all_its_drones() {
    let all = problems("[fleets.f]\ncount = 2\nhomes = { grid = [0, 0], spacing = 5 }\nhome = [0, 0]\nindex = 3\nmavlink = \"udp:127.0.0.1:14550\"\nsystem_id = 2\n");
    let spans: Vec<&str> = all.iter().map(|(_, at)| at.as_str()).collect();
    assert_eq!(spans, ["home", "index", "system_id"]);
    assert_eq!(all[0].0, "a fleet cannot set `home` for all its drones");
}

#[test]
fn a_fleet_on_one_mavlink_address_has_system_ids_for_255() {
    let text = "[fleets.f]\ncount = 256\nhomes = { grid = [0, 0], spacing = 5 }\nmavlink = \"udp:127.0.0.1:14550\"\n";
    let (msg, at) = problem(text);
    assert!(msg.starts_with("fleet `f` has 256 drones on one `mavlink` address"), "{msg}");
    assert_eq!(at, "256");
    let w = ok(&text.replace("256", "255"));
    assert!(w.drones.iter().all(|d| matches!(d.backend, crate::Backend::Mavlink(_))));
}

#[test]
fn drone_keys_in_a_fleet_are_checked_once_for_the_fleet() {
    let all = problems("[fleets.f]\ncount = 1000\nhomes = { grid = [0, 0], spacing = 5 }\nsensors = [\"thermel\"]\nmax_speed = -1\nspeed = 3\n");
    let messages: Vec<&str> = all.iter().map(|(m, _)| m.as_str()).collect();
    assert_eq!(
        messages,
        [
            "fleet `f` has sensor `thermel`, but no `[sensors.thermel]` defines it",
            "`max_speed` of fleet `f` must be greater than zero, found -1",
            "attribute `speed` of fleet `f` has the name of a telemetry field, so `.speed` of its drones could not read it",
        ]
    );
}

#[test]
fn every_drone_has_a_name_of_its_own() {
    let text = "[fleets.a]\ncount = 3\nnames = \"x{i}\"\nhomes = { grid = [0, 0], spacing = 5 }\n\
                [fleets.b]\ncount = 4\nnames = \"x{i}\"\nfirst = 1\nhomes = { grid = [0, 50], spacing = 5 }\n\
                [drones.x0]\nhome = [0, 90]\n";
    let all = problems(text);
    assert_eq!(
        all,
        [
            (
                "the name `x1` is used for two drones: a drone of fleet `a` and a drone of fleet `b` (1 more of its drones has a name taken as well)".to_string(),
                "b".to_string()
            ),
            (
                "the name `x0` is used for two drones: a drone of fleet `a` and `[drones.x0]`".into(),
                "x0".into()
            ),
        ]
    );
    // Names shared with a place, a group or an area are one name for two things.
    let (msg, _) = problem(
        "[places]\nf1 = [0, 0]\n[fleets.f]\ncount = 2\nhomes = { grid = [0, 0], spacing = 5 }\n",
    );
    assert_eq!(msg, "the name `f1` is used for a place and for a drone, so mission code could not tell which is meant");
}

#[test]
fn homes_outside_the_geofence_are_one_error_per_fleet() {
    let text = "[site]\ngeofence = [[0, 0], [100, 0], [100, 100], [0, 100]]\n\
                [fleets.f]\ncount = 9\nhomes = { grid = [50, 50], spacing = 30 }\n\
                [fleets.g]\ncount = 2\nhomes = { grid = [90, 0], spacing = 20 }\n";
    assert_eq!(
        problems(text),
        [
            (
                "5 drones of fleet `f` have their homes outside the geofence, the first `f2` at (110, 50)".to_string(),
                "{ grid = [50, 50], spacing = 30 }".to_string()
            ),
            (
                "drone `g1` of fleet `g` has its home (110, 0) outside the geofence".into(),
                "{ grid = [90, 0], spacing = 20 }".into()
            ),
        ]
    );
}

#[test]
fn areas_of_a_fleet() {
    let fleet = |areas: &str| {
        format!(
            "[fleets.f]\ncount = 2\nhomes = {{ grid = [0, 0], spacing = 5 }}\nareas = {areas}\n"
        )
    };
    assert_eq!(problem(&fleet("{ names = \"A{i}\" }")).0, "`areas` of fleet `f` has no `polygon`");
    assert_eq!(
        problem(&fleet("{ polygon = [[0, 0], [1, 0], [0, 1]] }")).0,
        "`areas` of fleet `f` has no `names`"
    );
    assert_eq!(
        problem(&fleet("{ names = \"A\", polygon = [[0, 0], [1, 0], [0, 1]] }")).0,
        "`names` of `areas` of fleet `f` (`A`) has no `{i}`, so every name would be the same"
    );
    assert_eq!(
        problem(&fleet("{ names = \"A{i}\", polygon = [[0, 0], [1, 0], [2, 0]] }")).0,
        "`polygon` of `areas` of fleet `f` encloses no area: its corners lie on one line"
    );
    assert_eq!(
        problem(
            "[fleets.f]\ncount = 2\nhomes = { grid = [1e308, 0], spacing = 5 }\n\
             areas = { names = \"A{i}\", polygon = [[0, 0], [1e308, 0], [1e308, 1e308]] }\n"
        )
        .0,
        "the areas of fleet `f` reach beyond the numbers a world can hold"
    );
    let clashes = problems(&fleet("{ names = \"f{i}\", polygon = [[0, 0], [1, 0], [0, 1]] }"));
    assert_eq!(
        clashes[0].0,
        "the name `f0` is used for a drone and for an area, so mission code could not tell which is meant"
    );
    assert_eq!(clashes.len(), 2);
}

#[test]
fn fleets_must_be_tables() {
    assert_eq!(problem("fleets = 3\n").0, "`fleets` must be a table, found an integer");
    assert_eq!(problem("[fleets]\nf = 3\n").0, "fleet `f` must be a table, found an integer");
}

/// A world written with a fleet is the world written with a table per drone.
#[test]
fn a_fleet_is_the_tables_it_stands_for() {
    let mut tables = String::from("[site]\nname = \"W\"\n");
    for i in 0..50 {
        tables.push_str(&format!(
            "\n[drones.a{i}]\nhome = [{}, {}]\ngroup = \"fleet\"\nindex = {i}\nsensors = [\"thermal\"]\n",
            (i % 8) * 5,
            (i / 8) * 5
        ));
    }
    let fleet = "[site]\nname = \"W\"\n[fleets.a]\ncount = 50\ngroup = \"fleet\"\nhomes = { grid = [0, 0], spacing = 5, columns = 8 }\nsensors = [\"thermal\"]\n";
    let (mut one, mut other) =
        (ok(&format!("{tables}{SENSORS}")), ok(&format!("{fleet}{SENSORS}")));
    for d in one.drones.iter_mut().chain(other.drones.iter_mut()) {
        d.span = Default::default();
    }
    for s in one.sensors.iter_mut().chain(other.sensors.iter_mut()) {
        s.span = Default::default();
    }
    // The fleet's one `group` string names all fifty; the tables, one each.
    assert_eq!((one.groups[0].spans.len(), other.groups[0].spans.len()), (50, 1));
    for g in one.groups.iter_mut().chain(other.groups.iter_mut()) {
        g.spans.clear();
    }
    assert_eq!(one, other);
}

/// Random edits of a world with a fleet: never a panic, every span in the text, a world
/// exactly when there is no diagnostic.
#[test]
fn random_edits_of_a_fleet_never_panic() {
    let base = include_str!("../tests/fixtures/fleet_grid.world.toml");
    let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed
    };
    let alphabet: Vec<char> = "[]{}=,.\"#\n 0123456789-e_aiz:".chars().collect();
    for _ in 0..1500 {
        let mut chars: Vec<char> = base.chars().collect();
        for _ in 0..(next() % 4 + 1) {
            let at = (next() % chars.len() as u64) as usize;
            let c = alphabet[(next() % alphabet.len() as u64) as usize];
            match next() % 3 {
                0 => {
                    chars.remove(at);
                }
                1 => chars.insert(at, c),
                _ => chars[at] = c,
            }
        }
        let text: String = chars.into_iter().collect();
        let (world, diags) = parse_world(FileId(0), &text);
        assert_eq!(world.is_some(), diags.is_empty(), "{text}");
        for d in &diags {
            assert!(text.get(d.primary.span.range()).is_some(), "{text}: {d:?}");
        }
    }
}
