//! The WebSocket protocol with a scripted participant (no browser): one who
//! drives like a simulated user is personalized within the same takeovers as
//! that user in `palc learn`; hostile messages get error frames and the session
//! goes on; a second tab is refused; a server killed with SIGKILL in the middle
//! of a lane change resumes with nothing lost before it.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use futures_util::{SinkExt, StreamExt};
use palc_drive::record::{Event, read_events};
use palc_drive::{Protocol, RECORD_FILE, Session};
use palc_harness::user::User;
use palc_harness::{LearnConfig, LearningLoop, NoObserver, Outcome, RunResult, run};
use serde_json::{Value, json};
use tokio::net::TcpStream;
use tokio_tungstenite::tungstenite::Message;
use tokio_tungstenite::{MaybeTlsStream, WebSocketStream, connect_async};

type Socket = WebSocketStream<MaybeTlsStream<TcpStream>>;

const PROTOCOL: &str = r#"
participant = "scripted"
pace = "lockstep"
show_plan = true

[[scene]]
speed_case = "collector-high"
headway_m = 40.0
seed = 1
success_streak = 3
max_lane_changes = 30
"#;

fn protocol() -> (Protocol, LearnConfig) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("study.toml");
    std::fs::write(&path, PROTOCOL).unwrap();
    Protocol::load(&path).unwrap()
}

/// The simulated user the scripted participant copies, and its run in `palc learn`.
fn reference() -> (Vec<f64>, f64, RunResult) {
    let (protocol, base) = protocol();
    let config = protocol.scene_config(&base, 0);
    let learning = LearningLoop::new(&config, None).unwrap();
    let mut user = (config.user)
        .simulated(config.planning.takeover_threshold_m)
        .unwrap();
    let expectation = user.next(&learning.setup().user_scene()).unwrap();
    let expected_l = expectation.lateral(learning.setup().horizon);
    let result = run(&config, None, &mut NoObserver).unwrap();
    (expected_l, config.planning.takeover_threshold_m, result)
}

/// Starts a server on a free local port in this process.
async fn start_server(dir: &Path, resume: bool) -> SocketAddr {
    let (protocol, base) = protocol();
    let session = Session::open(protocol, base, dir, resume).unwrap();
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let address = listener.local_addr().unwrap();
    tokio::spawn(palc_drive::serve(listener, session));
    address
}

async fn connect(address: SocketAddr) -> Socket {
    connect_async(format!("ws://{address}/ws")).await.unwrap().0
}

async fn receive(socket: &mut Socket) -> Value {
    loop {
        match socket.next().await.unwrap().unwrap() {
            Message::Text(text) => return serde_json::from_str(text.as_str()).unwrap(),
            _ => continue,
        }
    }
}

/// A participant who expects `expected_l`: it takes over when the plan shown
/// deviates from that path beyond `threshold_m` at the step to be driven, then
/// steers back onto it (the simulated user's rule, as a person would see it).
struct Scripted {
    expected_l: Vec<f64>,
    threshold_m: f64,
    seq: u64,
}

impl Scripted {
    fn message(&mut self, mut message: Value) -> Message {
        self.seq += 1;
        message["seq"] = json!(self.seq);
        Message::text(message.to_string())
    }

    /// The participant's answer to `frame`: start, or its controls for the next step.
    fn answer(&self, frame: &Value) -> Option<Value> {
        match frame["phase"].as_str().unwrap() {
            "done" => None,
            "ready" | "paused" => Some(json!({"type": "start"})),
            _ => {
                let i = frame["step"].as_u64().unwrap() as usize;
                let planned = frame["plan"][i][1].as_f64().unwrap();
                let expected = self.expected_l[i];
                let take_over = frame["taken_over"].as_bool().unwrap()
                    || (planned - expected).abs() > self.threshold_m;
                let dt = frame["dt"].as_f64().unwrap();
                let l = frame["ego"][1].as_f64().unwrap();
                let lateral = if i == 0 {
                    0.0
                } else {
                    (expected - l) / dt / 4.0
                };
                Some(json!({
                    "type": "control",
                    "take_over": take_over,
                    "lateral": lateral.clamp(-1.0, 1.0),
                    "speed": 0.0,
                }))
            }
        }
    }
}

