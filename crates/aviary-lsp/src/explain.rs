//! A diagnostic code's explanation: its section of docs/DIAGNOSTICS.md (a `## CODE —
//! title` heading for every code, which aviary-check's tests keep in step), compiled in.

const REFERENCE: &str = include_str!("../../../docs/DIAGNOSTICS.md");

/// The section of `code` without its heading line, trimmed; `None` for a code the
/// reference does not describe.
pub fn section(code: &str) -> Option<(&'static str, &'static str)> {
    let heading = format!("\n## {code} ");
    let start = REFERENCE.find(&heading)? + 1;
    let rest = &REFERENCE[start..];
    let title_end = rest.find('\n').unwrap_or(rest.len());
    let title = rest[..title_end].trim_start_matches('#').trim();
    let body = &rest[title_end..];
    let end = body.find("\n## ").unwrap_or(body.len());
    Some((title, body[..end].trim()))
}

/// Markdown for hovering a diagnostic of `code`.
pub fn markdown(code: aviary_diagnostics::Code) -> String {
    let mut out =
        format!("**{}** ({}): {}", code.as_str(), code.severity().as_str(), code.summary());
    if let Some((title, body)) = section(code.as_str()) {
        out.push_str(&format!("\n\n### {title}\n\n{body}"));
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_code_has_its_section() {
        for id in ["E001", "E101", "E107", "W203", "N303"] {
            let (title, body) = super::section(id).unwrap_or_else(|| panic!("{id}"));
            assert!(title.starts_with(id), "{title}");
            assert!(!body.is_empty() && !body.contains("\n## "), "{id}");
        }
        assert_eq!(super::section("E999"), None);
    }
}
