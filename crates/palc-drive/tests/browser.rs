//! The study page in a real browser: headless Chromium driven through WebDriver
//! (Debian's `chromium` and `chromium-driver`; `cargo xtask test` installs them
//! as root). The page loads, its canvas changes as the scene moves, key presses
//! take over and steer, a lesson is learned and the next plan is closer to what
//! was driven, and the record is on disk; the replay viewer reads the scene's run
//! back. Screenshots of the page are written to `target/palc-drive/browser.png`
//! and `replay.png`.
//!
//! Without Chromium or its driver the test says what is missing and skips.

use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use fantoccini::actions::{InputSource, KeyAction, KeyActions};
use fantoccini::key::Key;
use fantoccini::{Client, ClientBuilder, Locator};
use palc_drive::record::{Event, read_events};
use palc_drive::{EXPERIENCE_FILE, Protocol, RECORD_FILE, Session};
use palc_harness::RunResult;
use serde_json::json;

const PROTOCOL: &str = r#"
participant = "browser"

[[scene]]
speed_case = "collector-high"
headway_m = 40.0
seed = 1
max_lane_changes = 2
"#;

/// The first of `names` found on `PATH`.
fn find(names: &[&str]) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| names.iter().map(move |name| dir.join(name)))
        .find(|candidate| candidate.is_file())
}

/// The WebDriver server, killed when dropped.
struct Driver(Child);