/// Answers every frame until the session is done or `stop(frame)` says so;
/// returns the last frame. Beyond the rate bound the participant waits and
/// sends its answer again.
async fn drive(socket: &mut Socket, driver: &mut Scripted, stop: impl Fn(&Value) -> bool) -> Value {
    let mut last: Option<Value> = None;
    loop {
        let message = receive(socket).await;
        if message["type"] == "error" {
            let text = message["message"].as_str().unwrap_or_default();
            assert!(text.contains("in a second"), "{message}");
            tokio::time::sleep(Duration::from_millis(250)).await;
            let again = driver.message(last.clone().unwrap());
            socket.send(again).await.unwrap();
            continue;
        }
        assert_eq!(message["type"], "frame", "{message}");
        let frame = message["frame"].clone();
        if stop(&frame) {
            return frame;
        }
        match driver.answer(&frame) {
            Some(answer) => {
                last = Some(answer.clone());
                socket.send(driver.message(answer)).await.unwrap();
            }
            None => return frame,
        }
    }
}

fn scene_result(dir: &Path) -> RunResult {
    serde_json::from_slice(&std::fs::read(dir.join("scene-0.json")).unwrap()).unwrap()
}

fn assert_same_run(run: &RunResult, reference: &RunResult) {
    assert_eq!(run.summary.outcome, Outcome::Personalized);
    assert_eq!(run.summary.takeovers, reference.summary.takeovers);
    assert_eq!(run.records.len(), reference.records.len());
    for (a, b) in run.records.iter().zip(&reference.records) {
        assert_eq!(a.takeover.map(|t| t.step), b.takeover.map(|t| t.step));
        let gap =
            (a.driven_l.iter().zip(&b.driven_l)).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        // Steering is sent in steps of 1/1024 of the limit.
        assert!(
            gap < 0.01,
            "lane change {}: driven paths {gap} m apart",
            a.index
        );
    }
}

#[tokio::test]
async fn a_scripted_participant_is_personalized_within_the_simulated_users_takeovers() {
    let (expected_l, threshold_m, reference) = reference();
    let dir = tempfile::tempdir().unwrap();
    let address = start_server(dir.path(), false).await;
    let mut socket = connect(address).await;
    let mut driver = Scripted {
        expected_l,
        threshold_m,
        seq: 0,
    };
    let last = drive(&mut socket, &mut driver, |_| false).await;
    assert_eq!(last["phase"], "done");
    let result = scene_result(dir.path());
    assert_same_run(&result, &reference);
    let events = read_events(&dir.path().join(RECORD_FILE)).unwrap();
    let lane_changes = events
        .iter()
        .filter(|e| matches!(e, Event::LaneChange { .. }))
        .count();
    assert_eq!(lane_changes, result.records.len());
    assert!(events.iter().any(|e| matches!(e, Event::Tick { .. })));
    assert!(dir.path().join(palc_drive::EXPERIENCE_FILE).is_file());
}

