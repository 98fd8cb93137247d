//! The station's routes: the page (`/`, `/assets/...`), its own calls under
//! `/api/station/`, and every other `/api/` call handed to the operator API of the
//! flight in progress. Every request passes the gate first (Host and Origin); reads pass
//! `read_token`, changes `token`.

use std::sync::Arc;

use axum::body::Body;
use axum::extract::{DefaultBodyLimit, Path, Query, Request, State};
use axum::http::{header, StatusCode};
use axum::middleware;
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use tower::ServiceExt;

use aviary_check::SourceProvider;

use crate::checking::{self, Text};
use crate::wire::{About, CampaignReport, FlyRefused, Opened};
use crate::{assets, dir, flight, tiles, Mode, Station};
use aviary_api::operator::Accepted;
use aviary_server::error;

/// The largest body a station call takes: a mission and a world of the largest size
/// the station opens, with room for JSON's escapes.
const BODY_LIMIT: usize = 3 * dir::MAX_FILE_BYTES as usize;

pub(crate) fn router(station: Arc<Station>) -> Router {
    let gate = station.gate.clone();
    let reads = Router::new()
        .route("/api/station", get(about))
        .route("/api/station/files", get(files))
        .route("/api/station/file", get(open))
        .route("/api/station/check", post(check))
        .route("/api/station/trace", get(trace))
        .route("/api/station/report", get(report))
        .route("/api/station/world", get(world_map))
        .route_layer(middleware::from_fn_with_state(gate.clone(), aviary_server::read_token));
    let changes = Router::new()
        .route("/api/station/save", post(save))
        .route("/api/station/fly", post(fly))
        .route("/api/station/campaign", post(campaign))
        // The editor's language server: it reads files as `aviary lsp` does, for whoever
        // holds the token (on loopback too), as a save does.
        .route("/api/lsp", get(crate::lsp::socket))
        .route_layer(middleware::from_fn_with_state(gate.clone(), aviary_server::token));
    Router::new()
        .route("/", get(index))
        .route("/assets/{*path}", get(|Path(path): Path<String>| async move { page(&path) }))
        .merge(reads)
        .merge(changes)
        .layer(DefaultBodyLimit::max(BODY_LIMIT))
        .fallback(operator)
        .layer(middleware::from_fn_with_state(gate, aviary_server::same_origin))
        // Every error in JSON, an extractor's rejection too (axum's are plain text).
        .layer(middleware::map_response(aviary_server::json_errors))
        .with_state(station)
}

/// Why a call is refused, and its status: what the helpers below return, made a response
/// only at the end.
struct Refusal(StatusCode, String);

impl IntoResponse for Refusal {
    fn into_response(self) -> Response {
        error(self.0, self.1)
    }
}

/// The page, allowed images from the tile servers of the worlds it may show (and from
/// nowhere else).
async fn index(State(station): State<Arc<Station>>) -> Response {
    let policy =
        tokio::task::spawn_blocking(move || tiles::policy(&tiles::image_sources(&station)))
            .await
            .unwrap_or_else(|_| tiles::policy(&[]));
    served("index.html", &policy)
}

fn page(path: &str) -> Response {
    served(path, &tiles::policy(&[]))
}

/// One of the page's files. The page's own files only: no script, style or image from
/// anywhere else (but a world's tiles), and no page of another site may frame it.
fn served(path: &str, policy: &str) -> Response {
    match assets::find(path) {
        Some(a) => {
            let mut response = (
                [(header::CONTENT_TYPE, a.mime), (header::X_CONTENT_TYPE_OPTIONS, "nosniff")],
                a.bytes,
            )
                .into_response();
            // A tile source is only a scheme and a host (`tiles::source`), so the policy is
            // always a header's text; were it not, the page would load no image but its own.
            let value = header::HeaderValue::from_str(policy)
                .or_else(|_| header::HeaderValue::from_str(&tiles::policy(&[])))
                .unwrap_or(header::HeaderValue::from_static("default-src 'self'"));
            response.headers_mut().insert(header::CONTENT_SECURITY_POLICY, value);
            response
        }
        None => error(StatusCode::NOT_FOUND, format!("the page has no file {path}")),
    }
}

