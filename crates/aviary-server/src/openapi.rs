//! The API's OpenAPI 3.1 document (docs/openapi.yaml is this, and a test holds it so):
//! the paths, written here beside the routes (`routes.rs`), and the schemas of what they
//! return, generated from the types (`aviary_api::operator`) with schemars, as JSON
//! Schema 2020-12, the dialect of OpenAPI 3.1.

use aviary_api::operator::{Accepted, ApiError, OperatorState};
use schemars::Schema;

use crate::requests::{DroneRequest, LeashRequest, SignalRequest};
use schemars::generate::SchemaSettings;
use serde_json::{json, Map, Value};

/// The document, as data.
pub fn openapi() -> Value {
    let mut generator = SchemaSettings::draft2020_12()
        .with(|s| s.definitions_path = "/components/schemas".into())
        .into_generator();
    let schema = |s: Schema| serde_json::to_value(s).unwrap_or(Value::Null);
    let state = schema(generator.subschema_for::<OperatorState>());
    let bodies = Bodies {
        leash: schema(generator.subschema_for::<LeashRequest>()),
        signal: schema(generator.subschema_for::<SignalRequest>()),
        drone: schema(generator.subschema_for::<DroneRequest>()),
    };
    generator.subschema_for::<Accepted>();
    generator.subschema_for::<ApiError>();
    let schemas: Map<String, Value> = generator.take_definitions(true).into_iter().collect();
    json!({
        "openapi": "3.1.0",
        "info": {
            "title": "Aviary operator API",
            "version": "0.1.0",
            "description": "The state, live events and control of one running mission (`aviary run --serve`). See docs/OPERATOR_API.md. Generated from crates/aviary-server/src/openapi.rs and the types of crates/aviary-api/src/operator.rs: do not edit by hand.",
        },
        "components": {
            "securitySchemes": {
                "token": {
                    "type": "http",
                    "scheme": "bearer",
                    "description": "The token `aviary run --serve` printed at start, as `Authorization: Bearer TOKEN` (any case of `Bearer`); a browser's WebSocket offers it as the subprotocol `aviary.bearer.TOKEN` beside `aviary`. Control calls always need it; the state and the event stream need it when the server is bound beyond loopback. Every request's Host must name the server and a present Origin must be the server's own (403 otherwise); see docs/OPERATOR_API.md#security.",
                }
            },
            "schemas": schemas,
            "responses": responses(),
        },
        "paths": paths(state, bodies),
    })
}

/// The document as docs/openapi.yaml holds it.
pub fn openapi_yaml() -> String {
    serde_norway::to_string(&openapi()).unwrap_or_default()
}

/// The schemas of the control calls' bodies, from their types (`requests.rs`).
struct Bodies {
    leash: Value,
    signal: Value,
    drone: Value,
}

fn error_response(description: &str) -> Value {
    json!({
        "description": description,
        "content": { "application/json": { "schema": { "$ref": "#/components/schemas/ApiError" } } }
    })
}

fn responses() -> Value {
    json!({
        "Done": {
            "description": "Done",
            "content": { "application/json": { "schema": { "$ref": "#/components/schemas/Accepted" } } }
        },
        "BadRequest": error_response("A malformed body, or an argument the mission cannot take"),
        "Unauthorized": error_response("Without the token or with a wrong one"),
        "Forbidden": error_response("Host is not this server, or Origin is another site"),
        "TooLarge": error_response("The body is larger than 64 KiB"),
        "NotJson": error_response("The body was sent without Content-Type: application/json"),
        "Refused": error_response("The mission refused the control"),
    })
}

fn reference(response: &str) -> Value {
    json!({ "$ref": format!("#/components/responses/{response}") })
}

/// The responses of a control call with a JSON body.
fn control_with_body() -> Value {
    json!({
        "200": reference("Done"),
        "400": reference("BadRequest"),
        "401": reference("Unauthorized"),
        "403": reference("Forbidden"),
        "409": reference("Refused"),
        "413": reference("TooLarge"),
        "415": reference("NotJson"),
    })
}

/// The responses of a control call without a body.
fn control_without_body() -> Value {
    json!({
        "200": reference("Done"),
        "401": reference("Unauthorized"),
        "403": reference("Forbidden"),
        "409": reference("Refused"),
    })
}

fn body(schema: Value) -> Value {
    json!({ "required": true, "content": { "application/json": { "schema": schema } } })
}

