//! The report of a campaign: its figures, made from the runs' records alone, so that the
//! records of shards merged make exactly the report of one unsharded run.

use aviary_api::trace::Status;
use aviary_world::Expectation;
use serde::{Deserialize, Serialize};

use crate::stats::{wilson, Distribution};
use crate::{Campaign, RunRecord, Shard};

/// What a report's JSON says it is: a reader can tell a report of another layout.
pub const FORMAT: &str = "aviary-campaign/1";

/// How many of the worst runs a report names.
pub const WORST: usize = 5;

/// How many seeds each kind of outcome lists.
pub const SEEDS_SHOWN: usize = 5;

/// The seeds of a campaign: `first`, `first + 1`, ... `first + runs - 1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Seeds {
    pub first: u64,
    pub runs: u64,
}

impl Seeds {
    /// `runs` seeds from `first`: at least one, and all below 2^64.
    pub fn new(first: u64, runs: u64) -> Result<Seeds, String> {
        if runs == 0 {
            return Err("--runs must be at least 1".into());
        }
        if first.checked_add(runs - 1).is_none() {
            return Err(format!(
                "--seed {first} with --runs {runs} goes past the last seed, {}",
                u64::MAX
            ));
        }
        Ok(Seeds { first, runs })
    }

    /// The seeds of `shard` (all of them without one), in order.
    pub fn of(&self, shard: Option<Shard>) -> Vec<u64> {
        (0..self.runs)
            .filter(|k| match shard {
                None => true,
                Some(s) => s.holds(*k),
            })
            .map(|k| self.first + k)
            .collect()
    }
}

/// What the campaign flew: the same for every shard of it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Flew {
    pub mission_file: String,
    pub world_file: String,
    /// The `MISSION`'s name.
    pub mission: String,
    /// `Campaign::fingerprint`.
    pub fingerprint: String,
    pub drones: Vec<String>,
    /// How many `[[targets]]` the world has.
    pub targets: u64,
    pub expectations: Vec<Expectation>,
}