/// Any other call: the operator API of the flight in progress, if there is one.
async fn operator(State(station): State<Arc<Station>>, request: Request<Body>) -> Response {
    if !request.uri().path().starts_with("/api/") {
        return error(StatusCode::NOT_FOUND, "no such page: the station is at /");
    }
    match station.run() {
        Some((router, _)) => match router.oneshot(request).await {
            Ok(response) => response,
            Err(never) => match never {},
        },
        None => error(
            StatusCode::NOT_FOUND,
            "no mission has flown yet: open a mission and its world, check them and fly",
        ),
    }
}

async fn about(State(station): State<Arc<Station>>) -> Json<About> {
    let run = station.run().map(|(_, shown)| shown);
    Json(About {
        mode: station.mode.name(),
        reading_needs_token: station.gate.beyond_loopback(),
        folder: match &station.mode {
            Mode::Folder { folder, .. } => Some(folder.root().display().to_string()),
            Mode::Run | Mode::Replay { .. } => None,
        },
        lsp: station.lsp.is_some(),
        run,
        map: station.map(),
    })
}

fn folder(station: &Station) -> Result<(&dir::Folder, &crate::FilesFor), Refusal> {
    match &station.mode {
        Mode::Folder { folder, files } => Ok((folder, files)),
        _ => Err(Refusal(
            StatusCode::NOT_FOUND,
            "this station serves one run, not a folder: start it with `aviary gcs DIR`".into(),
        )),
    }
}

async fn files(State(station): State<Arc<Station>>) -> Response {
    match folder(&station) {
        Ok((folder, _)) => Json(folder.list()).into_response(),
        Err(refusal) => refusal.into_response(),
    }
}

#[derive(serde::Deserialize)]
struct Named {
    path: String,
}

async fn open(State(station): State<Arc<Station>>, Query(named): Query<Named>) -> Response {
    let (folder, _) = match folder(&station) {
        Ok(f) => f,
        Err(refusal) => return refusal.into_response(),
    };
    match folder.read(&named.path) {
        Ok(text) => Json(Opened { path: named.path, text }).into_response(),
        Err(why) => error(StatusCode::NOT_FOUND, why),
    }
}

async fn save(State(station): State<Arc<Station>>, body: Json<Text>) -> Response {
    let (folder, _) = match folder(&station) {
        Ok(f) => f,
        Err(refusal) => return refusal.into_response(),
    };
    match folder.save(&body.path, &body.text) {
        Ok(()) => Json(Accepted::YES).into_response(),
        Err(why) => error(StatusCode::CONFLICT, why),
    }
}

#[derive(serde::Deserialize)]
struct Pair {
    mission: Text,
    world: Text,
}

/// The checks of `pair`, with the files it `USE`s read from the station's folder.
/// And the provider it read them with, for a flight to read them again.
fn checked(
    station: &Station,
    mission: &Text,
    world: &Text,
) -> Result<(checking::Report, Box<dyn SourceProvider + Send>), Refusal> {
    let (folder, files_for) = folder(station)?;
    // Where the page would save them: the mission's folder is where its `USE`s are read.
    let place = |path: &str| {
        folder.place(path, dir::Access::Save).map_err(|w| Refusal(StatusCode::BAD_REQUEST, w))
    };
    let path = place(&mission.path)?;
    // No world chosen (a mission with none beside it): checked without one, as
    // `aviary check` does, and it cannot fly.
    let world = (!world.path.is_empty()).then_some(world);
    if let Some(world) = world {
        place(&world.path)?;
    }
    let files = files_for(&path).map_err(|w| Refusal(StatusCode::CONFLICT, w))?;
    let files: Box<dyn SourceProvider + Send> =
        Box::new(checking::InFolder { root: folder.root().to_path_buf(), files });
    Ok((checking::check(mission, world, &*files), files))
}

async fn check(State(station): State<Arc<Station>>, Json(pair): Json<Pair>) -> Response {
    // The checker recurses: it runs where its stack is (`aviary_check::STACK`).
    let work = move || match checked(&station, &pair.mission, &pair.world) {
        Ok((report, _)) => Json(report.json).into_response(),
        Err(refusal) => refusal.into_response(),
    };
    on_a_deep_stack(work).await
}

