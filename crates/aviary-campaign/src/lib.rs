//! Campaigns (`aviary test`, docs/CAMPAIGNS.md): one mission, checked and compiled once,
//! flown on the simulator with many seeds at once, one run per thread at a time, each
//! single-threaded and deterministic. No trace is written: each run is heard as it goes
//! ([`Observer`]) and summed up in a [`RunRecord`]; the records make the [`Report`], the
//! same whatever the number of threads, and the reports of shards merge into the report
//! of the whole ([`Report::merge`]).
//!
//! A library: texts in, records and reports out. The terminal (the progress bar, what is
//! printed, the exit codes) is the CLI's; the HTML report is `aviary_station::campaign`'s.

// No unsafe code, and no panic on any input (tests may unwrap).
#![forbid(unsafe_code)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used, clippy::panic))]

use parking_lot::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use aviary_api::trace::{EventKind, Record};
use aviary_api::Backend;
use aviary_ir::Mission;
use aviary_pipeline::pipeline::{fly_prepared, prepare, Hooks, NotFlown, Options, Prepared, Texts};

mod observe;
pub mod report;
pub mod shard;
pub mod stats;
mod text;

pub use observe::{met, wants, Failure, Observer, RunRecord, Statement};
pub use report::{Report, Seeds};
pub use shard::Shard;

/// A mission ready to fly many times, and what names it in reports.
pub struct Campaign {
    pub prepared: Prepared,
    /// The mission's and the world's files, as named on the command line.
    pub mission_file: String,
    pub world_file: String,
    /// A digest of every text the mission was compiled from (the mission, what it USEs,
    /// the standard library, the world): shards of one campaign have the same.
    pub fingerprint: String,
}

impl Campaign {
    /// Checks and compiles the mission of `texts` once (`aviary_pipeline::pipeline::prepare`).
    pub fn prepare(texts: Texts<'_>) -> Result<Campaign, NotFlown> {
        let mission_file = texts.mission.name.to_owned();
        let world_file = texts.world.name.to_owned();
        let prepared = prepare(texts)?;
        let mut digest = Fnv::default();
        for id in prepared.sources.ids() {
            digest.write(prepared.sources.name(id).as_bytes());
            digest.write(&[0]);
            digest.write(prepared.sources.text(id).as_bytes());
            digest.write(&[0]);
        }
        Ok(Campaign {
            prepared,
            mission_file,
            world_file,
            fingerprint: format!("fnv1a64:{:016x}", digest.0),
        })
    }

    /// One run, with `seed`: as `aviary run --seed SEED` flies it.
    pub fn fly(&self, seed: u64) -> Result<RunRecord, String> {
        let mission = &self.prepared.mission;
        let mut heard = Heard { observer: Observer::new(mission) };
        let options = Options { seed, ..Options::default() };
        let flown = fly_prepared(&self.prepared, &options, &mut heard).map_err(|e| match e {
            NotFlown::Failed(why) => why,
            _ => "the mission could not fly".to_owned(),
        })?;
        let world = &self.prepared.world;
        Ok(heard.observer.finish(
            seed,
            &flown.outcome,
            &world.expect,
            world.targets.len(),
            Some(&self.prepared.sources),
        ))
    }

    /// Every seed of `seeds`, on `jobs` threads (at least one), in any order; the
    /// records in the order of `seeds`. `done` hears each record as its run ends (from
    /// the thread that flew it).
    pub fn run(
        &self,
        seeds: &[u64],
        jobs: usize,
        done: &(dyn Fn(&RunRecord) + Sync),
    ) -> Result<Vec<RunRecord>, String> {
        let next = AtomicUsize::new(0);
        let records: Mutex<Vec<Option<RunRecord>>> = Mutex::new(vec![None; seeds.len()]);
        let failed: Mutex<Option<String>> = Mutex::new(None);
        let work = || loop {
            let k = next.fetch_add(1, Ordering::Relaxed);
            let Some(seed) = seeds.get(k) else { break };
            match self.fly(*seed) {
                Ok(record) => {
                    done(&record);
                    records.lock()[k] = Some(record);
                }
                Err(why) => {
                    failed.lock().get_or_insert(format!("seed {seed}: {why}"));
                    // No more work: the campaign has failed.
                    next.store(seeds.len(), Ordering::Relaxed);
                }
            }
        };
        let jobs = jobs.clamp(1, seeds.len().max(1));
        std::thread::scope(|scope| {
            let mut workers = Vec::new();
            for j in 1..jobs {
                let spawned = std::thread::Builder::new()
                    .name(format!("campaign-{j}"))
                    // The engine follows capability calls by recursion, as on the CLI's
                    // own thread (reserved, not used).
                    .stack_size(aviary_check::STACK)
                    .spawn_scoped(scope, work);
                match spawned {
                    Ok(w) => workers.push(w),
                    Err(e) => {
                        failed.lock().get_or_insert(format!("cannot start a thread: {e}"));
                    }
                }
            }
            // The calling thread works too.
            work();
            for w in workers {
                if w.join().is_err() {
                    failed.lock().get_or_insert("a run panicked".to_owned());
                }
            }
        });
        if let Some(why) = failed.into_inner() {
            return Err(why);
        }
        let records = records.into_inner();
        records.into_iter().map(|r| r.ok_or_else(|| "a run did not end".to_owned())).collect()
    }
}

/// The hooks of one run: its observer.
struct Heard {
    observer: Observer,
}

impl Hooks for Heard {
    fn wants(&self, kind: EventKind) -> bool {
        wants(kind)
    }

    fn record(&mut self, record: &Record<'_>, backend: &dyn Backend) {
        self.observer.record(record, backend);
    }

    fn landed(
        &mut self,
        _: &Mission,
        backend: &dyn Backend,
        _: &dyn Fn(usize) -> Option<(f64, f64)>,
    ) {
        self.observer.landed(backend);
    }
}

/// FNV-1a, 64 bits: a stable digest of the texts (not for security: it tells shards of
/// different files apart, which no one forges).
struct Fnv(u64);

impl Default for Fnv {
    fn default() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
}

impl Fnv {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 ^= u64::from(*b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
}