/// Every route `routes.rs` serves, by path and method.
fn paths(state: Value, bodies: Bodies) -> Value {
    json!({
        "/api/state": {
            "get": {
                "summary": "The mission's state",
                "description": "Needs the token only when the server is bound beyond loopback.",
                "security": [{}, { "token": [] }],
                "responses": {
                    "401": reference("Unauthorized"),
                    "403": reference("Forbidden"),
                    "200": {
                        "description": "The state",
                        "content": { "application/json": { "schema": state } }
                    }
                }
            }
        },
        "/api/events": {
            "get": {
                "summary": "WebSocket: every trace event from now on, one JSON text message each (see trace.schema.json), until mission_end",
                "description": "Needs the token only when the server is bound beyond loopback. The server picks the subprotocol `aviary` when offered.",
                "security": [{}, { "token": [] }],
                "parameters": [
                    {
                        "name": "from",
                        "in": "query",
                        "required": false,
                        "description": "`start`: first every event since the mission started but telemetry (at most the last 100,000; a message `{\"history_dropped\": N}` first when older ones were let go), then the live ones",
                        "schema": { "type": "string", "enum": ["start"] }
                    },
                    {
                        "name": "every",
                        "in": "query",
                        "required": false,
                        "description": "Batches every MS milliseconds (20 to 1000): each message a JSON array of the window's events in order, then each drone's latest telemetry; `{\"dropped\": N}` first when events were let go",
                        "schema": { "type": "integer", "minimum": 20, "maximum": 1000 }
                    }
                ],
                "responses": {
                    "101": { "description": "Switching to WebSocket" },
                    "400": error_response("Not a WebSocket handshake, or an unknown option"),
                    "401": reference("Unauthorized"),
                    "403": reference("Forbidden"),
                }
            }
        },
        "/api/leash": {
            "post": {
                "summary": "A leash on every running activity with a tag",
                "security": [{ "token": [] }],
                "requestBody": body(bodies.leash),
                "responses": control_with_body(),
            }
        },
        "/api/signal": {
            "post": {
                "summary": "Raise a signal the mission declares for the operator",
                "description": "Only a signal the mission declares with `OPERATOR SIGNAL` (the state's `operator_signals`); any other is refused (409) with the signals the mission declares and, on a near miss, the one meant.",
                "security": [{ "token": [] }],
                "requestBody": body(bodies.signal),
                "responses": control_with_body(),
            }
        },
        "/api/drone": {
            "post": {
                "summary": "Steer one drone",
                "description": "`hold` pauses every activity the drone takes part in (an activity of several drones whole) and those that start while it is held; `resume` undoes it (a pause of the whole mission holds on its own). `home` and `land` abort them and take the drone out of the mission, flying it home or landing it where it is; the rest of the fleet carries on. Refused (409, with the reason) for a drone the fleet does not have, a hold of a held drone, a resume of one not held, a drone already taken out (but a drone on its way home can be landed), or a mission that is ending. See docs/OPERATOR_API.md#steering-one-drone.",
                "security": [{ "token": [] }],
                "requestBody": body(bodies.drone),
                "responses": control_with_body(),
            }
        },
        "/api/pause": {
            "post": {
                "summary": "Hold every drone's activity where it is",
                "security": [{ "token": [] }],
                "responses": control_without_body(),
            }
        },
        "/api/resume": {
            "post": {
                "summary": "Go on after a pause",
                "security": [{ "token": [] }],
                "responses": control_without_body(),
            }
        },
        "/api/abort": {
            "post": {
                "summary": "End the mission; the fleet returns home",
                "security": [{ "token": [] }],
                "responses": control_without_body(),
            }
        },
    })
}

