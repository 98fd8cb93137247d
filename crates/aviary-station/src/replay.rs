//! A recorded trace for `aviary replay`: read whole and checked line by line before the
//! station serves it, so that the page gets only events it can play. A line that is not
//! an event is reported with its place (`path:line:col`), the line and a caret, and the
//! replay does not start.

use aviary_api::trace::Record;

/// The trace's text when every line is an event, or why not.
pub fn read(name: &str, bytes: Vec<u8>) -> Result<String, String> {
    let text = text(name, bytes)?;
    records(name, &text, |_| {})?;
    Ok(text)
}

/// The world a trace names in its `mission_start` (its first event), if it names one.
pub fn world_stamp(bytes: &[u8]) -> Option<aviary_api::trace::WorldStamp<'static>> {
    let first = bytes.split(|&b| b == b'\n').find(|l| !l.iter().all(u8::is_ascii_whitespace))?;
    match serde_json::from_slice::<Record>(first).ok()?.event {
        aviary_api::trace::Event::MissionStart { world: Some(w), .. } => {
            Some(aviary_api::trace::WorldStamp {
                file: w.file.into_owned().into(),
                sha256: w.sha256.into_owned().into(),
            })
        }
        _ => None,
    }
}

/// The bytes of a trace as text, or why they are none.
pub fn text(name: &str, bytes: Vec<u8>) -> Result<String, String> {
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        format!("{name}: byte {at} is not UTF-8: a trace is JSON Lines, as `aviary run --trace` writes it")
    })
}

/// Reads each line of `text` as an event and hands it to `each`; the number of events,
/// or why a line is none (its place, the line and a caret) or there is none at all.
pub fn records(name: &str, text: &str, mut each: impl FnMut(Record)) -> Result<usize, String> {
    let mut events = 0usize;
    for (index, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        match serde_json::from_str::<Record>(line) {
            Ok(record) => each(record),
            Err(e) => {
                let column = e.column().max(1);
                let shown: String = line.chars().take(160).collect();
                let caret = " ".repeat(column.saturating_sub(1).min(160));
                return Err(format!(
                    "{name}:{}:{column}: this line is not a trace event: {e}\n  | {shown}\n  | {caret}^\n  = help: a trace is what `aviary run --trace FILE` writes, one event a line (docs/TRACE.md)",
                    index + 1
                ));
            }
        }
        events += 1;
    }
    if events == 0 {
        return Err(format!("{name}: the trace holds no event"));
    }
    Ok(events)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_trace_reads_and_a_bad_line_is_shown_with_its_place() {
        let good = "{\"t\":0.0,\"event\":\"mission_start\",\"mission\":\"M\"}\n";
        assert_eq!(read("t.jsonl", good.as_bytes().to_vec()).unwrap(), good);
        let bad = format!("{good}{{\"t\":1.0,\"event\":\"nonsense\"}}\n");
        let why = read("t.jsonl", bad.into_bytes()).unwrap_err();
        assert!(why.starts_with("t.jsonl:2:"), "{why}");
        assert!(why.contains('^'), "{why}");
        assert!(read("t.jsonl", vec![0xff, 0xfe]).unwrap_err().contains("UTF-8"));
        assert!(read("t.jsonl", b"\n\n".to_vec()).unwrap_err().contains("no event"));
    }
}
