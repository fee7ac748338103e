//! The studio's HTTP server (axum) over its library calls ([`calls`]),
//! in a crate of its own so that no other scene
//! compiles a web server: one static page with its script and
//! style (served from the binary: no network, no CDN) and a JSON API.
//!
//! | route | answer |
//! |---|---|
//! | `GET /api/models` | every model with its parameters ([`calls::models`]) |
//! | `GET /api/schema` | every declared analysis's settings: name, type, default, range, help, and the studio's interactive defaults |
//! | `GET /api/models/{name}/derivations` | its derivations as MathML |
//! | `POST /api/orbit` | an orbit of the period map, streamed as NDJSON lines |
//! | `POST /api/chaos` | the FLI map of a view at growing resolutions, NDJSON |
//! | `POST /api/overlay` | level sets of H̄ and the equilibria, JSON |
//! | `POST /api/manifolds` | W^u, W^s of the hyperbolic point, JSON |
//! | `POST /api/continuation` | the periodic orbit nearest a seed continued in a parameter, JSON |
//! | `POST /api/section` | a Poincaré section orbit at a fixed energy from a seed, JSON |
//! | `POST /api/section_map` | the MEGNO map of that section, JSON |
//! | `POST /api/basins` | the basins of attraction of a view at growing resolutions, NDJSON |
//! | `POST /api/mechanism` | the mechanism's frames from a seed, JSON |
//! | `POST /api/steady_motion` | a constrained model's steady motion linearised (the `steady_motion` declaration), JSON |
//!
//! The numerics run on blocking threads; a streamed answer stops computing
//! when the page drops it (a superseded request). Every error is a JSON
//! `{"error": …}` with a 4xx status, or an `{"error": …}` line ending a
//! stream; a panic in one request is caught and reported, and the server
//! goes on.

use axum::body::{Body, Bytes};
use axum::extract::{Path, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post, MethodRouter};
use axum::Router;
use calls::{self as studio, StudioError};
use mechlab_runtime::analysis::period_map::PeriodMapError;
use mechlab_runtime::classify::{Classify, ErrorClass};
use mechlab_runtime::registry::Catalog;
use mechlab_scenes::scene::{knob, Scene, SceneError, ValueProblem};
use serde::Serialize;
use std::net::SocketAddr;

pub mod calls;

const PAGE: &str = include_str!("page/index.html");
const SCRIPT: &str = include_str!("page/studio.js");
const STYLE: &str = include_str!("page/studio.css");