/// The schema of `GET /api/state`'s answer, standing alone: the document's components
/// beside a `$ref` to the state's, so that a JSON Schema validator can hold a response to
/// it.
pub fn state_schema(document: &Value) -> Value {
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$ref": document["paths"]["/api/state"]["get"]["responses"]["200"]["content"]["application/json"]["schema"]["$ref"],
        "components": document["components"],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn committed() -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/openapi.yaml")
    }

    /// docs/openapi.yaml is made here, never by hand (`UPDATE_OPENAPI=1` writes it anew).
    #[test]
    fn the_committed_document_is_the_generated_one() {
        let fresh = openapi_yaml();
        assert!(!fresh.is_empty());
        if std::env::var_os("UPDATE_OPENAPI").is_some() {
            std::fs::write(committed(), &fresh).expect("write docs/openapi.yaml");
            return;
        }
        let on_disk = std::fs::read_to_string(committed()).expect("docs/openapi.yaml");
        assert!(
            on_disk == fresh,
            "docs/openapi.yaml is not what crates/aviary-server/src/openapi.rs makes: run `UPDATE_OPENAPI=1 cargo test -p aviary-server openapi` and commit it"
        );
    }

    /// Every route the router serves is a documented path and method, and every
    /// documented one is served.
    #[test]
    fn every_route_is_documented_and_every_documented_path_served() {
        let routes = include_str!("routes.rs");
        let mut served = std::collections::BTreeSet::new();
        for piece in routes.split(".route(\"").skip(1) {
            let (path, rest) = piece.split_once('"').expect("a path");
            let method = rest.trim_start_matches(", ").split('(').next().expect("a method");
            served.insert((path.to_string(), method.to_string()));
        }
        assert!(served.len() >= 8, "{served:?}");
        let document = openapi();
        let mut documented = std::collections::BTreeSet::new();
        for (path, methods) in document["paths"].as_object().expect("paths") {
            for method in methods.as_object().expect("methods").keys() {
                documented.insert((path.clone(), method.clone()));
            }
        }
        assert_eq!(served, documented);
    }

    /// The generated schemas are valid JSON Schema, and the state the server writes fits.
    #[test]
    fn the_state_fits_its_schema() {
        let v = state_validator(&openapi());
        let state = crate::state::MissionState::default().document();
        let value = serde_json::to_value(&state).expect("JSON");
        let errors: Vec<String> = v.iter_errors(&value).map(|e| e.to_string()).collect();
        assert!(errors.is_empty(), "{errors:#?}");
        let mut wrong = value.clone();
        wrong["status"] = json!("maybe");
        assert!(!v.is_valid(&wrong));
    }

    /// What `aviary ctl` sends fits the documented request bodies, and the schema refuses
    /// a body without what it needs.
    #[test]
    fn the_typed_requests_fit_their_schemas() {
        use crate::requests::{Argument, DroneRequest, DroneVerb, LeashRequest, SignalRequest};
        use aviary_syntax::ast::Unit;
        let document = openapi();
        let validator = |path: &str| {
            let schema = json!({
                "$schema": "https://json-schema.org/draft/2020-12/schema",
                "$ref": document["paths"][path]["post"]["requestBody"]["content"]["application/json"]["schema"]["$ref"],
                "components": document["components"],
            });
            jsonschema::validator_for(&schema).expect("a valid schema")
        };
        let args = [
            ("radius".to_string(), Argument::number(200.0, Some(Unit::Metre))),
            ("center".to_string(), Argument::metres(&[100.0, 50.0])),
            ("at".to_string(), Argument::geo(47.45, 13.1, Some(520.0))),
            ("kind".to_string(), Argument::word("Body")),
            ("loud".to_string(), Argument::truth(true)),
        ];
        let leash = LeashRequest {
            activity: Some("FlyCircle-C1".into()),
            capability: None,
            tag: None,
            action: "Widen".into(),
            args: Some(args.into_iter().collect()),
        };
        let signal =
            SignalRequest { name: "Go".into(), args: Some(vec![Argument::number(3.0, None)]) };
        let drone = DroneRequest { drone: "scout1".into(), action: DroneVerb::Home };
        for (path, body) in [
            ("/api/leash", serde_json::to_value(&leash)),
            ("/api/signal", serde_json::to_value(&signal)),
            ("/api/drone", serde_json::to_value(&drone)),
        ] {
            let body = body.expect("JSON");
            let v = validator(path);
            let errors: Vec<String> = v.iter_errors(&body).map(|e| e.to_string()).collect();
            assert!(errors.is_empty(), "{path}: {body}: {errors:#?}");
            assert!(!v.is_valid(&json!({})), "{path} takes {{}}");
        }
        let wrong_unit =
            json!({ "action": "Widen", "args": { "radius": { "number": 2, "unit": "furlong" } } });
        assert!(!validator("/api/leash").is_valid(&wrong_unit));
    }

    fn state_validator(document: &Value) -> jsonschema::Validator {
        jsonschema::validator_for(&state_schema(document)).expect("a valid schema")
    }
}
