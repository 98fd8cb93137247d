//! The page and everything it loads, embedded in the binary: a fresh machine needs
//! nothing but `aviary`, and no page loads anything from the internet. The files live in
//! `web/`; third-party code in `web/vendor/`, pinned from the npm registry with its
//! licence (`crates/aviary-station/web/vendor/README.md`).

use std::sync::LazyLock;

/// One file of the page.
pub struct Asset {
    /// Its path under `web/`, as the page asks for it under `/assets/`.
    pub path: &'static str,
    pub bytes: &'static [u8],
    pub mime: &'static str,
}

macro_rules! asset {
    ($path:literal, $mime:literal) => {
        Asset {
            path: $path,
            bytes: include_bytes!(concat!(env!("CARGO_MANIFEST_DIR"), "/web/", $path)),
            mime: $mime,
        }
    };
}

/// Every file the page may load. `index.html` is also the page at `/`.
pub const ASSETS: &[Asset] = &[
    asset!("index.html", "text/html; charset=utf-8"),
    asset!("station.css", "text/css; charset=utf-8"),
    asset!("js/main.js", "text/javascript; charset=utf-8"),
    asset!("js/api.js", "text/javascript; charset=utf-8"),
    asset!("js/model.js", "text/javascript; charset=utf-8"),
    asset!("js/map.js", "text/javascript; charset=utf-8"),
    asset!("js/fleet.js", "text/javascript; charset=utf-8"),
    asset!("js/tree.js", "text/javascript; charset=utf-8"),
    asset!("js/log.js", "text/javascript; charset=utf-8"),
    asset!("js/editor.js", "text/javascript; charset=utf-8"),
    asset!("js/lsp.js", "text/javascript; charset=utf-8"),
    asset!("js/replay.js", "text/javascript; charset=utf-8"),
    asset!("vendor/codemirror/codemirror.bundle.js", "text/javascript; charset=utf-8"),
    asset!("vendor/codemirror/LICENSES.md", "text/plain; charset=utf-8"),
    asset!("vendor/leaflet-1.9.4/leaflet.js", "text/javascript; charset=utf-8"),
    asset!("vendor/leaflet-1.9.4/leaflet.css", "text/css; charset=utf-8"),
    asset!("vendor/leaflet-1.9.4/LICENSE", "text/plain; charset=utf-8"),
    asset!("vendor/leaflet-1.9.4/images/layers.png", "image/png"),
    asset!("vendor/leaflet-1.9.4/images/layers-2x.png", "image/png"),
    asset!("vendor/leaflet-1.9.4/images/marker-icon.png", "image/png"),
    asset!("vendor/leaflet-1.9.4/images/marker-icon-2x.png", "image/png"),
    asset!("vendor/leaflet-1.9.4/images/marker-shadow.png", "image/png"),
];

/// The files the station writes from the language's own data when it starts, so that the
/// page keeps no copy of it: `js/builtins.js`, the built-in exceptions that are drone
/// faults ([`aviary_api::BuiltinException::is_drone_fault`]).
static GENERATED: LazyLock<[Asset; 1]> = LazyLock::new(|| {
    [Asset {
        path: "js/builtins.js",
        bytes: BUILTINS_JS.as_bytes(),
        mime: "text/javascript; charset=utf-8",
    }]
});

static BUILTINS_JS: LazyLock<String> = LazyLock::new(builtins_js);

fn builtins_js() -> String {
    let faults: Vec<&str> = aviary_api::BuiltinException::ALL
        .into_iter()
        .filter(|e| e.is_drone_fault())
        .map(|e| e.name())
        .collect();
    let faults = serde_json::to_string(&faults).unwrap_or_else(|_| "[]".into());
    format!(
        "// Written by the station from the language's built-in exceptions \
         (aviary_api::BuiltinException): not a file of web/.\n\
         /** The exceptions that are faults of a drone: an alarm even when handled. */\n\
         export const DRONE_FAULTS = new Set({faults});\n"
    )
}

/// The asset at `path` (under `/assets/`), if the page has one.
pub fn find(path: &str) -> Option<&'static Asset> {
    ASSETS.iter().chain(GENERATED.iter()).find(|a| a.path == path)
}

#[cfg(test)]
mod tests {
    use super::*;

    const JS: &str = "text/javascript; charset=utf-8";
    const CSS: &str = "text/css; charset=utf-8";
    const PNG: &str = "image/png";

    #[test]
    fn the_drone_faults_are_the_languages() {
        let js = std::str::from_utf8(find("js/builtins.js").unwrap().bytes).unwrap();
        assert!(js.contains(r#"export const DRONE_FAULTS = new Set(["BatteryCritical","ConnectionLost","DroneLost","MotorFailure","PositionLost","GeofenceViolation"]);"#), "{js}");
    }

    #[test]
    fn every_asset_has_the_type_of_its_extension() {
        for a in ASSETS.iter().chain(GENERATED.iter()) {
            let want = match a.path.rsplit('.').next() {
                Some("js") => JS,
                Some("css") => CSS,
                Some("png") => PNG,
                Some("html") => "text/html; charset=utf-8",
                _ => "text/plain; charset=utf-8",
            };
            assert_eq!(a.mime, want, "{}", a.path);
            assert!(!a.bytes.is_empty(), "{} is empty", a.path);
        }
    }
}