/// The checks of `mission` and `world` when the mission may fly (the fly and the
/// campaign routes); else the answer that refuses it, with the check for the page.
fn flyable(
    station: &Station,
    mission: &Text,
    world: &Text,
) -> Result<(checking::Report, Box<dyn SourceProvider + Send>), Box<Response>> {
    let (report, files) =
        checked(station, mission, world).map_err(|r| Box::new(r.into_response()))?;
    if !report.flyable {
        let why = if world.path.is_empty() {
            "the mission cannot fly without a world: choose one"
        } else {
            "the mission cannot fly: fix the errors the check shows"
        };
        let body = FlyRefused { error: why, check: report.json };
        return Err(Box::new((StatusCode::CONFLICT, Json(body)).into_response()));
    }
    Ok((report, files))
}

async fn fly(
    State(station): State<Arc<Station>>,
    Json(request): Json<flight::Request>,
) -> Response {
    let work = move || {
        let (report, files) = match flyable(&station, &request.mission, &request.world) {
            Ok(checked) => checked,
            Err(refused) => return *refused,
        };
        let (folder, _) = match folder(&station) {
            Ok(f) => f,
            Err(refusal) => return refusal.into_response(),
        };
        let tree = report.json["tree"].clone();
        let trace = trace_for(folder, &request.mission.path);
        match flight::start(station.clone(), request, tree, files, trace) {
            Ok(()) => Json(Accepted::YES).into_response(),
            Err(why) => error(StatusCode::CONFLICT, why),
        }
    };
    on_a_deep_stack(work).await
}

#[derive(serde::Deserialize)]
struct CampaignRequest {
    mission: Text,
    world: Text,
    runs: u64,
    #[serde(default)]
    seed: u64,
}

/// A campaign on the mission and world the page has open (`aviary test`, on every core):
/// `{text, html}`, the report as `aviary test` prints it and as its `--html` page.
async fn campaign(
    State(station): State<Arc<Station>>,
    Json(request): Json<CampaignRequest>,
) -> Response {
    let work = move || {
        let files = match flyable(&station, &request.mission, &request.world) {
            Ok((_, files)) => files,
            Err(refused) => return *refused,
        };
        let flown = crate::campaign::fly(
            &request.mission,
            &request.world,
            &*files,
            request.runs,
            request.seed,
        );
        match flown {
            Ok((text, html)) => Json(CampaignReport { text, html }).into_response(),
            Err(why) => error(StatusCode::CONFLICT, why),
        }
    };
    on_a_deep_stack(work).await
}

#[derive(serde::Deserialize)]
struct Recorded {
    /// A trace of the station's folder (`traces/NAME-TIME.jsonl`); none in a replay.
    path: Option<String>,
    /// The world to draw it on, in the folder (a report's map); by default the one the
    /// trace names, when the folder has it as it was.
    world: Option<String>,
}

/// The recorded trace a replay plays, as its file has it: JSON Lines. `aviary replay`
/// serves its one trace; `aviary gcs` any trace of its folder, checked line by line
/// first, as `aviary replay` checks its own.
async fn trace(State(station): State<Arc<Station>>, Query(asked): Query<Recorded>) -> Response {
    let (name, text) = match (&station.mode, asked.path) {
        (Mode::Replay { name, trace }, _) => (name.clone(), trace.clone()),
        (Mode::Folder { folder, .. }, Some(path)) => {
            let checked = trace_text(folder, &path).and_then(|text| {
                crate::replay::read(&path, text.into_bytes())
                    .map_err(|why| Refusal(StatusCode::CONFLICT, why))
            });
            match checked {
                Ok(text) => (path, text),
                Err(refusal) => return refusal.into_response(),
            }
        }
        (Mode::Folder { .. }, None) => {
            return error(StatusCode::BAD_REQUEST, "name the trace: ?path=traces/NAME.jsonl")
        }
        (Mode::Run, _) => {
            return error(
                StatusCode::NOT_FOUND,
                "this station replays no trace: start it with `aviary replay TRACE.jsonl`",
            )
        }
    };
    (
        [
            (header::CONTENT_TYPE, "application/x-ndjson".to_string()),
            (header::HeaderName::from_static("x-aviary-trace"), name),
        ],
        text,
    )
        .into_response()
}

