//! The page and everything it loads, embedded in the binary: a fresh machine needs
//! nothing but `aviary`, and no page loads anything from the internet. The files live in
//! `web/`; third-party code in `web/vendor/`, pinned from the npm registry with its
//! licence (`crates/aviary-station/web/vendor/README.md`).

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

/// The asset at `path` (under `/assets/`), if the page has one.
pub fn find(path: &str) -> Option<&'static Asset> {
    ASSETS.iter().find(|a| a.path == path)
}

#[cfg(test)]
mod tests {
    use super::*;

    const JS: &str = "text/javascript; charset=utf-8";
    const CSS: &str = "text/css; charset=utf-8";
    const PNG: &str = "image/png";

    #[test]
    fn every_asset_has_the_type_of_its_extension() {
        for a in ASSETS {
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