/// Why one request failed: a 4xx or 5xx answer with `{"error": message}`.
#[derive(Debug, thiserror::Error)]
pub enum ApiError {
    #[error(transparent)]
    Studio(#[from] StudioError),
    #[error("the request is not valid JSON for this route: {0}")]
    Json(#[from] serde_json::Error),
    #[error("no route {path}")]
    NotFound { path: String },
    /// A request's work panicked (a bug): its message; the server goes on.
    #[error("internal error (the server goes on): the request's work panicked: {message}")]
    Panicked { message: String },
    /// The blocking task that ran the request could not be joined.
    #[error("internal error (the server goes on): {0}")]
    Join(#[from] tokio::task::JoinError),
}

impl ApiError {
    /// The status of the library's class of the error (`classify`): a bad
    /// value 400, a refusal or an integration failure 422; an unknown
    /// model or route 404.
    fn status(&self) -> StatusCode {
        match self {
            ApiError::Studio(StudioError::UnknownModel(_)) | ApiError::NotFound { .. } => {
                StatusCode::NOT_FOUND
            }
            ApiError::Studio(e) => match e.class() {
                ErrorClass::BadValue | ErrorClass::Stopped => StatusCode::BAD_REQUEST,
                ErrorClass::Refused | ErrorClass::Integration => StatusCode::UNPROCESSABLE_ENTITY,
            },
            ApiError::Json(_) => StatusCode::BAD_REQUEST,
            ApiError::Panicked { .. } | ApiError::Join(_) => StatusCode::INTERNAL_SERVER_ERROR,
        }
    }
}

#[derive(Serialize)]
struct ErrorBody {
    error: String,
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let body = ErrorBody {
            error: self.to_string(),
        };
        (self.status(), axum::Json(body)).into_response()
    }
}

/// The studio's routes, serving the models of `catalog`.
pub fn router(catalog: Catalog) -> Router {
    Router::new()
        .route(
            "/",
            get(|| async { asset("text/html; charset=utf-8", PAGE) }),
        )
        .route(
            "/studio.js",
            get(|| async { asset("text/javascript; charset=utf-8", SCRIPT) }),
        )
        .route(
            "/studio.css",
            get(|| async { asset("text/css; charset=utf-8", STYLE) }),
        )
        .route(
            "/api/models",
            get(move || async move { axum::Json(studio::models(catalog)) }),
        )
        .route(
            "/api/schema",
            get(|| async { axum::Json(studio::schemas()) }),
        )
        .route("/api/models/{name}/derivations", get(derivations))
        .route("/api/orbit", post(orbit))
        .route("/api/chaos", post(chaos))
        .route("/api/overlay", json_route(studio::overlay))
        .route("/api/manifolds", json_route(studio::manifolds))
        .route("/api/continuation", json_route(studio::continuation))
        .route("/api/section", json_route(studio::section))
        .route("/api/section_map", json_route(studio::section_map))
        .route("/api/mechanism", json_route(studio::mechanism))
        .route("/api/steady_motion", json_route(studio::steady_motion))
        .route("/api/basins", post(basins))
        .fallback(|uri: axum::http::Uri| async move {
            ApiError::NotFound {
                path: uri.to_string(),
            }
        })
        .with_state(catalog)
}

fn asset(content_type: &'static str, text: &'static str) -> Response {
    ([(header::CONTENT_TYPE, content_type)], text).into_response()
}

/// The scene `name` serving `catalog` (`about` says which models): reads
/// its knob `port` (default `default_port`, 0: any free port), then
/// [`run`]s the server.
pub fn scene(
    name: &'static str,
    catalog: Catalog,
    about: &'static str,
    default_port: &'static str,
) -> Result<(), SceneError> {
    let scene = Scene::from_args(
        name,
        about,
        &[knob(
            "port",
            default_port,
            "the port to listen on (0: any free port)",
        )],
    )?;
    let port = scene
        .text("port")
        .parse::<u16>()
        .map_err(|_| SceneError::BadValue {
            name: "port".into(),
            value: scene.text("port").into(),
            reason: ValueProblem::Requirement("a port is a whole number from 0 to 65535"),
        })?;
    run(catalog, port)
}

/// Serves the studio on 127.0.0.1:`port` (0: any free port) until Ctrl-C,
/// printing its address once listening.
pub fn run(catalog: Catalog, port: u16) -> Result<(), SceneError> {
    let address = SocketAddr::from(([127, 0, 0, 1], port));
    let failed = |source| SceneError::Serve { address, source };
    // Requests run their analyses on the runtime's blocking threads.
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .thread_stack_size(mechlab_scenes::scene::STACK_BYTES)
        .enable_all()
        .build()
        .map_err(failed)?;
    runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind(address)
            .await
            .map_err(failed)?;
        println!(
            "studio: http://{}/  (Ctrl-C stops it)",
            listener.local_addr().map_err(failed)?
        );
        axum::serve(listener, router(catalog))
            .with_graceful_shutdown(async {
                // Without a signal handler the server runs until killed.
                let _ = tokio::signal::ctrl_c().await;
            })
            .await
            .map_err(failed)
    })
}

async fn derivations(
    State(catalog): State<Catalog>,
    Path(name): Path<String>,
) -> Result<Response, ApiError> {
    Ok(axum::Json(studio::derivations(catalog, &name)?).into_response())
}

async fn orbit(State(catalog): State<Catalog>, body: Bytes) -> Result<Response, ApiError> {
    let request: studio::AnalysisRequest = serde_json::from_slice(&body)?;
    studio::orbit_check(catalog, &request)?;
    Ok(stream(move |send, _| {
        let end = studio::orbit(catalog, &request, &mut |chunk| send(&chunk))?;
        send(&Ended { end });
        Ok(())
    }))
}