/// A trace of the folder, as its file holds it. Its lines are read as events by the one
/// who uses them (a replay checks them all first; a report reads each once).
fn trace_text(folder: &dir::Folder, path: &str) -> Result<String, Refusal> {
    if dir::FileKind::of(path) != Some(dir::FileKind::Trace) {
        return Err(Refusal(
            StatusCode::BAD_REQUEST,
            format!("`{path}` is not a trace (.jsonl): name one of the folder's traces"),
        ));
    }
    folder.read(path).map_err(|why| Refusal(StatusCode::NOT_FOUND, why))
}

/// The report of a trace of the folder (`aviary report`'s HTML), on the world named, as a
/// file to save: `GET /api/station/report?path=traces/X.jsonl&world=W.toml`.
async fn report(State(station): State<Arc<Station>>, Query(asked): Query<Recorded>) -> Response {
    let work = move || {
        let (folder, files) = match folder(&station) {
            Ok(f) => f,
            Err(refusal) => return refusal.into_response(),
        };
        let Some(path) = asked.path else {
            return error(StatusCode::BAD_REQUEST, "name the trace: ?path=traces/NAME.jsonl");
        };
        let text = match trace_text(folder, &path) {
            Ok(text) => text,
            Err(refusal) => return refusal.into_response(),
        };
        let world = match world_of_trace(folder, files, &text, asked.world.as_deref()) {
            Ok(world) => world,
            Err(refusal) => return refusal.into_response(),
        };
        match crate::report::render(&path, text.into_bytes(), world.as_ref()) {
            Ok(html) => {
                // A name a header can carry whatever the trace is called.
                let stem: String = std::path::Path::new(&path)
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
                    .chars()
                    .filter(|c| c.is_ascii_alphanumeric() || "-_.".contains(*c))
                    .collect();
                let stem = if stem.is_empty() { "report".to_string() } else { stem };
                (
                    [
                        (header::CONTENT_TYPE, "text/html; charset=utf-8".to_string()),
                        (
                            header::CONTENT_DISPOSITION,
                            format!("attachment; filename=\"{stem}.html\""),
                        ),
                        // The report is a document of its own, with no script.
                        (
                            header::CONTENT_SECURITY_POLICY,
                            "default-src 'none'; style-src 'unsafe-inline'; img-src data:".into(),
                        ),
                    ],
                    html,
                )
                    .into_response()
            }
            Err(why) => error(StatusCode::CONFLICT, why),
        }
    };
    on_a_deep_stack(work).await
}

#[derive(serde::Deserialize)]
struct WorldAsked {
    /// A world of the folder.
    path: Option<String>,
    /// A trace of the folder: the world it was flown in.
    trace: Option<String>,
}

/// What the map shows of a world of the folder: `GET /api/station/world?path=W.toml`, or
/// the world a trace of the folder was flown in, `?trace=traces/X.jsonl` (for its replay):
/// `null` when the trace names none, refused when the folder's copy is not the one flown.
async fn world_map(
    State(station): State<Arc<Station>>,
    Query(asked): Query<WorldAsked>,
) -> Response {
    let (folder, files) = match folder(&station) {
        Ok(f) => f,
        Err(refusal) => return refusal.into_response(),
    };
    let world = match (asked.path, asked.trace) {
        (Some(path), None) => world_of(folder, files, &path).map(Some),
        (None, Some(trace)) => trace_text(folder, &trace).and_then(|text| {
            let stamp = crate::replay::world_stamp(text.as_bytes());
            match stamp {
                Some(stamp) => world_of_trace(folder, files, &text, Some(&stamp.file)),
                None => Ok(None),
            }
        }),
        _ => Err(Refusal(
            StatusCode::BAD_REQUEST,
            "name a world (?path=W.toml) or a trace (?trace=traces/X.jsonl)".into(),
        )),
    };
    match world {
        Ok(world) => Json(world.as_ref().map(checking::map_of)).into_response(),
        Err(refusal) => refusal.into_response(),
    }
}

