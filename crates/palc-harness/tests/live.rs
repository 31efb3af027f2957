//! Live mode: a scripted live driver that takes over 0.3 m from its own quintic
//! and then steers back onto it is personalized within the same takeovers as the
//! simulated user it copies, in open and in closed loop; its commands are held
//! to the physical limits.

use palc_harness::live::{LiveDriver, LiveInput, LiveLimits, LiveView};
use palc_harness::user::User;
use palc_harness::{LearnConfig, LearningLoop, Method, NoObserver, Outcome, UserConfig, run};

fn config(style: &str, closed_loop: bool) -> LearnConfig {
    let text = include_str!("../../../configs/learn.toml");
    let mut config = LearnConfig::from_toml_str(text).expect("the default config parses");
    config.planning.closed_loop.enabled = closed_loop;
    let user = UserConfig {
        style: style.parse().expect("a valid style name"),
        ..config.user.clone()
    };
    config.with_method(Method::Palc).with_user(user)
}

/// A live driver who expects `expected_l` and takes over beyond `threshold_m`,
/// then commands the lateral speed that puts it back on that path at each step.
#[derive(Debug)]
struct Scripted {
    expected_l: Vec<f64>,
    threshold_m: f64,
}

impl LiveDriver for Scripted {
    fn decide(&mut self, view: &LiveView<'_>) -> LiveInput {
        let expected = self.expected_l[view.step];
        let take_over = view.taken_over || (view.proposed.l - expected).abs() > self.threshold_m;
        let lateral_speed_mps = view
            .previous
            .map_or(0.0, |previous| (expected - previous.l) / view.dt);
        LiveInput {
            take_over,
            lateral_speed_mps,
            acceleration_mps2: None,
        }
    }
}

/// Runs the loop of `config` with the scripted copy of its simulated user.
fn live_run(config: &LearnConfig) -> (Outcome, usize, usize) {
    let mut learning = LearningLoop::new(config, None).expect("the scenario prepares");
    let mut user = config
        .user
        .simulated(config.planning.takeover_threshold_m)
        .unwrap();
    let expectation = user.next(&learning.setup().user_scene()).unwrap();
    let mut driver = Scripted {
        expected_l: expectation.lateral(learning.setup().horizon),
        threshold_m: config.planning.takeover_threshold_m,
    };
    let outcome = loop {
        if let Some(outcome) = learning.termination() {
            break outcome;
        }
        (learning.step_live(&mut driver, LiveLimits::default(), &mut NoObserver)).unwrap();
    };
    let takeovers = learning.records().iter().filter(|r| r.takeover.is_some());
    (outcome, takeovers.count(), learning.records().len())
}

#[test]
fn a_scripted_live_driver_is_personalized_within_the_simulated_users_takeovers() {
    for closed_loop in [false, true] {
        for style in ["aggressive", "neutral", "cautious"] {
            let config = config(style, closed_loop);
            let simulated = run(&config, None, &mut NoObserver).unwrap();
            let (outcome, takeovers, lane_changes) = live_run(&config);
            let label = format!("{style}, closed loop {closed_loop}");
            assert_eq!(outcome, Outcome::Personalized, "{label}");
            assert_eq!(simulated.summary.outcome, Outcome::Personalized, "{label}");
            assert_eq!(takeovers, simulated.summary.takeovers, "{label}");
            assert_eq!(lane_changes, simulated.records.len(), "{label}");
        }
    }
}

#[test]
fn commands_are_held_to_the_physical_limits() {
    let limits = LiveLimits::default();
    let wild = LiveInput {
        take_over: true,
        lateral_speed_mps: 50.0,
        acceleration_mps2: Some(-40.0),
    };
    assert!((limits.lateral_speed(&wild) - limits.max_lateral_speed_mps).abs() < 1e-12);
    assert!((limits.acceleration(&wild, 0.5) + limits.max_deceleration_mps2).abs() < 1e-12);
    let broken = LiveInput {
        lateral_speed_mps: f64::NAN,
        acceleration_mps2: Some(f64::INFINITY),
        ..wild
    };
    assert!(limits.lateral_speed(&broken).abs() < 1e-12);
    assert!((limits.acceleration(&broken, 0.5) - 0.5).abs() < 1e-12);
    let bad = LiveLimits {
        max_lateral_speed_mps: -1.0,
        ..limits
    };
    let message = bad.validate("live").unwrap_err().to_string();
    assert!(message.contains("live.max_lateral_speed_mps"), "{message}");
}

#[test]
fn a_live_lane_change_cannot_be_finished_early_or_stepped_past_its_end() {
    let config = config("neutral", false);
    let mut learning = LearningLoop::new(&config, None).unwrap();
    let mut lane_change = learning.begin_live(LiveLimits::default()).unwrap();
    lane_change
        .advance(learning.setup(), LiveInput::default())
        .unwrap();
    let early = learning.finish_live(lane_change.clone(), &mut NoObserver);
    assert!(early.unwrap_err().to_string().contains("finished"));
    while lane_change.step() <= lane_change.horizon() {
        lane_change
            .advance(learning.setup(), LiveInput::default())
            .unwrap();
    }
    let past = lane_change.advance(learning.setup(), LiveInput::default());
    assert!(past.unwrap_err().to_string().contains("stepped"));
    let record = learning.finish_live(lane_change, &mut NoObserver).unwrap();
    assert_eq!(record.driven_l.len(), learning.setup().horizon + 1);
}
