//! A world's base map (`[site] tiles`, docs/WORLD.md) and what the page may load for it:
//! the page's Content-Security-Policy lets images come from the station itself and from
//! the tile servers of the worlds it may show, nowhere else.

use crate::{Mode, Station};

/// The image sources of the page: its own files, and each tile server a world of the
/// station names (in a folder, every world in it, as the page is loaded: a world given
/// tiles later is shown with them after the page is reloaded).
pub(crate) fn image_sources(station: &Station) -> Vec<String> {
    let mut urls: Vec<String> = Vec::new();
    if let Some(url) = station.map()["site"]["tiles"].as_str() {
        urls.push(url.to_owned());
    }
    if let Mode::Folder { folder, files } = &station.mode {
        for world in folder.list().worlds {
            let Ok(text) = folder.read(&world) else { continue };
            // With its `[imports]`, read beside it, as for a flight.
            let full = folder.root().join(&world);
            let Ok(provider) = files(&full) else { continue };
            let read = aviary_check::read_world(
                &mut aviary_diagnostics::SourceMap::new(),
                &full.display().to_string(),
                std::borrow::Cow::Owned(text.into_bytes()),
                &*provider,
            );
            urls.extend(read.world.and_then(|w| w.site.tiles));
        }
    }
    let mut sources: Vec<String> = urls.iter().filter_map(|u| source(u)).collect();
    sources.sort();
    sources.dedup();
    sources
}

/// The CSP source a tile address needs: its scheme and host (and port), with a
/// subdomain placeholder `{s}` as `*`. `None` for what a CSP source cannot say.
pub(crate) fn source(url: &str) -> Option<String> {
    let (scheme, rest) = url.split_once("://")?;
    if scheme != "http" && scheme != "https" {
        return None;
    }
    let host = rest.split('/').next()?.replace("{s}", "*");
    let allowed =
        |c: char| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | ':' | '*' | '[' | ']');
    if host.is_empty() || !host.chars().all(allowed) {
        return None;
    }
    Some(format!("{scheme}://{host}"))
}

/// The page's Content-Security-Policy with `images` as its extra image sources.
pub(crate) fn policy(images: &[String]) -> String {
    let mut img = String::from("'self' data:");
    for s in images {
        img.push(' ');
        img.push_str(s);
    }
    format!(
        "default-src 'self'; img-src {img}; style-src 'self' 'unsafe-inline'; connect-src 'self'; frame-ancestors 'none'"
    )
}

/// What the page needs to draw a world over its tiles: the address and attribution, and
/// the local frame's place on Earth as degrees per metre about the origin (the one
/// projection, `aviary_api::geo::Origin`, is linear: the page applies these, it does not
/// project again). `Null` for a world without tiles or origin.
pub fn base_map(world: &aviary_world::World) -> Option<BaseMap> {
    let (Some(url), Some(o)) = (&world.site.tiles, &world.site.origin) else {
        return None;
    };
    let origin = aviary_api::geo::Origin { lat: o.lat, lon: o.lon, alt: o.alt };
    let (lat_per_m, lon_per_m) = origin.degrees_per_metre();
    Some(BaseMap {
        url: url.clone(),
        attribution: world.site.tiles_attribution.clone(),
        lat: o.lat,
        lon: o.lon,
        lat_per_m,
        lon_per_m,
    })
}

/// The tiles under the map, and how the local frame lies on them: the origin and how
/// many degrees a metre north and a metre east are there.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BaseMap {
    pub url: String,
    pub attribution: Option<String>,
    pub lat: f64,
    pub lon: f64,
    pub lat_per_m: f64,
    pub lon_per_m: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tile_address_gives_its_scheme_and_host() {
        assert_eq!(
            source("https://tile.openstreetmap.org/{z}/{x}/{y}.png").as_deref(),
            Some("https://tile.openstreetmap.org")
        );
        assert_eq!(
            source("https://{s}.tile.example.org/{z}/{x}/{y}.png").as_deref(),
            Some("https://*.tile.example.org")
        );
        assert_eq!(
            source("http://127.0.0.1:8080/tiles/{z}/{x}/{y}.png").as_deref(),
            Some("http://127.0.0.1:8080")
        );
        assert_eq!(source("javascript:alert(1)//{z}{x}{y}"), None);
        assert_eq!(source("https://a b/{z}/{x}/{y}"), None);
        assert_eq!(source("https://evil.org;script-src *"), None);
    }

    #[test]
    fn the_policy_adds_only_the_tile_servers_to_images() {
        let p = policy(&["https://tile.openstreetmap.org".into()]);
        assert!(p.contains("img-src 'self' data: https://tile.openstreetmap.org;"), "{p}");
        assert!(p.starts_with("default-src 'self';") && p.contains("connect-src 'self'"), "{p}");
    }

    #[test]
    fn the_base_map_places_the_local_frame_by_the_one_projection() {
        let text = "[site]\norigin = { lat = 46.6167, lon = 14.2650, alt = 440.0 }\ntiles = \"https://t.example/{z}/{x}/{y}.png\"\n";
        let (world, diags) = aviary_world::parse_world(aviary_diagnostics::FileId(0), text);
        assert!(diags.is_empty(), "{diags:?}");
        let map = base_map(&world.unwrap()).unwrap();
        let origin = aviary_api::geo::Origin { lat: 46.6167, lon: 14.2650, alt: 440.0 };
        let (lat, lon) = origin.to_geodetic(350.0, -450.0);
        // Within 1e-10 degrees, about a hundredth of a millimetre.
        assert!((map.lat + -450.0 * map.lat_per_m - lat).abs() < 1e-10);
        assert!((map.lon + 350.0 * map.lon_per_m - lon).abs() < 1e-10);
    }
}
