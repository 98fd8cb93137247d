//! docs/trace.schema.json is made from the trace's types (`aviary_api::trace::schema`),
//! never by hand: this test holds the file to them (`UPDATE_SCHEMA=1` writes it anew),
//! and holds every event the types can write to the schema, and the schema to refuse
//! what they cannot.

use std::path::Path;

fn committed() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/trace.schema.json")
}

fn generated() -> String {
    let text = serde_json::to_string_pretty(&aviary_api::trace::schema()).expect("JSON");
    format!("{text}\n")
}

#[test]
fn the_committed_schema_is_the_generated_one() {
    let fresh = generated();
    if std::env::var_os("UPDATE_SCHEMA").is_some() {
        std::fs::write(committed(), &fresh).expect("write docs/trace.schema.json");
        return;
    }
    let on_disk = std::fs::read_to_string(committed()).expect("docs/trace.schema.json");
    assert!(
        on_disk == fresh,
        "docs/trace.schema.json is not what the trace's types make: run `UPDATE_SCHEMA=1 cargo test -p aviary-api --test schema` and commit it"
    );
}

fn validator() -> jsonschema::Validator {
    jsonschema::validator_for(&aviary_api::trace::schema()).expect("a valid schema")
}

/// Every kind of event, as the engine writes it (docs/TRACE.md's tour, which another
/// test keeps to the engine's own), fits.
#[test]
fn every_event_the_types_write_fits() {
    let v = validator();
    let tour = include_str!("../src/trace/examples.jsonl");
    let mut kinds = std::collections::BTreeSet::new();
    for (n, line) in tour.lines().enumerate() {
        let value: serde_json::Value = serde_json::from_str(line).expect("JSON");
        // Read as the type, then written again: what the types write.
        let record: aviary_api::trace::Record = serde_json::from_str(line).expect("a record");
        let written = serde_json::to_value(&record).expect("JSON");
        for shown in [&value, &written] {
            let errors: Vec<String> = v.iter_errors(shown).map(|e| e.to_string()).collect();
            assert!(errors.is_empty(), "line {}: {line}\n{errors:#?}", n + 1);
        }
        kinds.insert(value["event"].as_str().unwrap_or("").to_string());
    }
    assert!(kinds.len() >= 15, "{kinds:?}");
}

#[test]
fn a_field_or_an_event_the_types_do_not_have_is_refused() {
    let v = validator();
    let ok = serde_json::json!({ "t": 1.0, "event": "block_start", "block": "B" });
    assert!(v.is_valid(&ok));
    let more =
        serde_json::json!({ "t": 1.0, "event": "block_start", "block": "B", "colour": "red" });
    assert!(!v.is_valid(&more), "an unknown field");
    let unknown = serde_json::json!({ "t": 1.0, "event": "block_paused", "block": "B" });
    assert!(!v.is_valid(&unknown), "an unknown event");
    let missing = serde_json::json!({ "t": 1.0, "event": "block_end", "block": "B" });
    assert!(!v.is_valid(&missing), "block_end without its status");
    let wrong =
        serde_json::json!({ "t": 1.0, "event": "block_end", "block": "B", "status": "maybe" });
    assert!(!v.is_valid(&wrong), "a status that is none");
}
