//! The web server: the page (embedded, no build step, no CDN) at `/`, and one
//! WebSocket at `/ws` over which the page sends its controls and the server
//! sends a [`crate::Frame`] every tick. The replay viewer at `/replay` reads a
//! record chosen in the browser (a study's, `palc learn --record`'s) and shows it
//! lane change by lane change; it sends nothing to the server.
//!
//! One tab drives a session: a second connection is refused (HTTP 409) while
//! one is open. Every message is checked ([`crate::control::Inbox`]); a bad one
//! gets an error frame and the session goes on. Ticks run only while the page is
//! connected, and a lost connection pauses the lane change in progress.

use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use axum::Router;
use axum::extract::State;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::http::{StatusCode, header};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::get;
use serde_json::json;
use tokio::net::TcpListener;

use crate::DriveError;
use crate::control::{Control, Inbox, MAX_MESSAGE_BYTES, Request};
use crate::protocol::Pace;
use crate::session::Session;

const INDEX_HTML: &str = include_str!("page/index.html");
const PAGE_JS: &str = include_str!("page/page.js");
const PAGE_CSS: &str = include_str!("page/page.css");
const REPLAY_HTML: &str = include_str!("page/replay.html");
const REPLAY_JS: &str = include_str!("page/replay.js");

/// Largest frame the WebSocket layer accepts before the checks (bytes): larger
/// ones close the connection, which pauses the session.
const MAX_FRAME_BYTES: usize = 64 * MAX_MESSAGE_BYTES;

/// What the handlers share.
#[derive(Debug)]
struct Shared {
    session: Mutex<Session>,
    connected: AtomicBool,
    tick: Duration,
    lockstep: bool,
}

impl Shared {
    /// The session, also after a handler panicked while holding it.
    fn session(&self) -> MutexGuard<'_, Session> {
        self.session
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

/// Marks the session free again when the connection holding it ends.
struct Connection(Arc<Shared>);

impl Drop for Connection {
    fn drop(&mut self) {
        self.0.session().pause();
        self.0.connected.store(false, Ordering::SeqCst);
    }
}

/// Serves `session` on `listener` until the process ends.
///
/// # Errors
/// [`DriveError::Io`] when the server fails.
pub async fn serve(listener: TcpListener, session: Session) -> Result<(), DriveError> {
    let lockstep = session.protocol().pace == Pace::Lockstep;
    let tick = Duration::from_secs_f64(session.dt());
    let shared = Arc::new(Shared {
        session: Mutex::new(session),
        connected: AtomicBool::new(false),
        tick,
        lockstep,
    });
    let address = listener.local_addr().ok();
    let app = Router::new()
        .route("/", get(|| async { Html(INDEX_HTML) }))
        .route(
            "/page.js",
            get(|| async { asset("text/javascript", PAGE_JS) }),
        )
        .route("/page.css", get(|| async { asset("text/css", PAGE_CSS) }))
        .route("/replay", get(|| async { Html(REPLAY_HTML) }))
        .route(
            "/replay.js",
            get(|| async { asset("text/javascript", REPLAY_JS) }),
        )
        .route("/ws", get(upgrade))
        .with_state(shared);
    axum::serve(listener, app)
        .await
        .map_err(|source| DriveError::Io {
            path: address.map_or_else(Default::default, |a: SocketAddr| a.to_string().into()),
            source,
        })
}

/// An embedded file with its content type.
fn asset(content_type: &'static str, body: &'static str) -> Response {
    ([(header::CONTENT_TYPE, content_type)], body).into_response()
}

/// The WebSocket upgrade, refused while another tab drives the session.
async fn upgrade(State(shared): State<Arc<Shared>>, ws: WebSocketUpgrade) -> Response {
    if shared.connected.swap(true, Ordering::SeqCst) {
        return (
            StatusCode::CONFLICT,
            "another tab is driving this session; close it first",
        )
            .into_response();
    }
    let connection = Connection(shared);
    ws.max_message_size(MAX_FRAME_BYTES)
        .max_frame_size(MAX_FRAME_BYTES)
        .on_upgrade(move |socket| drive(socket, connection))
}

/// One connection: a frame every tick (in lockstep, for every control
/// message), the page's messages checked as they come.
async fn drive(mut socket: WebSocket, connection: Connection) {
    let shared = Arc::clone(&connection.0);
    let mut interval = tokio::time::interval(shared.tick);
    interval.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    let mut inbox = Inbox::default();
    let mut control = Control::default();
    let mut reply = Some(frame_message(&shared, None));
    loop {
        if let Some(message) = reply.take() {
            let text = message.to_string();
            if socket.send(Message::Text(text.into())).await.is_err() {
                break;
            }
        }
        tokio::select! {
            _ = interval.tick(), if !shared.lockstep => {
                reply = Some(frame_message(&shared, Some(control)));
                // Taking over is sent once; it latches in the session.
                control.take_over = false;
            }
            message = socket.recv() => match message {
                Some(Ok(Message::Text(text))) => {
                    match inbox.receive(text.as_str(), Instant::now()) {
                        Ok(Request::Control(next)) => {
                            control = Control {
                                take_over: control.take_over || next.take_over,
                                ..next
                            };
                            if shared.lockstep {
                                reply = Some(frame_message(&shared, Some(control)));
                                control.take_over = false;
                            }
                        }
                        Ok(Request::Start) => {
                            let started = shared.session().start();
                            reply = Some(match started {
                                Ok(()) => frame_message(&shared, None),
                                Err(error) => error_message(&error.to_string()),
                            });
                        }
                        Err(message) => reply = Some(error_message(&message)),
                    }
                }
                Some(Ok(Message::Binary(_))) => {
                    reply = Some(error_message("binary messages are not understood; send JSON text"));
                }
                Some(Ok(_)) => {}
                Some(Err(_)) | None => break,
            },
        }
    }
    drop(connection);
}

/// The frame after a tick with `control`, or without one the frame as it stands.
fn frame_message(shared: &Shared, control: Option<Control>) -> serde_json::Value {
    let mut session = shared.session();
    let frame = match control {
        Some(control) => session.tick(control),
        None => Ok(session.frame()),
    };
    match frame {
        Ok(frame) => json!({"type": "frame", "frame": frame}),
        Err(error) => error_message(&error.to_string()),
    }
}

/// An error frame.
fn error_message(message: &str) -> serde_json::Value {
    json!({"type": "error", "message": message})
}
