//! The documentation says what is true, and stands on its own.
//!
//! - Every mission shown in `docs/*.md` and `README.md` (a code block tagged `aviary`)
//!   checks clean against its world and runs to its end in the simulator; every
//!   fragment (tagged `aviary-fragment`) reads without a syntax error; every world shown
//!   (a `toml` block with a `[drones.NAME]` table) reads without an error.
//! - Every key that `docs/WORLD.md`'s tables name is one the world reader reads, and every
//!   key the reader reads is in those tables.
//! - The events `docs/TRACE.md` lists are the engine's, each with the fields it writes.
//! - Every flag of `aviary run` is in the README's "What works today", and the trace's
//!   size limit is documented with the default the binary has.
//! - Nothing in the docs, the README, the standard library, the examples or the crates'
//!   sources points outside the repository.
//!
//! The conventions of the code blocks (docs/LANGUAGE.md, "About the examples"):
//! - A mission block is checked against the world named on its first line,
//!   `// world: PATH` (a file of the repository), or else against the nearest world block
//!   above it in the same file, or else the nearest one below it.
//! - `// expect: W201` lines name the warnings the mission is meant to have (notes are
//!   always allowed; any other warning or any error fails).
//! - A mission block is in the layout `aviary fmt` gives.
//! - A block with a `MISSION` is also run, and must end `ok` (exit 0), or `failed` (exit 1)
//!   when it says `// run: fails`.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use aviary_diagnostics::FileId;
use common::{aviary, repo, scratch};

/// A fenced code block of a Markdown file.
#[derive(Clone, Debug)]
struct Block {
    /// Repository-relative path of the file, and the line of the opening fence.
    file: String,
    line: usize,
    lang: String,
    text: String,
}

impl Block {
    fn place(&self) -> String {
        format!("{}:{}", self.file, self.line)
    }
    fn is_world(&self) -> bool {
        self.lang == "toml" && self.text.lines().any(|l| l.trim_start().starts_with("[drones."))
    }
    /// The values of `// KEY: value` comment lines.
    fn directives(&self, key: &str) -> Vec<String> {
        let prefix = format!("// {key}:");
        self.text
            .lines()
            .filter_map(|l| l.trim().strip_prefix(prefix.as_str()))
            .map(|v| v.trim().to_string())
            .collect()
    }
}

fn blocks(rel: &str) -> Vec<Block> {
    let text = std::fs::read_to_string(repo().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
    let mut out = Vec::new();
    let mut open: Option<Block> = None;
    for (i, line) in text.lines().enumerate() {
        let trimmed = line.trim_start();
        match &mut open {
            None => {
                if let Some(lang) = trimmed.strip_prefix("```") {
                    open = Some(Block {
                        file: rel.to_string(),
                        line: i + 1,
                        lang: lang.trim().to_string(),
                        text: String::new(),
                    });
                }
            }
            Some(b) => {
                if trimmed.starts_with("```") {
                    out.push(open.take().unwrap());
                } else {
                    b.text.push_str(line);
                    b.text.push('\n');
                }
            }
        }
    }
    assert!(open.is_none(), "{rel}: a code block is not closed");
    out
}

/// The Markdown files whose examples are checked.
fn documents() -> Vec<String> {
    let mut out: Vec<String> = std::fs::read_dir(repo().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".md"))
        .map(|n| format!("docs/{n}"))
        .collect();
    out.push("README.md".into());
    out.sort();
    out
}

/// Where a mission block's world comes from.
enum WorldOf {
    File(PathBuf),
    Block(Block),
}

fn world_of(all: &[Block], index: usize) -> Option<WorldOf> {
    if let Some(path) = all[index].directives("world").first() {
        return Some(WorldOf::File(repo().join(path)));
    }
    let above = all[..index].iter().rev().find(|b| b.is_world());
    let below = all[index + 1..].iter().find(|b| b.is_world());
    above.or(below).cloned().map(WorldOf::Block)
}