/// The world to draw a trace of the folder on: `given`, unless the trace names another
/// (refused, with why); with none given, the one it names when the folder has it as it
/// was flown, else none.
fn world_of_trace(
    folder: &dir::Folder,
    files: &crate::FilesFor,
    trace: &str,
    given: Option<&str>,
) -> Result<Option<aviary_world::World>, Refusal> {
    let stamp = crate::replay::world_stamp(trace.as_bytes());
    let path = match (given, &stamp) {
        (Some(path), _) => path.to_string(),
        (None, Some(stamp)) => stamp.file.to_string(),
        (None, None) => return Ok(None),
    };
    if dir::FileKind::of(&path) != Some(dir::FileKind::World) {
        return Err(Refusal(StatusCode::BAD_REQUEST, format!("`{path}` is not a world (.toml)")));
    }
    let text = match folder.read(&path) {
        Ok(text) => text,
        Err(_) if given.is_none() => return Ok(None),
        Err(why) => return Err(Refusal(StatusCode::NOT_FOUND, why)),
    };
    if let Some(why) = stamp.as_ref().and_then(|s| s.refuses(&path, text.as_bytes())) {
        return match given {
            Some(_) => Err(Refusal(StatusCode::CONFLICT, why)),
            None => Ok(None),
        };
    }
    world_of(folder, files, &path).map(Some)
}

/// A world of the folder, read; refused with its first error.
/// Its `[imports]` are read beside it by the command line's provider, as for a flight.
fn world_of(
    folder: &dir::Folder,
    files: &crate::FilesFor,
    path: &str,
) -> Result<aviary_world::World, Refusal> {
    if dir::FileKind::of(path) != Some(dir::FileKind::World) {
        return Err(Refusal(StatusCode::BAD_REQUEST, format!("`{path}` is not a world (.toml)")));
    }
    let text = folder.read(path).map_err(|why| Refusal(StatusCode::NOT_FOUND, why))?;
    let full = folder.root().join(path);
    let provider: Box<dyn SourceProvider> = match files(&full) {
        Ok(p) => p,
        Err(_) => Box::new(aviary_check::NoFiles),
    };
    let mut sources = aviary_diagnostics::SourceMap::new();
    let name = full.display().to_string();
    let read = aviary_check::read_world(
        &mut sources,
        &name,
        std::borrow::Cow::Owned(text.into_bytes()),
        &*provider,
    );
    match (read.world, read.diagnostics) {
        (Some(world), _) => Ok(world),
        (None, diagnostics) => {
            let first = diagnostics.first().map(|d| d.message.clone()).unwrap_or_default();
            Err(Refusal(StatusCode::CONFLICT, format!("{path} has errors: {first}")))
        }
    }
}

/// A new trace file for a flight of `mission`: `traces/NAME-TIME.jsonl` in the folder,
/// the time in UTC. Only its name: the flight makes it (`Folder::record`).
fn trace_for(folder: &dir::Folder, mission: &str) -> flight::Trace {
    let stem = std::path::Path::new(mission)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mission".into());
    let now = humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string();
    let stamp: String = now.chars().map(|c| if c == ':' { '-' } else { c }).collect();
    let mut shown = format!("traces/{stem}-{stamp}.jsonl");
    let mut n = 1;
    // A link counts as a file there, whether or not it leads anywhere.
    while folder.root().join(&shown).symlink_metadata().is_ok() {
        n += 1;
        shown = format!("traces/{stem}-{stamp}-{n}.jsonl");
    }
    flight::Trace { shown }
}

/// Runs `work` on a thread with the checker's stack, and waits for it without holding
/// the server's thread.
async fn on_a_deep_stack(work: impl FnOnce() -> Response + Send + 'static) -> Response {
    let (tx, rx) = tokio::sync::oneshot::channel();
    let spawned = std::thread::Builder::new()
        .name("aviary-station-check".into())
        .stack_size(aviary_check::STACK)
        .spawn(move || {
            let _ = tx.send(work());
        });
    if let Err(e) = spawned {
        return error(StatusCode::SERVICE_UNAVAILABLE, format!("cannot check now: {e}"));
    }
    rx.await.unwrap_or_else(|_| error(StatusCode::INTERNAL_SERVER_ERROR, "the check stopped"))
}