async fn chaos(State(catalog): State<Catalog>, body: Bytes) -> Result<Response, ApiError> {
    let request: studio::LevelsRequest = serde_json::from_slice(&body)?;
    studio::chaos_levels(catalog, &request)?;
    Ok(stream(move |send, listening| {
        studio::chaos(catalog, &request, &mut |level| send(&level), listening)
    }))
}

async fn basins(State(catalog): State<Catalog>, body: Bytes) -> Result<Response, ApiError> {
    let request: studio::LevelsRequest = serde_json::from_slice(&body)?;
    studio::basins_levels(catalog, &request)?;
    Ok(stream(move |send, _| {
        studio::basins(catalog, &request, &mut |level| send(&level))
    }))
}

/// A route that answers one JSON request with one JSON answer, computed
/// on a blocking thread.
fn json_route<Q, A>(answer: fn(Catalog, &Q) -> Result<A, StudioError>) -> MethodRouter<Catalog>
where
    Q: serde::de::DeserializeOwned + Send + 'static,
    A: Serialize + Send + 'static,
{
    post(
        move |State(catalog): State<Catalog>, body: Bytes| async move {
            let request: Q = serde_json::from_slice(&body)?;
            let answer =
                blocking(move || answer(catalog, &request).map_err(ApiError::from)).await?;
            Ok::<_, ApiError>(axum::Json(answer).into_response())
        },
    )
}

#[derive(Serialize)]
struct Ended {
    end: studio::OrbitEnd,
}

/// Runs `work` on a blocking thread, catching a panic as an internal error.
async fn blocking<R: Send + 'static>(
    work: impl FnOnce() -> Result<R, ApiError> + Send + 'static,
) -> Result<R, ApiError> {
    tokio::task::spawn_blocking(move || {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(work))
            .unwrap_or_else(|panic| Err(panicked(&panic)))
    })
    .await?
}

/// The error of a panic, with its message (a panic's payload is its text).
fn panicked(panic: &Box<dyn std::any::Any + Send>) -> ApiError {
    let message = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".into());
    ApiError::Panicked { message }
}

/// An NDJSON answer: `work` runs on a blocking thread and sends lines with
/// `send`, which returns false once the page has dropped the answer; then
/// `listening` (callable from any thread) says false too, and `work` should
/// stop. An error or a panic ends the stream with an `{"error": …}` line.
fn stream(
    work: impl FnOnce(
            &mut dyn FnMut(&dyn erased::Line) -> bool,
            &(dyn Fn() -> bool + Sync),
        ) -> Result<(), StudioError>
        + Send
        + 'static,
) -> Response {
    let (tx, rx) = tokio::sync::mpsc::channel::<Bytes>(8);
    let probe = tx.clone();
    tokio::task::spawn_blocking(move || {
        let listening = move || !probe.is_closed();
        let mut send = |line: &dyn erased::Line| tx.blocking_send(line.ndjson()).is_ok();
        let outcome =
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(&mut send, &listening)));
        let error = match outcome {
            Ok(Ok(()) | Err(StudioError::PeriodMap(PeriodMapError::Cancelled))) => return,
            Ok(Err(e)) => ApiError::Studio(e),
            Err(panic) => panicked(&panic),
        };
        send(&ErrorBody {
            error: error.to_string(),
        });
    });
    let lines = futures_util::stream::unfold(rx, |mut rx| async move {
        rx.recv()
            .await
            .map(|line| (Ok::<_, std::convert::Infallible>(line), rx))
    });
    (
        [(header::CONTENT_TYPE, "application/x-ndjson")],
        Body::from_stream(lines),
    )
        .into_response()
}

mod erased {
    /// A value sent as one NDJSON line (object-safe `Serialize`).
    pub trait Line {
        fn ndjson(&self) -> axum::body::Bytes;
    }
    impl<T: serde::Serialize> Line for T {
        fn ndjson(&self) -> axum::body::Bytes {
            let mut bytes = serde_json::to_vec(self).unwrap_or_else(|e| {
                format!("{{\"error\":\"cannot encode an answer: {e}\"}}").into_bytes()
            });
            bytes.push(b'\n');
            bytes.into()
        }
    }
}
