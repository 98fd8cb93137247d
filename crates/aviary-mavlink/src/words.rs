//! The autopilot's words (STATUSTEXT), whole. One message holds at most 50 bytes of
//! text; PX4 cuts a longer text (up to 127 bytes) into chunks that share an `id` and are
//! numbered by `chunk_seq` from 0, the last one ending before the field does
//! (MAVLink's common.xml; PX4's `mavlink/streams/STATUSTEXT.hpp`). ArduPilot sends `id` 0,
//! a text in one message. PX4 ends a text with a tab when the same words also go out as
//! an event: the tab is no part of them.

use aviary_clock::Instant;
use std::collections::VecDeque;

/// How many texts are kept: enough for the reasons around one refusal or failsafe.
const KEPT: usize = 16;
/// The most one text may grow to, whatever a vehicle sends as chunks of it (PX4's
/// longest is 127 bytes).
const LONGEST: usize = 1024;
/// Put where chunks of a text were lost.
const LOST: &[u8] = b"[...]";

/// Recent texts, newest last, chunks joined.
#[derive(Default)]
pub struct Words {
    texts: VecDeque<Text>,
}

struct Text {
    at: Instant,
    bytes: Vec<u8>,
    /// While the text goes on: its id and the chunk expected next.
    open: Option<(u16, u8)>,
}

impl Words {
    /// Takes one STATUSTEXT: its `id`, `chunk_seq` and text field.
    pub fn take(&mut self, now: Instant, id: u16, chunk: u8, field: &[u8]) {
        let len = field.iter().position(|&b| b == 0).unwrap_or(field.len());
        let ends = len < field.len();
        let part = &field[..len];
        let next = |id: u16| (id != 0 && !ends).then(|| (id, chunk.wrapping_add(1)));
        if let Some(text) = self.texts.back_mut().filter(|t| t.open.is_some_and(|o| o.0 == id)) {
            if chunk > 0 {
                if text.open.map(|o| o.1) != Some(chunk) {
                    text.bytes.extend_from_slice(LOST);
                }
                text.bytes.extend_from_slice(part);
                text.bytes.truncate(LONGEST);
                text.open = next(id);
                return;
            }
        }
        let mut bytes = Vec::with_capacity(part.len());
        if id != 0 && chunk > 0 {
            // Its beginning was lost.
            bytes.extend_from_slice(LOST);
        }
        bytes.extend_from_slice(part);
        self.texts.push_back(Text { at: now, bytes, open: next(id) });
        while self.texts.len() > KEPT {
            self.texts.pop_front();
        }
    }

    /// The texts whose first chunk came at or after `since`, oldest first.
    pub fn since(&self, since: Instant) -> Vec<String> {
        self.texts.iter().filter(|t| t.at >= since).map(Text::words).collect()
    }

    /// The newest text.
    pub fn last(&self) -> Option<String> {
        self.texts.back().map(Text::words)
    }
}

impl Text {
    /// What it says: bytes that are no UTF-8 (a vehicle's, or a character cut between
    /// chunks that never came) are shown as `�`.
    fn words(&self) -> String {
        String::from_utf8_lossy(&self.bytes).trim_end().to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::Words;
    use aviary_clock::Instant;
    use std::time::Duration;

    /// The 50-byte field as a vehicle sends it.
    fn field(text: &str) -> [u8; 50] {
        let mut f = [0u8; 50];
        f[..text.len()].copy_from_slice(text.as_bytes());
        f
    }

    /// PX4's chunks of `text` under `id`, as `STATUSTEXT.hpp` cuts them.
    fn chunks(id: u16, text: &str) -> Vec<(u16, u8, [u8; 50])> {
        text.as_bytes()
            .chunks(50)
            .enumerate()
            .map(|(i, c)| (id, i as u8, field(std::str::from_utf8(c).unwrap())))
            .collect()
    }

    #[test]
    fn px4s_chunks_are_one_text_and_its_tab_is_dropped() {
        let said = "Preflight Fail: Battery unhealthy. Check battery connection and configuration, then retry\t";
        let mut words = Words::default();
        let now = Instant::now();
        for (id, seq, f) in chunks(7, said) {
            words.take(now, id, seq, &f);
        }
        assert_eq!(words.last().as_deref(), Some(said.trim_end()));
        assert_eq!(words.since(now).len(), 1);
    }

    #[test]
    fn a_text_of_exactly_fifty_bytes_is_whole_and_the_next_stands_apart() {
        let fifty = "x".repeat(50);
        let mut words = Words::default();
        let now = Instant::now();
        words.take(now, 3, 0, &field(&fifty));
        assert_eq!(words.last(), Some(fifty.clone()), "shown while it may go on");
        words.take(now, 4, 0, &field("Takeoff detected"));
        assert_eq!(words.since(now), vec![fifty, "Takeoff detected".to_owned()]);
    }

    #[test]
    fn ardupilots_single_texts_and_lost_chunks() {
        let mut words = Words::default();
        let t0 = Instant::now();
        words.take(t0, 0, 0, &field("PreArm: Battery 1 below minimum arming voltage"));
        words.take(t0, 0, 0, &field("Arm: Throttle too high"));
        assert_eq!(words.since(t0).len(), 2, "id 0: each text whole in itself");
        // A lost middle chunk is marked, and a chunk without its beginning stands alone.
        let t1 = t0 + Duration::from_secs(1);
        let parts = chunks(9, &"a".repeat(120));
        words.take(t1, parts[0].0, parts[0].1, &parts[0].2);
        words.take(t1, parts[2].0, parts[2].1, &parts[2].2);
        words.take(t1, 10, 1, &field("tail"));
        let got = words.since(t1);
        assert_eq!(
            got,
            vec![format!("{}[...]{}", "a".repeat(50), "a".repeat(20)), "[...]tail".into()]
        );
        // Sixteen are kept, newest last.
        for i in 0..40 {
            words.take(t1, 0, 0, &field(&format!("text {i}")));
        }
        assert_eq!(words.since(t0).len(), 16);
        assert_eq!(words.last().as_deref(), Some("text 39"));
    }

    #[test]
    fn endless_chunks_stay_bounded_and_bad_bytes_are_shown() {
        let mut words = Words::default();
        let now = Instant::now();
        let full = [b'y'; 50];
        for seq in 0..=255u8 {
            words.take(now, 1, seq, &full);
        }
        assert!(words.last().unwrap().len() <= super::LONGEST);
        words.take(now, 0, 0, &[0xff, 0xfe, b'o', b'k', 0]);
        assert_eq!(words.last().as_deref(), Some("\u{fffd}\u{fffd}ok"));
    }
}
