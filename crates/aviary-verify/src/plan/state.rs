//! What a walk of the estimate changes, and how an `IF` it cannot decide, or a handler's
//! worst case, tries a walk and goes back without copying it all. The per-drone figures
//! are copied (their size is the fleet's, not the mission's). What grows with the mission
//! only grows during a walk (the activities, the assumptions, the handlers that fired) or
//! changes with a log of what it held (the signals' first raise times), so a [`Mark`]
//! remembers lengths, and going back is cutting there. Trying both sides of N undecidable
//! `IF`s in a row, or N unfired handlers, so costs what the walks cost, not N copies of
//! everything.

use aviary_api::DroneId;
use aviary_ir::{Origin, SignalId, TiSlice, TiVec};

/// Per signal, when it is first raised (`None`: not yet, or not known).
pub type RaiseTimes = TiVec<SignalId, Option<f64>>;

use super::model::Flyer;
use super::radio::Leg;
use super::Activity;

/// An assumption: where (file, byte), and what.
pub type Note = (Option<(u32, u32)>, String);

#[derive(Clone)]
pub struct State {
    pub drones: TiVec<DroneId, Flyer>,
    /// Per drone; only ever pushed to.
    pub activities: TiVec<DroneId, Vec<Activity>>,
    /// Per signal, when it is first raised; changed only by [`State::raise`].
    pub raised: RaiseTimes,
    /// Each change to `raised`: the signal and what it held before.
    raised_log: Vec<(SignalId, Option<f64>)>,
    /// Per drone: the mission-level statement during which the reserve fell under 20%.
    pub reserve: TiVec<DroneId, Option<Origin>>,
    /// What the estimate had to assume, with where, as noted (each may come more than
    /// once: [`State::notes`] gives them sorted, each once).
    pub assumptions: Vec<Note>,
    /// Handlers that fired, by address, as they fired.
    pub fired: Vec<usize>,
    /// Per drone, the legs it flies, when the world has a radio (`super::radio`); only
    /// ever pushed to, as the activities.
    pub tracks: TiVec<DroneId, Vec<Leg>>,
}

/// The state at a moment: the small parts, and the lengths of the growing ones.
pub struct Mark {
    drones: TiVec<DroneId, Flyer>,
    raised: usize,
    reserve: TiVec<DroneId, Option<Origin>>,
    activities: TiVec<DroneId, usize>,
    assumptions: usize,
    fired: usize,
    tracks: TiVec<DroneId, usize>,
}

/// What a walk changed since a [`Mark`]: the small parts as they are after it, and what
/// the growing ones gained.
pub struct Tail {
    drones: TiVec<DroneId, Flyer>,
    /// The changes to `raised`, last first: the signal and what it held after.
    raised: Vec<(SignalId, Option<f64>)>,
    reserve: TiVec<DroneId, Option<Origin>>,
    activities: TiVec<DroneId, Vec<Activity>>,
    assumptions: Vec<Note>,
    fired: Vec<usize>,
    tracks: TiVec<DroneId, Vec<Leg>>,
}

impl Mark {
    /// The drones as they were at the mark.
    pub fn drones(&self) -> &TiSlice<DroneId, Flyer> {
        &self.drones
    }
}

impl State {
    pub fn new(drones: TiVec<DroneId, Flyer>, signals: usize) -> State {
        let n = drones.len();
        State {
            drones,
            activities: vec![Vec::new(); n].into(),
            raised: vec![None; signals].into(),
            raised_log: Vec::new(),
            reserve: vec![None; n].into(),
            assumptions: Vec::new(),
            fired: Vec::new(),
            tracks: vec![Vec::new(); n].into(),
        }
    }

    /// `signal` is raised at `t`: its first raise time becomes `t` if that is earlier.
    pub fn raise(&mut self, signal: SignalId, t: f64) {
        let first = self.raised[signal];
        if first.map_or(true, |f| t < f) {
            self.raised_log.push((signal, first));
            self.raised[signal] = Some(t);
        }
    }

    pub fn mark(&self) -> Mark {
        Mark {
            drones: self.drones.clone(),
            raised: self.raised_log.len(),
            reserve: self.reserve.clone(),
            activities: self.activities.iter().map(Vec::len).collect(),
            assumptions: self.assumptions.len(),
            fired: self.fired.len(),
            tracks: self.tracks.iter().map(Vec::len).collect(),
        }
    }

