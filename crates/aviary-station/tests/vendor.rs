//! The vendored browser code is what `web/vendor/SHA256SUMS` says it is: a file changed
//! by hand, or a copy from another version, is noticed. Leaflet is copied from its
//! package; CodeMirror is bundled from its packages (`web/vendor/codemirror/`), its
//! inputs (the pinned manifest, the lockfile, the entry) listed beside the bundle.

use sha2::{Digest, Sha256};
use std::path::Path;

#[test]
fn vendored_files_match_their_recorded_digests() {
    let vendor = Path::new(env!("CARGO_MANIFEST_DIR")).join("web/vendor");
    let sums = std::fs::read_to_string(vendor.join("SHA256SUMS")).expect("SHA256SUMS");
    let mut checked = Vec::new();
    for line in sums.lines().filter(|l| !l.trim().is_empty()) {
        let (digest, name) = line.split_once("  ").expect("`DIGEST  NAME`");
        let bytes = std::fs::read(vendor.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let actual: String = Sha256::digest(&bytes).iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(actual, digest, "{name} is not the file recorded");
        checked.push(name.to_string());
    }
    assert_eq!(checked.iter().filter(|n| n.starts_with("leaflet-1.9.4/")).count(), 8);
    for file in
        ["codemirror.bundle.js", "LICENSES.md", "package.json", "package-lock.json", "entry.js"]
    {
        let name = format!("codemirror/{file}");
        assert!(checked.contains(&name), "{name} is listed");
    }
    let licence = std::fs::read_to_string(vendor.join("leaflet-1.9.4/LICENSE")).expect("LICENSE");
    assert!(licence.contains("BSD 2-Clause"), "Leaflet comes with its licence");
}

#[test]
fn codemirror_comes_with_the_licence_of_every_package_it_is_bundled_from() {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("web/vendor/codemirror");
    let lock: serde_json::Value =
        serde_json::from_slice(&std::fs::read(folder.join("package-lock.json")).unwrap()).unwrap();
    let licences = std::fs::read_to_string(folder.join("LICENSES.md")).expect("LICENSES.md");
    let packages = lock["packages"].as_object().expect("a lockfile of npm 7 or later");
    let mut bundled = 0;
    for (path, p) in packages {
        if path.is_empty() || p["dev"] == true {
            continue;
        }
        let name = path.rsplit_once("node_modules/").map_or(path.as_str(), |(_, n)| n);
        let version = p["version"].as_str().unwrap();
        let integrity = p["integrity"].as_str().unwrap();
        let row = format!("| {name} | {version} | MIT | {integrity} |");
        assert!(licences.contains(&row), "LICENSES.md lists {name} {version}");
        assert!(licences.contains(&format!("## {name} {version}\n")), "the licence of {name}");
        bundled += 1;
    }
    assert!(licences.matches("Permission is hereby granted").count() >= bundled);
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(folder.join("package.json")).unwrap()).unwrap();
    for deps in ["dependencies", "devDependencies"] {
        for (name, version) in manifest[deps].as_object().unwrap() {
            let v = version.as_str().unwrap();
            assert!(v.chars().all(|c| c.is_ascii_digit() || c == '.'), "{name} is pinned: {v}");
        }
    }
}