impl Drop for Driver {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn free_port() -> u16 {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    listener.local_addr().unwrap().port()
}

async fn start_server(dir: &Path) -> SocketAddr {
    let path = dir.join("study.toml");
    std::fs::write(&path, PROTOCOL).unwrap();
    let (protocol, base) = Protocol::load(&path).unwrap();
    let session = Session::open(protocol, base, &dir.join("out"), false).unwrap();
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let address = listener.local_addr().unwrap();
    tokio::spawn(palc_drive::serve(listener, session));
    address
}

async fn connect(chromium: &Path, port: u16) -> Client {
    let capabilities = json!({
        "goog:chromeOptions": {
            "binary": chromium,
            "args": ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1280,640"],
        }
    });
    let capabilities = capabilities.as_object().unwrap().clone();
    let connector = hyper_util::client::legacy::connect::HttpConnector::new();
    let deadline = Instant::now() + Duration::from_secs(30);
    loop {
        let connected = ClientBuilder::new(connector.clone())
            .capabilities(capabilities.clone())
            .connect(&format!("http://127.0.0.1:{port}"))
            .await;
        match connected {
            Ok(client) => return client,
            Err(error) => assert!(Instant::now() < deadline, "no WebDriver session: {error}"),
        }
        tokio::time::sleep(Duration::from_millis(200)).await;
    }
}

async fn text(client: &Client, id: &str) -> String {
    let script = format!("return document.getElementById('{id}').textContent;");
    let value = client.execute(&script, Vec::new()).await.unwrap();
    value.as_str().unwrap_or_default().to_owned()
}

async fn canvas(client: &Client) -> String {
    canvas_of(client, "road").await
}

async fn canvas_of(client: &Client, id: &str) -> String {
    let script = format!("return document.getElementById('{id}').toDataURL();");
    let value = client.execute(&script, Vec::new()).await.unwrap();
    value.as_str().unwrap_or_default().to_owned()
}

/// Waits until the element `id` reads something containing `wanted`.
async fn wait_for_text(client: &Client, id: &str, wanted: &str) {
    let deadline = Instant::now() + Duration::from_secs(60);
    loop {
        let now = text(client, id).await;
        if now.contains(wanted) {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "#{id} never read {wanted:?}: {now:?}"
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

async fn keys(client: &Client, actions: Vec<KeyAction>) {
    let sequence =
        (actions.into_iter()).fold(KeyActions::new("keyboard".to_owned()), |s, a| s.then(a));
    client.perform_actions(sequence).await.unwrap();
}

fn press(key: char) -> Vec<KeyAction> {
    vec![KeyAction::Down { value: key }, KeyAction::Up { value: key }]
}

/// Mean `|a − b|` over the common steps.
fn mean_gap(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()).max(1);
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f64>() / n as f64
}

#[tokio::test]
async fn a_participant_in_a_real_browser_takes_over_steers_and_is_learned_from() {
    let (Some(chromium), Some(chromedriver)) = (
        find(&["chromium", "chromium-browser"]),
        find(&["chromedriver"]),
    ) else {
        eprintln!(
            "NOTICE: the real-browser test is SKIPPED: `chromium` and `chromedriver` must be on PATH \
             (Debian: apt-get install chromium chromium-driver; `cargo xtask test` installs them as root)"
        );
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let address = start_server(dir.path()).await;
    let port = free_port();
    let _driver = Driver(
        Command::new(chromedriver)
            .arg(format!("--port={port}"))
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap(),
    );
    let client = connect(&chromium, port).await;
    client.goto(&format!("http://{address}/")).await.unwrap();
    wait_for_text(&client, "state", "Press Space").await;
    let before = canvas(&client).await;

    // Start; the scene moves.
    keys(&client, press(Key::Space.into())).await;
    wait_for_text(&client, "state", "palc is driving").await;
    tokio::time::sleep(Duration::from_millis(500)).await;
    assert_ne!(canvas(&client).await, before, "the canvas did not change");

    // Take over before the plan moves and steer left for 0.8 s.
    let mut steer = press('t');
    steer.extend([
        KeyAction::Down {
            value: Key::Left.into(),
        },
        KeyAction::Pause {
            duration: Duration::from_millis(800),
        },
        KeyAction::Up {
            value: Key::Left.into(),
        },
    ]);
    keys(&client, steer).await;
    wait_for_text(&client, "state", "You are driving").await;
    let screenshot = client.screenshot().await.unwrap();
    let target = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../target/palc-drive");
    std::fs::create_dir_all(&target).unwrap();
    palc_aggregator::output::write(&target.join("browser.png"), &screenshot).unwrap();

    // The lesson is learned at the end of the lane change; a second one follows.
    wait_for_text(&client, "state", "Press Space").await;
    let out = dir.path().join("out");
    assert!(
        out.join(EXPERIENCE_FILE).is_file(),
        "no experience after the lesson"
    );
    keys(&client, press(Key::Space.into())).await;
    wait_for_text(&client, "state", "study is complete").await;

    // The replay viewer reads the scene's run back, lane change by lane change.
    client
        .goto(&format!("http://{address}/replay"))
        .await
        .unwrap();
    let blank = canvas_of(&client, "paths").await;
    let input = client.find(Locator::Id("file")).await.unwrap();
    let scene = std::path::absolute(out.join("scene-0.json")).unwrap();
    input.send_keys(&scene.display().to_string()).await.unwrap();
    wait_for_text(&client, "summary", "2 lane changes, 1 takeovers").await;
    wait_for_text(
        &client,
        "lane-change",
        "lane change 1 of 2: takeover at step",
    )
    .await;
    assert_ne!(
        canvas_of(&client, "paths").await,
        blank,
        "the replay drew nothing"
    );
    let replay = client.screenshot().await.unwrap();
    palc_aggregator::output::write(&target.join("replay.png"), &replay).unwrap();
    client.close().await.unwrap();

    let events = read_events(&out.join(RECORD_FILE)).unwrap();
    let ticks = events
        .iter()
        .filter(|e| matches!(e, Event::Tick { .. }))
        .count();
    assert!(ticks > 20, "{ticks} ticks recorded");
    let result: RunResult =
        serde_json::from_slice(&std::fs::read(out.join("scene-0.json")).unwrap()).unwrap();
    assert_eq!(result.records.len(), 2);
    let taken = &result.records[0];
    assert!(taken.takeover.is_some(), "the key press did not take over");
    assert!(taken.learning_error.is_none(), "{:?}", taken.learning_error);
    let peak = taken.driven_l.iter().copied().fold(0.0, f64::max);
    assert!(peak > 1.75, "steering moved the ego only to l = {peak} m");
    let driven = &taken.driven_l;
    let (first, next) = (
        mean_gap(&taken.planned_l, driven),
        mean_gap(&result.records[1].planned_l, driven),
    );
    assert!(
        next < first,
        "the next plan is {next} m from the driven path, the first {first} m"
    );
}
