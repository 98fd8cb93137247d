//! Answers: every error is `{"error": "..."}` with its status, whoever made it (a
//! handler, an extractor's rejection, the router's 404 and 405, the body limit).

use aviary_api::operator::ApiError;
use axum::body::Body;
use axum::extract::rejection::JsonRejection;
use axum::extract::{FromRequest, Request};
use axum::http::{header, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde_json::Value;

/// A control call's body may be this large; the largest real one is a few hundred bytes.
pub const BODY_LIMIT: usize = 64 * 1024;

/// An error answer, `{"error": "..."}` with its status: the operator API's, and the ground
/// station's own calls'.
pub fn error(status: StatusCode, message: impl Into<String>) -> Response {
    (status, Json(ApiError { error: message.into() })).into_response()
}

/// A JSON object body. Its rejections are answered in JSON, and in words that say what
/// to send (axum's own are plain text).
pub(crate) struct Object(pub serde_json::Map<String, Value>);

impl<S: Send + Sync> FromRequest<S> for Object {
    type Rejection = Response;

    async fn from_request(request: Request, state: &S) -> Result<Self, Response> {
        match Json::<Value>::from_request(request, state).await {
            Ok(Json(Value::Object(o))) => Ok(Object(o)),
            Ok(Json(other)) => Err(error(
                StatusCode::BAD_REQUEST,
                format!("the body must be a JSON object, not {}", kind_of(&other)),
            )),
            Err(JsonRejection::MissingJsonContentType(_)) => Err(error(
                StatusCode::UNSUPPORTED_MEDIA_TYPE,
                "send the body as JSON, with `Content-Type: application/json`",
            )),
            Err(JsonRejection::JsonSyntaxError(e)) => Err(error(
                StatusCode::BAD_REQUEST,
                format!("the body is not JSON: {}", e.body_text()),
            )),
            Err(rejection) if rejection.status() == StatusCode::PAYLOAD_TOO_LARGE => Err(error(
                StatusCode::PAYLOAD_TOO_LARGE,
                format!("the body is larger than {} KiB", BODY_LIMIT / 1024),
            )),
            Err(rejection) => Err(error(rejection.status(), rejection.body_text())),
        }
    }
}

fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// The last word on every answer: an error that is not JSON yet (axum's 404, 405, a
/// failed WebSocket handshake) becomes `{"error": its text}`, keeping status and headers.
pub async fn json_errors(response: Response) -> Response {
    let status = response.status();
    let is_json = response
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes().starts_with(b"application/json"));
    if !(status.is_client_error() || status.is_server_error()) || is_json {
        return response;
    }
    let (mut parts, body) = response.into_parts();
    let text = axum::body::to_bytes(body, BODY_LIMIT)
        .await
        .map(|b| String::from_utf8_lossy(&b).trim().to_string())
        .unwrap_or_default();
    let message = if text.is_empty() {
        status.canonical_reason().unwrap_or("error").to_string()
    } else {
        text
    };
    let body = serde_json::to_string(&ApiError { error: message }).unwrap_or_default();
    parts.headers.insert(header::CONTENT_TYPE, HeaderValue::from_static("application/json"));
    parts.headers.remove(header::CONTENT_LENGTH);
    Response::from_parts(parts, Body::from(body))
}

pub(crate) async fn not_found() -> Response {
    error(StatusCode::NOT_FOUND, "no such call: see docs/OPERATOR_API.md for the calls")
}

pub(crate) async fn method_not_allowed() -> Response {
    error(StatusCode::METHOD_NOT_ALLOWED, "this call takes another method: GET for /api/state and /api/events, POST for the control calls")
}