    /// Takes what changed since `mark` out, leaving the state as it was at `mark`.
    pub fn cut(&mut self, mark: &Mark) -> Tail {
        Tail {
            drones: std::mem::replace(&mut self.drones, mark.drones.clone()),
            raised: self.unraise(mark.raised),
            reserve: std::mem::replace(&mut self.reserve, mark.reserve.clone()),
            activities: self
                .activities
                .iter_mut()
                .zip(&mark.activities)
                .map(|(a, &n)| a.split_off(n))
                .collect(),
            assumptions: self.assumptions.split_off(mark.assumptions),
            fired: self.fired.split_off(mark.fired),
            tracks: self
                .tracks
                .iter_mut()
                .zip(&mark.tracks)
                .map(|(a, &n)| a.split_off(n))
                .collect(),
        }
    }

    /// Back to `mark`, but keeping what the walk since had to assume.
    pub fn back_keeping_notes(&mut self, mark: Mark) {
        self.unraise(mark.raised);
        for (a, &n) in self.activities.iter_mut().zip(&mark.activities) {
            a.truncate(n);
        }
        self.fired.truncate(mark.fired);
        for (a, &n) in self.tracks.iter_mut().zip(&mark.tracks) {
            a.truncate(n);
        }
        self.drones = mark.drones;
        self.reserve = mark.reserve;
    }

    /// Back to `mark`, then on with `tail`: the state the walk that made `tail` left.
    pub fn redo(&mut self, mark: &Mark, tail: Tail) {
        for (a, &n) in self.activities.iter_mut().zip(&mark.activities) {
            a.truncate(n);
        }
        self.assumptions.truncate(mark.assumptions);
        self.fired.truncate(mark.fired);
        for (a, &n) in self.tracks.iter_mut().zip(&mark.tracks) {
            a.truncate(n);
        }
        self.unraise(mark.raised);
        self.drones = tail.drones;
        for (signal, after) in tail.raised.into_iter().rev() {
            self.raised_log.push((signal, self.raised[signal]));
            self.raised[signal] = after;
        }
        self.reserve = tail.reserve;
        for (a, more) in self.activities.iter_mut().zip(tail.activities) {
            a.extend(more);
        }
        self.assumptions.extend(tail.assumptions);
        self.fired.extend(tail.fired);
        for (a, more) in self.tracks.iter_mut().zip(tail.tracks) {
            a.extend(more);
        }
    }

    /// Undoes the changes to `raised` past the log's length `to`; what each held after.
    fn unraise(&mut self, to: usize) -> Vec<(SignalId, Option<f64>)> {
        let undone = self.raised_log.split_off(to.min(self.raised_log.len()));
        undone
            .into_iter()
            .rev()
            .map(|(signal, before)| (signal, std::mem::replace(&mut self.raised[signal], before)))
            .collect()
    }

    /// The assumptions, sorted, each once.
    pub fn notes(&self) -> Vec<&Note> {
        let mut out: Vec<&Note> = self.assumptions.iter().collect();
        out.sort();
        out.dedup();
        out
    }
}

#[cfg(test)]
mod tests {
    use aviary_test_support::harness;

    fn plan(text: &str) -> crate::Plan {
        let world = "[drones.scout]\nhome = [0, 0]\nendurance = 100000\n";
        let (mission, world) = harness::compile(text, world);
        crate::verify(&mission, &world).plan
    }

    /// Many `IF`s the estimate cannot decide, in a row, each with a longer and a shorter
    /// side: each takes its longer side, with what that side did (its activities), and
    /// nothing of the side it dropped; each assumption is listed once.
    #[test]
    fn undecidable_ifs_take_their_longer_side_with_its_activities_only() {
        let n = 2000;
        let mut text = String::from("MISSION M:\n    scout TakeOff WITH 20m\n");
        for i in 0..n {
            let (then, otherwise) = if i % 2 == 0 { ("5s", "1s") } else { ("1s", "3s") };
            text.push_str(&format!("    IF scout.link = Lost:\n        scout Hover WITH {then}\n    ELSE:\n        scout Hover WITH {otherwise}\n"));
        }
        let p = plan(&text);
        let hovers: Vec<f64> = p.drones[0]
            .activities
            .iter()
            .filter(|a| a.what == "Hover")
            .map(|a| a.end - a.start)
            .collect();
        assert_eq!(hovers.len(), n);
        assert!(
            hovers
                .iter()
                .enumerate()
                .all(|(i, d)| (d - if i % 2 == 0 { 5.0 } else { 3.0 }).abs() < 1e-9),
            "{:?}",
            &hovers[..6]
        );
        let mut seen: Vec<(Option<(u32, u32)>, &str)> =
            p.assumptions.iter().map(|a| (a.origin, a.text.as_str())).collect();
        let all = seen.len();
        seen.dedup();
        assert_eq!(seen.len(), all, "each assumption once");
    }
}