impl Flew {
    pub fn of(campaign: &Campaign) -> Flew {
        let world = &campaign.prepared.world;
        Flew {
            mission_file: campaign.mission_file.clone(),
            world_file: campaign.world_file.clone(),
            mission: campaign.prepared.mission.name.clone(),
            fingerprint: campaign.fingerprint.clone(),
            drones: campaign.prepared.mission.drones.iter().map(str::to_owned).collect(),
            targets: world.targets.len() as u64,
            expectations: world.expect.clone(),
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Report {
    pub format: String,
    pub flew: Flew,
    pub seeds: Seeds,
    /// The share of the seeds this report holds; none for the whole campaign.
    pub shard: Option<Shard>,
    /// The runs in this report.
    pub runs: u64,
    /// Runs that ended `ok` and met every expectation.
    pub succeeded: u64,
    /// `succeeded / runs`; none without runs.
    pub success_rate: Option<f64>,
    /// The 95 % Wilson score interval of the success rate.
    pub interval95: [f64; 2],
    /// How many runs met each expectation, in the order of `[expect]`.
    pub expectations: Vec<Met>,
    /// Runs by how they ended, the most frequent first.
    pub outcomes: Vec<Outcome>,
    /// Mission time, seconds.
    pub time: Option<Distribution>,
    /// Each drone's lowest battery, a fraction.
    pub lowest_battery: Vec<DroneBattery>,
    /// Targets found.
    pub found: Option<Distribution>,
    /// The worst runs, worst first: each repeats exactly with its command.
    pub worst: Vec<Worst>,
    /// Every run, by seed.
    pub records: Vec<RunRecord>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Met {
    pub expectation: String,
    pub met: u64,
}

/// Runs that ended the same way, on the same drone, at the same statement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// `ok`, `unhandled exception NAME`, `expectation not met: ...`, or the mission's end
    /// and its reason.
    pub outcome: String,
    pub drone: Option<String>,
    /// `file:line:col`.
    pub statement: Option<String>,
    pub runs: u64,
    /// The first few seeds that ended so.
    pub seeds: Vec<u64>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DroneBattery {
    pub drone: String,
    pub lowest: Option<Distribution>,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Worst {
    pub seed: u64,
    pub outcome: String,
    pub time: f64,
    pub lowest_battery: f64,
    /// The command that flies this run again, exactly.
    pub command: String,
}

/// How one run ended, in words: `ok`, the unhandled exception, the mission's end and
/// reason, or the expectations it did not meet.
pub fn outcome_of(record: &RunRecord, expectations: &[Expectation]) -> String {
    if let Some(name) = record.failure.as_ref().and_then(|f| f.exception.as_deref()) {
        return format!("unhandled exception {name}");
    }
    if record.status != Status::Ok {
        return match &record.reason {
            Some(reason) => format!("{}: {reason}", record.status.as_str()),
            None => record.status.as_str().to_owned(),
        };
    }
    let unmet: Vec<String> = expectations
        .iter()
        .zip(&record.expectations)
        .filter(|(_, met)| !**met)
        .map(|(e, _)| e.to_string())
        .collect();
    if unmet.is_empty() {
        "ok".into()
    } else {
        format!("expectation not met: {}", unmet.join(", "))
    }
}

impl Report {
    /// The report of `records` (any order) of the campaign `flew` over `seeds`.
    pub fn new(
        flew: Flew,
        seeds: Seeds,
        shard: Option<Shard>,
        mut records: Vec<RunRecord>,
    ) -> Report {
        records.sort_by_key(|r| r.seed);
        let runs = records.len() as u64;
        let succeeded = records.iter().filter(|r| r.success).count() as u64;
        let expectations = flew
            .expectations
            .iter()
            .enumerate()
            .map(|(i, e)| Met {
                expectation: e.to_string(),
                met: records
                    .iter()
                    .filter(|r| r.expectations.get(i).copied().unwrap_or(false))
                    .count() as u64,
            })
            .collect();
        let outcomes = outcomes(&records, &flew.expectations);
        let values = |f: &dyn Fn(&RunRecord) -> f64| records.iter().map(f).collect::<Vec<f64>>();
        let lowest_battery = flew
            .drones
            .iter()
            .enumerate()
            .map(|(d, drone)| DroneBattery {
                drone: drone.clone(),
                lowest: Distribution::of(
                    &values(&|r| r.lowest_battery.get(d).copied().unwrap_or(f64::NAN)),
                    false,
                ),
            })
            .collect();
        let worst = worst(&records, &flew);
        Report {
            format: FORMAT.into(),
            seeds,
            shard,
            runs,
            succeeded,
            success_rate: (runs > 0).then(|| succeeded as f64 / runs as f64),
            interval95: wilson(succeeded, runs),
            expectations,
            outcomes,
            time: Distribution::of(&values(&|r| r.time), false),
            lowest_battery,
            found: Distribution::of(&values(&|r| r.found as f64), true),
            worst,
            records,
            flew,
        }
    }

    /// The report of the whole campaign from the reports of its shards (any order): each
    /// run of the campaign must be in exactly one of them.
    pub fn merge(parts: Vec<Report>) -> Result<Report, String> {
        let Some(first) = parts.first() else {
            return Err("no reports to merge".into());
        };
        let (flew, seeds) = (first.flew.clone(), first.seeds);
        let mut records = Vec::new();
        for (i, part) in parts.into_iter().enumerate() {
            let n = i + 1;
            if part.format != FORMAT {
                return Err(format!(
                    "report {n} is of the layout `{}`, not `{FORMAT}`",
                    part.format
                ));
            }
            if part.flew != flew {
                let why = if part.flew.fingerprint != flew.fingerprint {
                    "its mission, world or the files they USE differ"
                } else {
                    "its mission or world file is named differently"
                };
                return Err(format!("report {n} is of another campaign than report 1: {why}"));
            }
            if part.seeds != seeds {
                return Err(format!(
                    "report {n} is of the seeds {} to {}, report 1 of {} to {}",
                    part.seeds.first,
                    part.seeds.first + (part.seeds.runs - 1),
                    seeds.first,
                    seeds.first + (seeds.runs - 1)
                ));
            }
            records.extend(part.records);
        }
        records.sort_by_key(|r| r.seed);
        if let Some(twice) = records.windows(2).find(|w| w[0].seed == w[1].seed) {
            return Err(format!(
                "seed {} is in two of the reports: merge each shard once",
                twice[0].seed
            ));
        }
        let end = seeds.first + (seeds.runs - 1);
        if let Some(out) = records.iter().find(|r| r.seed < seeds.first || r.seed > end) {
            return Err(format!("seed {} is outside the campaign's seeds", out.seed));
        }
        if records.len() as u64 != seeds.runs {
            let missing = (seeds.first..=end)
                .find(|s| records.binary_search_by_key(s, |r| r.seed).is_err())
                .unwrap_or(seeds.first);
            return Err(format!(
                "the reports hold {} of the campaign's {} runs (seed {missing} is missing): merge every shard",
                records.len(),
                seeds.runs
            ));
        }
        Ok(Report::new(flew, seeds, None, records))
    }

    /// The report as JSON (one object, with a newline).
    pub fn json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).unwrap_or_default();
        text.push('\n');
        text
    }

    /// A report read back from its JSON; `name` for messages.
    pub fn read(name: &str, text: &str) -> Result<Report, String> {
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| format!("{name} is not JSON: {e}"))?;
        match value.get("format").and_then(|f| f.as_str()) {
            Some(FORMAT) => {}
            Some(other) => {
                return Err(format!("{name} is a report of the layout `{other}`, not `{FORMAT}`"))
            }
            None => {
                return Err(format!(
                    "{name} is not a campaign report (`aviary test --format json`)"
                ))
            }
        }
        let report: Report = serde_json::from_value(value)
            .map_err(|e| format!("{name} is not a whole campaign report: {e}"))?;
        Seeds::new(report.seeds.first, report.seeds.runs)
            .map_err(|why| format!("{name} has seeds no campaign has: {why}"))?;
        Ok(report)
    }
}

/// Runs grouped by how they ended, on which drone and at which statement.
fn outcomes(records: &[RunRecord], expectations: &[Expectation]) -> Vec<Outcome> {
    let mut out: Vec<Outcome> = Vec::new();
    for r in records {
        let outcome = outcome_of(r, expectations);
        let drone = r.failure.as_ref().and_then(|f| f.drone.clone());
        let statement =
            r.failure.as_ref().and_then(|f| f.statement.as_ref()).map(ToString::to_string);
        match out
            .iter_mut()
            .find(|o| o.outcome == outcome && o.drone == drone && o.statement == statement)
        {
            Some(o) => {
                o.runs += 1;
                if o.seeds.len() < SEEDS_SHOWN {
                    o.seeds.push(r.seed);
                }
            }
            None => out.push(Outcome { outcome, drone, statement, runs: 1, seeds: vec![r.seed] }),
        }
    }
    // The most frequent first; among equals, the one whose first run came first.
    out.sort_by(|a, b| b.runs.cmp(&a.runs).then(a.seeds.first().cmp(&b.seeds.first())));
    out
}

/// The worst runs, worst first: failed or aborted, then expectations not met (more
/// first), then the longest, then the lowest battery, then the lowest seed.
fn worst(records: &[RunRecord], flew: &Flew) -> Vec<Worst> {
    let lowest = |r: &RunRecord| r.lowest_battery.iter().copied().fold(1.0_f64, f64::min);
    let unmet = |r: &RunRecord| r.expectations.iter().filter(|m| !**m).count();
    let mut ranked: Vec<&RunRecord> = records.iter().collect();
    ranked.sort_by(|a, b| {
        (a.status == Status::Ok)
            .cmp(&(b.status == Status::Ok))
            .then(unmet(b).cmp(&unmet(a)))
            .then(b.time.total_cmp(&a.time))
            .then(lowest(a).total_cmp(&lowest(b)))
            .then(a.seed.cmp(&b.seed))
    });
    ranked
        .into_iter()
        .take(WORST)
        .map(|r| Worst {
            seed: r.seed,
            outcome: outcome_of(r, &flew.expectations),
            time: r.time,
            lowest_battery: lowest(r),
            command: format!(
                "aviary run {} --world {} --seed {}",
                shell_word(&flew.mission_file),
                shell_word(&flew.world_file),
                r.seed
            ),
        })
        .collect()
}

/// A word as a POSIX shell reads it back: as it is when it is plain, else in single quotes.
pub fn shell_word(word: &str) -> String {
    let plain = !word.is_empty()
        && word.chars().all(|c| c.is_ascii_alphanumeric() || "/._-+,:@%=".contains(c));
    if plain {
        word.to_owned()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}