fn json_lines(text: &str) -> Vec<serde_json::Value> {
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect()
}

/// Checks (and runs) one mission block; the problems found, in words.
fn check_mission(dir: &Path, all: &[Block], index: usize) -> Vec<String> {
    let b = &all[index];
    let stem = format!("{}_{}", b.file.replace(['/', '.'], "_"), b.line);
    let mission = dir.join(format!("{stem}.mission"));
    std::fs::write(&mission, &b.text).unwrap();
    let world = match world_of(all, index) {
        Some(WorldOf::File(path)) => path,
        Some(WorldOf::Block(w)) => {
            let path = dir.join(format!("{stem}.world.toml"));
            std::fs::write(&path, &w.text).unwrap();
            path
        }
        None => return vec![format!("{}: no world for this mission", b.place())],
    };
    let (mission, world) =
        (mission.to_string_lossy().into_owned(), world.to_string_lossy().into_owned());
    let mut problems = Vec::new();
    let (code, out, err) = aviary(&["check", &mission, "--world", &world, "--format", "json"], dir);
    let diagnostics = json_lines(&out);
    let expected: BTreeSet<String> = b.directives("expect").into_iter().collect();
    let mut warned = BTreeSet::new();
    for d in &diagnostics {
        match d["severity"].as_str() {
            Some("error") => problems.push(format!(
                "{}: error {} at line {}: {}",
                b.place(),
                d["code"],
                d["line"],
                d["message"]
            )),
            Some("warning") => {
                let code = d["code"].as_str().unwrap_or_default().to_string();
                if !expected.contains(&code) {
                    problems.push(format!(
                        "{}: warning {code} at line {}: {}",
                        b.place(),
                        d["line"],
                        d["message"]
                    ));
                }
                warned.insert(code);
            }
            _ => {}
        }
    }
    for code in expected.difference(&warned) {
        problems
            .push(format!("{}: expects warning {code}, which the check does not give", b.place()));
    }
    if code != 0 && problems.is_empty() {
        problems.push(format!("{}: aviary check exits {code}: {err}", b.place()));
    }
    let (code, out, err) = aviary(&["fmt", "--check", &mission], dir);
    if code != 0 {
        problems.push(format!("{}: not in the layout `aviary fmt` gives: {out}{err}", b.place()));
    }
    if !problems.is_empty() || !b.text.lines().any(|l| l.trim_start().starts_with("MISSION")) {
        return problems;
    }
    let fails = b.directives("run").iter().any(|r| r == "fails");
    let (code, out, err) = aviary(&["run", &mission, "--world", &world], dir);
    let want = if fails { 1 } else { 0 };
    if code != want {
        problems.push(format!("{}: aviary run exits {code}, not {want}:\n{out}{err}", b.place()));
    }
    problems
}

#[test]
fn every_mission_in_the_docs_checks_clean_and_runs_to_its_end() {
    let dir = scratch("docs_missions");
    let mut problems = Vec::new();
    let mut missions: BTreeMap<String, usize> = BTreeMap::new();
    for doc in documents() {
        let all = blocks(&doc);
        for (i, b) in all.iter().enumerate() {
            if b.lang == "aviary" {
                *missions.entry(doc.clone()).or_default() += 1;
                problems.extend(check_mission(&dir, &all, i));
            }
        }
    }
    assert!(
        problems.is_empty(),
        "{} problems in the docs' missions:\n{}",
        problems.len(),
        problems.join("\n")
    );
    // The docs that teach the language show missions, and each one was checked.
    for (doc, at_least) in [
        ("docs/LANGUAGE.md", 20),
        ("docs/TUTORIAL.md", 3),
        ("docs/PATTERNS.md", 5),
        ("docs/TRACE.md", 1),
    ] {
        let n = missions.get(doc).copied().unwrap_or(0);
        assert!(n >= at_least, "{doc} shows {n} missions, expected at least {at_least}");
    }
}

