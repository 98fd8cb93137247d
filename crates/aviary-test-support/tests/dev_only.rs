//! The support crate stays where it belongs: no crate of the workspace, nor the fuzz
//! targets, has it among its `[dependencies]` (a dev-dependency only), and the engine's
//! own dependencies stay free of the front end that the harness brings to its tests; the
//! engine's `testing` feature comes in through this crate alone.

use std::path::Path;

fn manifests() -> Vec<(String, toml::Table)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut paths: Vec<_> = std::fs::read_dir(root.join("crates"))
        .expect("crates/")
        .map(|e| e.expect("an entry").path().join("Cargo.toml"))
        .filter(|p| p.is_file())
        .collect();
    paths.push(root.join("fuzz/Cargo.toml"));
    paths.sort();
    paths
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("a manifest");
            let table: toml::Table = text.parse().unwrap_or_else(|e| panic!("{p:?}: {e}"));
            (p.display().to_string(), table)
        })
        .collect()
}

fn dependencies(manifest: &toml::Table) -> Vec<&str> {
    let mut names: Vec<&str> = Vec::new();
    if let Some(deps) = manifest.get("dependencies").and_then(|d| d.as_table()) {
        names.extend(deps.keys().map(String::as_str));
    }
    // Target-specific tables count too: `[target.'cfg(..)'.dependencies]`.
    if let Some(targets) = manifest.get("target").and_then(|t| t.as_table()) {
        for target in targets.values() {
            if let Some(deps) = target.get("dependencies").and_then(|d| d.as_table()) {
                names.extend(deps.keys().map(String::as_str));
            }
        }
    }
    names
}

#[test]
fn no_crate_depends_on_the_test_support_but_for_its_tests() {
    let all = manifests();
    assert!(all.len() > 10, "only {} manifests", all.len());
    for (path, manifest) in &all {
        assert!(
            !dependencies(manifest).contains(&"aviary-test-support"),
            "{path}: aviary-test-support may only be a dev-dependency"
        );
    }
}

#[test]
fn the_engine_depends_on_no_part_of_the_front_end() {
    let all = manifests();
    let (_, engine) = all
        .iter()
        .find(|(_, m)| m["package"]["name"].as_str() == Some("aviary-engine"))
        .expect("the engine's manifest");
    let deps = dependencies(engine);
    assert!(deps.contains(&"aviary-ir"), "the engine's dependencies, as read: {deps:?}");
    for front in ["aviary-syntax", "aviary-check", "aviary-lower"] {
        assert!(!deps.contains(&front), "the engine depends on {front}");
    }
}

/// The engine's `testing` feature (its general path on its own) comes in only through this
/// crate: a crate that ships never turns it on.
#[test]
fn only_the_test_support_turns_on_the_engines_testing_feature() {
    for (path, manifest) in &manifests() {
        if manifest["package"]["name"].as_str() == Some("aviary-test-support") {
            continue;
        }
        for table in ["dependencies", "dev-dependencies", "build-dependencies"] {
            let Some(engine) = manifest.get(table).and_then(|d| d.get("aviary-engine")) else {
                continue;
            };
            let features = engine.get("features").and_then(|f| f.as_array());
            assert!(
                !features.is_some_and(|f| f.iter().any(|f| f.as_str() == Some("testing"))),
                "{path}: [{table}] turns on aviary-engine's `testing` feature"
            );
        }
    }
}