#[tokio::test]
async fn hostile_messages_get_error_frames_and_the_session_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let address = start_server(dir.path(), false).await;
    let mut socket = connect(address).await;
    let first = receive(&mut socket).await;
    assert_eq!(first["frame"]["phase"], "ready");
    let hostile = [
        Message::text("{not json"),
        Message::text(format!(
            r#"{{"type":"start","seq":1,"pad":"{}"}}"#,
            "x".repeat(4000)
        )),
        Message::text(r#"{"type":"control","seq":5,"take_over":false,"lateral":1e300,"speed":0}"#),
        Message::text(r#"{"type":"fly","seq":6}"#),
        Message::binary(vec![0u8; 16]),
    ];
    for message in hostile {
        socket.send(message).await.unwrap();
        let reply = receive(&mut socket).await;
        assert_eq!(reply["type"], "error", "{reply}");
    }
    socket
        .send(Message::text(r#"{"type":"start","seq":10}"#))
        .await
        .unwrap();
    let started = receive(&mut socket).await;
    assert_eq!(started["frame"]["phase"], "driving", "{started}");
    socket
        .send(Message::text(r#"{"type":"start","seq":9}"#))
        .await
        .unwrap();
    let reply = receive(&mut socket).await;
    assert!(
        reply["message"].as_str().unwrap().contains("out of order"),
        "{reply}"
    );
    // A flood: beyond the rate bound, messages are refused.
    for seq in 11..211 {
        let text = format!(r#"{{"type":"start","seq":{seq}}}"#);
        socket.send(Message::text(text)).await.unwrap();
    }
    let mut refused = 0;
    for _ in 11..211 {
        let reply = receive(&mut socket).await;
        refused += usize::from(reply["type"] == "error");
    }
    assert!(refused > 0);
    // A second tab is refused while the first is open.
    assert!(connect_async(format!("ws://{address}/ws")).await.is_err());
    // A lost connection pauses the lane change; the next tab goes on from there.
    drop(socket);
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut again = loop {
        if let Ok((socket, _)) = connect_async(format!("ws://{address}/ws")).await {
            break socket;
        }
        assert!(Instant::now() < deadline, "the session stayed taken");
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    let frame = receive(&mut again).await;
    assert_eq!(frame["frame"]["phase"], "paused", "{frame}");
}

/// The server of the kill test, in a child process: this test binary run again
/// with `PALC_DRIVE_CHILD` naming the output directory. It writes its address
/// to `address` there and serves until it is killed. Without the variable it
/// has nothing to do.
#[test]
fn child_server() {
    let Ok(dir) = std::env::var("PALC_DRIVE_CHILD") else {
        return;
    };
    let dir = PathBuf::from(dir);
    let resume = dir.join(RECORD_FILE).exists();
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async {
        let (protocol, base) = protocol();
        let session = Session::open(protocol, base, &dir, resume).unwrap();
        let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
        let address = listener.local_addr().unwrap().to_string();
        std::fs::write(dir.join("address.tmp"), address).unwrap();
        std::fs::rename(dir.join("address.tmp"), dir.join("address")).unwrap();
        palc_drive::serve(listener, session).await.unwrap();
    });
}

/// The child server, killed (SIGKILL) when dropped.
struct ChildServer(Child);

impl ChildServer {
    fn kill(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

impl Drop for ChildServer {
    fn drop(&mut self) {
        self.kill();
    }
}

fn spawn_child(dir: &Path) -> (ChildServer, SocketAddr) {
    let _ = std::fs::remove_file(dir.join("address"));
    let child = ChildServer(
        Command::new(std::env::current_exe().unwrap())
            .args(["--exact", "child_server", "--test-threads=1"])
            .env("PALC_DRIVE_CHILD", dir)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let deadline = Instant::now() + Duration::from_secs(120);
    loop {
        if let Ok(text) = std::fs::read_to_string(dir.join("address")) {
            return (child, text.parse().unwrap());
        }
        assert!(Instant::now() < deadline, "the child server did not start");
        std::thread::sleep(Duration::from_millis(50));
    }
}

#[tokio::test]
async fn a_server_killed_mid_lane_change_resumes_with_nothing_lost_before_it() {
    let (expected_l, threshold_m, reference) = reference();
    let dir = tempfile::tempdir().unwrap();
    let (mut child, address) = spawn_child(dir.path());
    let mut socket = connect(address).await;
    let mut driver = Scripted {
        expected_l,
        threshold_m,
        seq: 0,
    };
    // Two lane changes, then half of the third.
    let frame = drive(&mut socket, &mut driver, |f| {
        f["lane_changes"] == 2 && f["phase"] == "driving" && f["step"].as_u64() > Some(20)
    })
    .await;
    assert_eq!(frame["lane_changes"], 2, "{frame}");
    child.kill(); // SIGKILL
    drop(socket);
    let before = read_events(&dir.path().join(RECORD_FILE)).unwrap();
    let completed = |events: &[Event]| {
        events
            .iter()
            .filter_map(|e| match e {
                Event::LaneChange { record, .. } => Some(record.clone()),
                _ => None,
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(completed(&before).len(), 2);

    let (mut child, address) = spawn_child(dir.path());
    let mut socket = connect(address).await;
    let first = receive(&mut socket).await;
    assert_eq!(first["frame"]["lane_changes"], 2, "{first}");
    assert_eq!(first["frame"]["phase"], "ready");
    let start = driver.answer(&first["frame"]).unwrap();
    socket.send(driver.message(start)).await.unwrap();
    let last = drive(&mut socket, &mut driver, |_| false).await;
    assert_eq!(last["phase"], "done");
    child.kill();
    let after = read_events(&dir.path().join(RECORD_FILE)).unwrap();
    assert!(
        after
            .iter()
            .any(|e| matches!(e, Event::Resumed { lane_changes: 2 }))
    );
    assert_eq!(completed(&after)[..2], completed(&before)[..]);
    assert_same_run(&scene_result(dir.path()), &reference);
}
