//! Each benchmark runs on small sizes and writes its report as docs/BENCHMARKS.md shows it;
//! wrong arguments are a usage error, before any work.

use aviary_bench::{Emit, Error, Shape};

fn report(ran: impl FnOnce(&mut Vec<u8>) -> Result<(), Error>) -> String {
    let mut out = Vec::new();
    if let Err(e) = ran(&mut out) {
        panic!("{e:?}; wrote:\n{}", String::from_utf8_lossy(&out));
    }
    String::from_utf8(out).expect("UTF-8")
}

/// The stages' names, in order, from a `stages: ...` line.
fn stages(report: &str) -> Vec<&str> {
    let line = report.lines().find_map(|l| l.strip_prefix("stages: ")).expect("a stages line");
    let line = line.split(';').next().unwrap_or("");
    line.split(", ").map(|s| s.split(" 0.").next().unwrap_or(s).trim_end()).collect()
}

const PIPELINE: [&str; 8] = [
    "generate",
    "generate",
    "world",
    "check",
    "compile",
    "free front end",
    "sim start",
    "engine + sim",
];

#[test]
fn w_flies_through_the_pipeline_and_checks_its_trace() {
    let text = report(|out| aviary_bench::w(40, 3, Emit::Nothing, true, out));
    assert!(
        text.starts_with("aviary W N=40 K=3 done=40 handled=40 sum=780 steps=120 ok=true elapsed="),
        "{text}"
    );
    assert_eq!(stages(&text), PIPELINE, "{text}");
}

#[test]
fn the_swarm_flies_through_the_pipeline_and_handles_every_find() {
    let text = report(|out| aviary_bench::swarm(4, Emit::Nothing, out));
    assert!(text.starts_with("aviary swarm drones=4 status=ok simulated="), "{text}");
    assert!(text.contains(" ok=true; whole process "), "{text}");
    assert_eq!(stages(&text), PIPELINE, "{text}");
}

#[test]
fn emit_writes_the_mission_or_the_world_instead() {
    let mission = report(|out| aviary_bench::w(5, 2, Emit::Mission, false, out));
    assert_eq!(mission, aviary_bench::generate::w_mission(2));
    let world = report(|out| aviary_bench::swarm(3, Emit::World, out));
    assert_eq!(world, aviary_bench::generate::swarm_world(3));
    let both = report(|out| aviary_bench::front(Shape::Chain, 3, 1, Emit::of(true, true), out));
    assert_eq!(both, aviary_bench::generate::chain_mission(3));
}

#[test]
fn parse_and_front_report_each_run_and_the_median() {
    let text = report(|out| aviary_bench::parse(0.05, 1, out));
    assert!(
        text.contains("\nrun 1: parse ") && text.contains("\nmedian of 1 run(s) over "),
        "{text}"
    );
    assert!(!text.contains("note: the check reports"), "{text}");
    let text = report(|out| aviary_bench::front(Shape::Sequential, 50, 2, Emit::Nothing, out));
    assert!(text.starts_with("generated a mission of 50 statements in one SEQUENTIAL block: "));
    assert!(text.contains("\nrun 2: parse + check ") && text.contains(" 0 error(s), "), "{text}");
    assert!(text.contains("\nmedian of 2 run(s) over "), "{text}");
}

#[test]
fn wrong_sizes_are_usage_errors() {
    let mut out = Vec::new();
    assert!(matches!(aviary_bench::w(0, 3, Emit::Nothing, false, &mut out), Err(Error::Usage(_))));
    assert!(matches!(aviary_bench::swarm(0, Emit::Mission, &mut out), Err(Error::Usage(_))));
    assert!(matches!(aviary_bench::parse(0.0, 1, &mut out), Err(Error::Usage(_))));
    let realistic = aviary_bench::front(Shape::Realistic, 5000, 1, Emit::Nothing, &mut out);
    assert!(matches!(realistic, Err(Error::Usage(_))));
    assert!(out.is_empty());
}

#[test]
fn a_campaign_of_the_papers_mission_flies_every_seed() {
    let text = report(|out| aviary_bench::campaign(4, 2, None, out));
    assert!(
        text.starts_with("aviary campaign mission=Search_and_Rescue runs=4 jobs=2 wall="),
        "{text}"
    );
    assert!(text.contains(" succeeded=4 "), "{text}");
    let mut out = Vec::new();
    assert!(matches!(aviary_bench::campaign(0, 2, None, &mut out), Err(Error::Usage(_))));
    assert!(matches!(aviary_bench::campaign(3, 0, None, &mut out), Err(Error::Usage(_))));
}