#[test]
fn every_fragment_in_the_docs_reads_without_a_syntax_error() {
    let mut problems = Vec::new();
    let mut count = 0;
    for doc in documents() {
        for b in blocks(&doc).into_iter().filter(|b| b.lang == "aviary-fragment") {
            count += 1;
            let first = b
                .text
                .lines()
                .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with("//"))
                .unwrap_or("");
            let whole = ["MISSION", "CAPABILITY", "USE"].iter().any(|k| first.starts_with(k));
            let text = if whole {
                b.text.clone()
            } else {
                format!(
                    "MISSION Fragment:\n{}",
                    b.text.lines().map(|l| format!("    {l}\n")).collect::<String>()
                )
            };
            let parse = aviary_syntax::parse(FileId(0), &text);
            for d in parse.diagnostics.iter().filter(|d| d.is_error()) {
                problems.push(format!("{}: {:?}: {}", b.place(), d.code, d.message));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert!(count >= 5, "the docs show {count} fragments");
}

/// DIAGNOSTICS.md shows a mistake in every example, on purpose (its missions are
/// `crates/aviary-check`'s fixtures, checked there).
const WRONG_ON_PURPOSE: &str = "docs/DIAGNOSTICS.md";

#[test]
fn every_mission_shown_in_the_docs_is_marked_for_checking() {
    let mut problems = Vec::new();
    for doc in documents().into_iter().filter(|d| d != WRONG_ON_PURPOSE) {
        for b in blocks(&doc) {
            let mission = b
                .text
                .lines()
                .any(|l| ["MISSION ", "CAPABILITY "].iter().any(|k| l.trim_start().starts_with(k)));
            if mission && b.lang != "aviary" && b.lang != "aviary-fragment" {
                problems.push(format!(
                    "{}: a mission in a block tagged `{}`: tag it `aviary` (or `aviary-fragment`)",
                    b.place(),
                    b.lang
                ));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn every_world_in_the_docs_reads_without_an_error() {
    let mut problems = Vec::new();
    for doc in documents().into_iter().filter(|d| d != WRONG_ON_PURPOSE) {
        for b in blocks(&doc).into_iter().filter(Block::is_world) {
            let (_, diagnostics) = aviary_world::parse_world(FileId(0), &b.text);
            for d in diagnostics.iter().filter(|d| d.is_error()) {
                problems.push(format!("{}: {}", b.place(), d.message));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

// ---- docs/WORLD.md against the world reader ----

/// The keys named in the first column of each table of WORLD.md, by the heading above it.
fn documented_world_keys() -> BTreeMap<String, BTreeSet<String>> {
    let text = std::fs::read_to_string(repo().join("docs/WORLD.md")).unwrap();
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut heading = String::new();
    for line in text.lines() {
        if line.starts_with('#') {
            heading = line.trim_start_matches('#').trim().to_string();
            continue;
        }
        let Some(row) = line.strip_prefix('|') else { continue };
        let first = row.split('|').next().unwrap_or("").trim();
        if first.starts_with("---") || first == "key" {
            continue;
        }
        for name in backticked(first) {
            out.entry(heading.clone()).or_default().insert(name);
        }
    }
    out
}

/// The `quoted` names of a text.
fn backticked(text: &str) -> Vec<String> {
    text.split('`').skip(1).step_by(2).map(str::to_string).collect()
}

fn keys_under(all: &BTreeMap<String, BTreeSet<String>>, heading: &str) -> BTreeSet<String> {
    let keys = all.iter().find(|(h, _)| h.contains(heading)).map(|(_, k)| k.clone());
    let keys =
        keys.unwrap_or_else(|| panic!("docs/WORLD.md has no table under a heading with {heading}"));
    assert!(!keys.is_empty(), "docs/WORLD.md: no keys under {heading}");
    keys
}

fn read_world(text: &str) -> (Option<aviary_world::World>, Vec<aviary_diagnostics::Diagnostic>) {
    aviary_world::parse_world(FileId(0), text)
}

/// The keys the reader knows in a table that rejects unknown keys: those its message
/// for an unknown key lists.
fn known_keys(world_with_unknown: &str) -> BTreeSet<String> {
    let (_, diagnostics) = read_world(world_with_unknown);
    let d = diagnostics.iter().find(|d| d.message.contains("zz_not_a_key")).unwrap_or_else(|| {
        panic!("no message for an unknown key in:\n{world_with_unknown}\n{diagnostics:?}")
    });
    let help = d.help.clone().unwrap_or_default();
    let list = help.split("are ").last().unwrap_or("");
    backticked(list)
        .into_iter()
        .map(|k| {
            k.trim_start_matches("[[").trim_start_matches('[').trim_end_matches(']').to_string()
        })
        .collect()
}

#[test]
fn every_world_key_documented_is_read_and_every_key_read_is_documented() {
    let doc = documented_world_keys();
    // Tables that reject an unknown key: each documented key is accepted, and the
    // reader's own list of known keys is the documented one.
    type KeyInTable<'a> = (&'a str, &'a dyn Fn(&str) -> String);
    let tables: [KeyInTable; 14] = [
        ("`[air]`", &|k| format!("[air]\n{k} = 1\n")),
        ("`[air.wind]`", &|k| format!("[air.wind]\n{k} = 1\n")),
        ("`[air.radio]`", &|k| format!("[air.radio]\n{k} = 1\n")),
        ("`[air.gps]`", &|k| format!("[air.gps]\n{k} = 1\n")),
        ("`[air.detection]`", &|k| format!("[air.detection]\n{k} = 1\n")),
        ("`[air.battery]`", &|k| format!("[air.battery]\n{k} = 1\n")),
        ("A drone's `air`", &|k| format!("[drones.d]\nhome = [0, 0]\nair = {{ {k} = 1 }}\n")),
        ("`[site]`", &|k| format!("[site]\n{k} = 1\n")),
        ("`[no_fly.NAME]`", &|k| {
            format!("[no_fly.z]\npolygon = [[0, 0], [9, 0], [9, 9]]\n{k} = 1\n")
        }),
        ("`origin`", &|k| format!("[site]\norigin = {{ {k} = 1 }}\n")),
        ("`[sensors.KIND]`", &|k| format!("[sensors.thermal]\n{k} = 1\n")),
        ("`[[targets]]`", &|k| format!("[[targets]]\n{k} = 1\n")),
        ("`[[faults]]`", &|k| format!("[drones.d]\nhome = [0, 0]\n[[faults]]\n{k} = 1\n")),
        ("`[expect]`", &|k| format!("[[targets]]\nkind = \"P\"\nat = [1, 1]\n[expect]\n{k} = 1\n")),
    ];
    for (heading, world) in tables {
        let keys = keys_under(&doc, heading);
        for key in &keys {
            let (_, diagnostics) = read_world(&world(key));
            let unknown: Vec<&String> = diagnostics
                .iter()
                .map(|d| &d.message)
                .filter(|m| m.contains("unknown key"))
                .collect();
            assert!(unknown.is_empty(), "docs/WORLD.md documents `{key}` under {heading}, and the reader does not know it: {unknown:?}");
        }
        let read = known_keys(&world("zz_not_a_key"));
        assert_eq!(read, keys, "the keys the reader knows under {heading} (left) and those docs/WORLD.md documents (right)");
    }
    // The top level: the tables.
    let (_, diagnostics) = read_world("[zz_not_a_key]\n");
    let d = diagnostics
        .iter()
        .find(|d| d.message.contains("zz_not_a_key"))
        .expect("an unknown table is an error");
    let tables: BTreeSet<String> = backticked(d.help.as_deref().unwrap_or(""))
        .into_iter()
        .filter(|t| t.starts_with('['))
        .collect();
    let text = std::fs::read_to_string(repo().join("docs/WORLD.md")).unwrap();
    for t in &tables {
        let name = t.trim_matches(['[', ']']);
        assert!(
            text.contains(&format!("[{name}")),
            "the world file's table {t} is not in docs/WORLD.md"
        );
    }
    assert!(tables.len() >= 7, "{tables:?}");

    // Fleets: their own keys, and the keys of `homes` (which rejects unknown ones).
    let fleet_keys = keys_under(&doc, "`[fleets.NAME]`");
    let fleet_source =
        std::fs::read_to_string(repo().join("crates/aviary-world/src/build/fleet.rs")).unwrap();
    let own = fleet_source
        .lines()
        .find(|l| l.contains("const FLEET_KEYS"))
        .expect("FLEET_KEYS in fleet.rs");
    let own: BTreeSet<String> = own.split('"').skip(1).step_by(2).map(str::to_string).collect();
    assert_eq!(
        own, fleet_keys,
        "the fleet's own keys (left) and those docs/WORLD.md documents (right)"
    );
    let homes = keys_under(&doc, "`homes`");
    let read = known_keys("[fleets.f]\ncount = 1\nhomes = { zz_not_a_key = 1 }\n");
    assert_eq!(
        read, homes,
        "the keys of `homes` the reader knows (left) and those docs/WORLD.md documents (right)"
    );

    // Drones: an unknown key is an attribute, so a documented key must not become one.
    let drone_keys = keys_under(&doc, "`[drones.NAME]`");
    for key in &drone_keys {
        let text = if key == "home" {
            "[drones.d]\nhome = [0, 0]\n".to_string()
        } else {
            format!("[drones.d]\nhome = [0, 0]\n{key} = 1\n")
        };
        match read_world(&text) {
            (Some(world), _) => {
                let attributes: Vec<&str> =
                    world.drones[0].attributes.iter().map(|(k, _)| &**k).collect();
                assert!(!attributes.contains(&key.as_str()), "docs/WORLD.md documents the drone key `{key}`, and the reader takes it for an attribute");
            }
            // A value of the wrong kind for a key the reader knows is an error about that key.
            (None, diagnostics) => assert!(
                diagnostics.iter().any(|d| d.message.contains(&format!("`{key}`"))),
                "`{key} = 1` in a drone gives errors that do not name it: {diagnostics:?}"
            ),
        }
    }
    // The method works: a key the reader does not know is an attribute.
    let (world, _) = read_world("[drones.d]\nhome = [0, 0]\ncall_sign = 1\n");
    assert_eq!(
        world.unwrap().drones[0].attributes.first().map(|(k, _)| k.to_string()).as_deref(),
        Some("call_sign")
    );
    // And every key the reader matches by name is documented.
    let source =
        std::fs::read_to_string(repo().join("crates/aviary-world/src/build/drone.rs")).unwrap();
    let mut read: BTreeSet<String> = source
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix('"'))
        .filter_map(|l| l.split_once("\" =>").map(|(k, _)| k.to_string()))
        .filter(|k| k.chars().all(|c| c.is_ascii_lowercase() || c == '_'))
        .collect();
    let backends = source
        .lines()
        .find(|l| l.contains("const BACKEND_KEYS"))
        .expect("BACKEND_KEYS in drone.rs");
    read.extend(backends.split('"').skip(1).step_by(2).map(str::to_string));
    assert!(
        read.contains("home") && read.contains("endurance") && read.contains("mavlink"),
        "{read:?}"
    );
    let missing: Vec<&String> = read.difference(&drone_keys).collect();
    assert!(
        missing.is_empty(),
        "drone keys the reader reads and docs/WORLD.md does not document: {missing:?}"
    );
}

// ---- docs/TRACE.md against the engine ----

/// TRACE.md's event table: event → (fields always written, fields sometimes written).
fn documented_events() -> BTreeMap<String, (BTreeSet<String>, BTreeSet<String>)> {
    let text = std::fs::read_to_string(repo().join("docs/TRACE.md")).unwrap();
    let mut out = BTreeMap::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // | `event` | always | sometimes | when |
        if cells.len() < 5 || !cells[1].starts_with('`') {
            continue;
        }
        let always: BTreeSet<String> = backticked(cells[2]).into_iter().collect();
        let sometimes: BTreeSet<String> = backticked(cells[3]).into_iter().collect();
        for event in backticked(cells[1]) {
            out.insert(event, (always.clone(), sometimes.clone()));
        }
    }
    out
}

#[test]
fn the_trace_events_documented_are_the_engines_with_their_fields() {
    let doc = documented_events();
    let engine: BTreeSet<String> =
        aviary_api::trace::EventKind::ALL.iter().map(|k| k.as_str().to_string()).collect();
    let documented: BTreeSet<String> = doc.keys().cloned().collect();
    assert_eq!(documented, engine, "docs/TRACE.md's events (left) and the engine's (right)");

    // TRACE.md's own example writes every kind of event, each with the fields documented.
    let all = blocks("docs/TRACE.md");
    let index = all.iter().position(|b| b.lang == "aviary").expect("docs/TRACE.md shows a mission");
    let dir = scratch("docs_trace");
    let mission = dir.join("example.mission");
    std::fs::write(&mission, &all[index].text).unwrap();
    let Some(WorldOf::Block(world)) = world_of(&all, index) else {
        panic!("docs/TRACE.md's mission has no world block")
    };
    std::fs::write(dir.join("example.world.toml"), &world.text).unwrap();
    let (code, out, err) = aviary(
        &["run", "example.mission", "--trace", "trace.jsonl", "--telemetry-hz", "0.2"],
        &dir,
    );
    assert_eq!(code, 0, "{out}{err}");
    let text = std::fs::read_to_string(dir.join("trace.jsonl")).unwrap();
    // A reader (a replay, a ground station) reads each line back as the typed event,
    // which writes the line again byte for byte.
    for line in text.lines() {
        let record: aviary_api::trace::Record =
            serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {line}"));
        assert_eq!(serde_json::to_string(&record).unwrap(), line);
    }
    let mut events = json_lines(&text);
    // Only an operator writes `operator`, and only a failsafe `autopilot`: they are checked
    // as the engine's own type writes them.
    use aviary_api::trace::{AutopilotAction, Event, OperatorAction, Record};
    for (action, drone) in [(OperatorAction::Pause, None), (OperatorAction::Hold, Some("scout1"))] {
        let event = Event::Operator { action, drone: drone.map(Into::into) };
        events.push(serde_json::to_value(Record { t: 1.0, event }).unwrap());
    }
    let event = Event::Autopilot {
        actor: "scout1".into(),
        action: AutopilotAction::Hold,
        reason: "scout1: link lost: holds where it is".into(),
    };
    events.push(serde_json::to_value(Record { t: 1.0, event }).unwrap());
    let mut seen = BTreeSet::new();
    for e in &events {
        let kind = e["event"].as_str().unwrap().to_string();
        let (always, sometimes) =
            doc.get(&kind).unwrap_or_else(|| panic!("an event TRACE.md does not list: {e}"));
        let keys: BTreeSet<String> =
            e.as_object().unwrap().keys().filter(|k| *k != "t" && *k != "event").cloned().collect();
        let missing: Vec<&String> = always.difference(&keys).collect();
        assert!(missing.is_empty(), "{kind} without {missing:?}: {e}");
        let extra: Vec<&String> =
            keys.iter().filter(|k| !always.contains(*k) && !sometimes.contains(*k)).collect();
        assert!(extra.is_empty(), "{kind} has fields TRACE.md does not list, {extra:?}: {e}");
        seen.insert(kind);
    }
    assert_eq!(seen, engine, "the kinds of event TRACE.md's example writes (left)");
}

// ---- nothing points outside the repository ----

fn files_under(dir: &Path, keep: &dyn Fn(&Path) -> bool, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries {
        let path = e.unwrap().path();
        if path.is_dir() {
            files_under(&path, keep, out);
        } else if keep(&path) {
            out.push(path);
        }
    }
}

#[test]
fn nothing_in_the_repository_points_outside_it() {
    let root = repo();
    let mut files = vec![root.join("README.md")];
    let ext = |wanted: &'static [&'static str]| {
        move |p: &Path| p.extension().is_some_and(|e| wanted.iter().any(|w| e == *w))
    };
    files_under(&root.join("docs"), &ext(&["md", "yaml", "json"]), &mut files);
    files_under(&root.join("std"), &ext(&["mission"]), &mut files);
    files_under(&root.join("examples"), &ext(&["mission", "toml"]), &mut files);
    let crates = std::fs::read_dir(root.join("crates")).unwrap();
    for c in crates {
        files_under(&c.unwrap().path().join("src"), &ext(&["rs"]), &mut files);
    }
    assert!(files.len() > 50, "{} files", files.len());
    let mut problems = Vec::new();
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap();
        let rel = path.strip_prefix(&root).unwrap_or(path).to_string_lossy().into_owned();
        let dir = path.parent().unwrap();
        for (n, line) in text.lines().enumerate() {
            let at = format!("{rel}:{}", n + 1);
            if line.contains("../shared")
                || line.contains("shared/LANGUAGE")
                || line.contains("shared/RUNTIME")
            {
                problems.push(format!("{at}: points outside the repository: {line}"));
            }
            if line.contains(".md §")
                || line.contains("RUNTIME.md")
                || line.contains("STYLE.md")
                || line.contains("paper/")
            {
                problems.push(format!("{at}: names the outside reference: {line}"));
            }
            // Every `NAME.md` named is a file of the repository: as written, beside the
            // file, in docs/, or in the page's folder of a crate that serves one (`web/`,
            // which the station's assets are named from).
            for word in line.split(|c: char| !(c.is_ascii_alphanumeric() || "_-./".contains(c))) {
                let word = word.trim_start_matches("./").trim_end_matches('.');
                if !word.ends_with(".md") || word.len() <= 3 {
                    continue;
                }
                let found = [
                    root.join(word),
                    dir.join(word),
                    root.join("docs").join(word),
                    dir.join("../web").join(word),
                ]
                .iter()
                .any(|p| {
                    p.is_file()
                        && p.canonicalize()
                            .is_ok_and(|p| p.starts_with(root.canonicalize().unwrap()))
                });
                if !found {
                    problems.push(format!(
                        "{at}: names `{word}`, which is not a file of the repository"
                    ));
                }
            }
            // Markdown links lead to files of the repository.
            let markdown = rel.ends_with(".md");
            for link in line.split("](").skip(1).filter(|_| markdown) {
                let target = link.split(')').next().unwrap_or("").split('#').next().unwrap_or("");
                if target.is_empty() || target.contains("://") {
                    continue;
                }
                let resolved = dir.join(target);
                if !resolved.exists()
                    || !resolved
                        .canonicalize()
                        .is_ok_and(|p| p.starts_with(root.canonicalize().unwrap()))
                {
                    problems.push(format!(
                        "{at}: a link to `{target}`, which is not in the repository"
                    ));
                }
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// The code map names every crate of the workspace, and nothing that is not one.
#[test]
fn the_architecture_maps_every_crate() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let map = std::fs::read_to_string(root.join("docs/ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let mapped: BTreeSet<String> = map
        .lines()
        .filter_map(|l| l.strip_prefix("### `crates/"))
        .filter_map(|l| l.strip_suffix('`'))
        .map(str::to_string)
        .collect();
    let crates: BTreeSet<String> = std::fs::read_dir(root.join("crates"))
        .expect("crates/")
        .map(|e| e.expect("an entry").path())
        .filter(|p| p.join("Cargo.toml").is_file())
        .map(|p| p.file_name().unwrap_or_default().to_string_lossy().into_owned())
        .collect();
    assert_eq!(mapped, crates, "docs/ARCHITECTURE.md's code map and crates/ differ");
}

/// Each crate's section of the code map names every Rust file of its `src/` (but
/// `lib.rs` and `main.rs`, and the files of a folder it names, `walk/`), and every file
/// it names in backticks is one of the crate's.
#[test]
fn each_crates_section_names_its_files_and_only_those() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let map = std::fs::read_to_string(root.join("docs/ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    let mut problems = Vec::new();
    let sections: Vec<&str> = map.split("\n### `crates/").skip(1).collect();
    for section in sections {
        let Some((name, text)) = section.split_once("`\n") else { continue };
        // The section ends at the next heading.
        let text = text.split("\n## ").next().unwrap_or(text);
        let text = text.split("\n### ").next().unwrap_or(text);
        let dir = root.join("crates").join(name);
        let mut files = Vec::new();
        files_under(&dir.join("src"), &|p| p.extension().is_some_and(|e| e == "rs"), &mut files);
        let relative: Vec<String> = files
            .iter()
            .filter_map(|f| f.strip_prefix(dir.join("src")).ok())
            .map(|f| f.to_string_lossy().into_owned())
            .collect();
        let named: BTreeSet<String> = backticked(text)
            .into_iter()
            .flat_map(|b| b.split([' ', ',', '(']).map(str::to_string).collect::<Vec<_>>())
            .filter(|w| w.ends_with(".rs") || w.ends_with('/'))
            .collect();
        for file in &relative {
            // Unit tests beside the code are not in the map.
            let base = file.rsplit('/').next().unwrap_or(file);
            if ["lib.rs", "main.rs", "tests.rs"].contains(&base) || base.ends_with("_tests.rs") {
                continue;
            }
            let in_folder = file.contains('/')
                && named
                    .iter()
                    .any(|n| n.ends_with('/') && file.starts_with(n.trim_start_matches("src/")));
            if !named.contains(file) && !named.contains(base) && !in_folder {
                problems.push(format!("crates/{name}: src/{file} is not in its section"));
            }
        }
        let own = format!("crates/{name}/");
        // A path into another crate is that crate's.
        for n in named
            .iter()
            .filter(|n| n.ends_with(".rs") && (!n.starts_with("crates/") || n.starts_with(&own)))
        {
            let n = n.trim_start_matches(own.as_str()).trim_start_matches("src/");
            let exists = relative.iter().any(|f| f == n || f.ends_with(&format!("/{n}")))
                || dir.join(n).is_file();
            if !exists {
                problems.push(format!(
                    "crates/{name}: its section names `{n}`, which it does not have"
                ));
            }
        }
    }
    assert!(problems.is_empty(), "docs/ARCHITECTURE.md:\n{}", problems.join("\n"));
}

/// The long flags a command's `--help` lists (but `--help` itself).
fn flags_of(command: &str) -> BTreeSet<String> {
    let (code, help, err) = aviary(&[command, "--help"], &repo());
    assert_eq!(code, 0, "{err}");
    help.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'))
        .filter(|w| w.starts_with("--") && w.len() > 2 && *w != "--help")
        .map(str::to_owned)
        .collect()
}

#[test]
fn every_flag_of_aviary_run_is_documented_with_its_default() {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let works = readme
        .split("## What works today")
        .nth(1)
        .and_then(|rest| rest.split("\n## ").next())
        .expect("README has a \"What works today\" section");
    let missing: Vec<String> =
        flags_of("run").into_iter().filter(|f| !works.contains(f.as_str())).collect();
    assert!(missing.is_empty(), "README's \"What works today\" does not name {missing:?}");
    // The trace's size limit: its default as the binary has it, as the docs say it.
    let (_, help, _) = aviary(&["run", "--help"], &repo());
    assert!(help.contains("[default: 1GiB]"), "{help}");
    for doc in ["README.md", "docs/GUIDE.md", "docs/TRACE.md", "docs/SECURITY.md"] {
        let text = std::fs::read_to_string(repo().join(doc)).unwrap();
        let said = text.lines().any(|l| l.contains("1 GiB"));
        assert!(
            text.contains("--max-trace-size") && said,
            "{doc} documents --max-trace-size and its default, 1 GiB"
        );
    }
}
