//! A world's `[imports]` as a user meets them: GeoJSON beside the world file, read by
//! `aviary check` and `aviary run` alike, placed through the site's origin, and refused
//! outside the world's folder with the place in the world file that names it.

mod common;

use common::{aviary, repo, scratch};

const FIXTURES: &str = "crates/aviary-world/tests/fixtures/imports";

const WORLD: &str = "[site]
origin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }

[imports]
features = \"farm.geojson\"
no_fly = \"airspace.geojson\"

[drones.d1]
home = [0, 0]
";

const MISSION: &str = "MISSION Farm:
    d1 TakeOff WITH 20m
    d1 FlyTo WITH Barn
    d1 FollowPath WITH Ditch
    d1 FlyTo WITH North_Field
    d1 ReturnHome
";

/// A folder with the world, its GeoJSON files (the fixtures'), and the mission.
fn farm(name: &str) -> std::path::PathBuf {
    let dir = scratch(name);
    for file in ["farm.geojson", "airspace.geojson"] {
        std::fs::copy(repo().join(FIXTURES).join(file), dir.join(file)).unwrap();
    }
    std::fs::write(dir.join("m.world.toml"), WORLD).unwrap();
    std::fs::write(dir.join("m.mission"), MISSION).unwrap();
    dir
}

#[test]
fn places_lines_and_areas_of_a_geojson_file_are_flown() {
    let dir = farm("imports_flown");
    let (code, out, err) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 0, "{out}{err}");
    let (code, out, err) = aviary(&["run", "m.mission", "--trace", "t.jsonl"], &dir);
    assert_eq!(code, 0, "{out}{err}");
    let trace = std::fs::read_to_string(dir.join("t.jsonl")).unwrap();
    assert!(trace.contains("\"FollowPath\""), "the line was flown: {trace:.400}");
}

#[test]
fn a_world_read_from_another_folder_reads_its_imports_beside_it() {
    let dir = farm("imports_elsewhere");
    std::fs::create_dir_all(dir.join("missions")).unwrap();
    std::fs::rename(dir.join("m.mission"), dir.join("missions/m.mission")).unwrap();
    let (code, out, err) =
        aviary(&["check", "missions/m.mission", "--world", "m.world.toml"], &dir);
    assert_eq!(code, 0, "{out}{err}");
}

#[test]
fn an_import_missing_or_outside_the_worlds_folder_is_an_error_where_it_is_named() {
    let dir = farm("imports_refused");
    std::fs::write(dir.join("m.world.toml"), WORLD.replace("farm.geojson", "gone.geojson"))
        .unwrap();
    let (code, out, _) = aviary(&["check", "m.mission"], &dir);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.starts_with("m.world.toml:5:12: error[E119]: cannot read `gone.geojson`: there is no file gone.geojson"),
        "{out}"
    );
    std::fs::create_dir_all(dir.join("inner")).unwrap();
    std::fs::rename(dir.join("m.world.toml"), dir.join("inner/m.world.toml")).unwrap();
    std::fs::write(
        dir.join("inner/m.world.toml"),
        WORLD.replace("farm.geojson", "../farm.geojson"),
    )
    .unwrap();
    let (code, out, _) = aviary(&["check", "m.mission", "--world", "inner/m.world.toml"], &dir);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("inner/m.world.toml:5:12: error[E119]: cannot read `../farm.geojson`"),
        "{out}"
    );
    assert!(out.contains("is outside the world file's folder"), "{out}");
}
