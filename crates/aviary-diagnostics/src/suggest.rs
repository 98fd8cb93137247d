//! "Did you mean" suggestions: one rule for every message that offers a name, the
//! checker's and the engine's refusals of an operator's control alike.

/// The candidate closest to `name`, if one is close enough to be a likely typo.
pub fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let lower = name.to_ascii_lowercase();
    let limit = (name.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .filter(|c| *c != name)
        .map(|c| (strsim::damerau_levenshtein(&lower, &c.to_ascii_lowercase()), c))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, c)| (d, c.len(), c.to_string()))
        .map(|(_, c)| c)
}

/// `did you mean `X`?`, or `None`.
pub fn did_you_mean<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<String> {
    closest(name, candidates).map(|c| format!("did you mean `{c}`?"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_close_names_only() {
        assert_eq!(closest("Hoem", ["Home", "Base"]), Some("Home"));
        assert_eq!(closest("flir_drone", ["flir_drone1", "video_drone1"]), Some("flir_drone1"));
        assert_eq!(closest("BuildingZ", ["BuildingA", "BuildingB"]), Some("BuildingA"));
        assert_eq!(closest("Xyz", ["Home", "Base"]), None);
        assert_eq!(closest("takeoff", ["TakeOff", "Land"]), Some("TakeOff"));
        let fleet = ["scout1", "scout2", "carrier"];
        assert_eq!(closest("scuot1", fleet), Some("scout1"));
        assert_eq!(closest("Carrier", fleet), Some("carrier"));
        assert_eq!(closest("tower", fleet), None);
    }
}
