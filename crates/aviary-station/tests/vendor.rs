//! The vendored browser code is what `web/vendor/SHA256SUMS` says it is: a file changed
//! by hand, or a copy from another version, is noticed.

use sha2::{Digest, Sha256};
use std::path::Path;

#[test]
fn vendored_files_match_their_recorded_digests() {
    let vendor = Path::new(env!("CARGO_MANIFEST_DIR")).join("web/vendor");
    let sums = std::fs::read_to_string(vendor.join("SHA256SUMS")).expect("SHA256SUMS");
    let mut checked = 0;
    for line in sums.lines().filter(|l| !l.trim().is_empty()) {
        let (digest, name) = line.split_once("  ").expect("`DIGEST  NAME`");
        let bytes = std::fs::read(vendor.join("leaflet-1.9.4").join(name))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let actual: String = Sha256::digest(&bytes).iter().map(|b| format!("{b:02x}")).collect();
        assert_eq!(actual, digest, "{name} is not the file recorded");
        checked += 1;
    }
    assert_eq!(checked, 8, "every vendored file is listed");
    let licence = std::fs::read_to_string(vendor.join("leaflet-1.9.4/LICENSE")).expect("LICENSE");
    assert!(licence.contains("BSD 2-Clause"), "Leaflet comes with its licence");
}
