//! A platoon that starts away from equilibrium, each follower with its own initial gap
//! and speed (`[[platoon.followers]]`), against an independent integration of the same
//! scheme written here: the IDM of Treiber et al. (2000) with either form of `s*`, the
//! deceleration clipped to the braking limit, and the ballistic update, all vehicles
//! updated synchronously from the states at the start of the step (issue 12, item 2).

use palc_traffic::{ConfigError, DesiredGap, ScenarioConfig, Scene};

const MPH: f64 = 0.44704;
const LENGTH: f64 = 5.0;
const BRAKING: f64 = 9.0;

/// Per follower: (front-to-front headway to the vehicle ahead in m, speed in mph).
const FOLLOWERS: [(f64, f64); 4] = [(18.0, 45.0), (60.0, 10.0), (9.0, 30.0), (35.0, 0.0)];

fn config(form: &str, followers: &[(f64, f64)]) -> String {
    let mut text = format!(
        "[road]\nlength_m = 5000.0\nlanes = 1\n\
         [idm]\ndesired_gap = \"{form}\"\n\
         [platoon]\nvehicles = {}\nlane = 0\nleader_start_s_m = 1000.0\nheadway_m = 40.0\n\
         initial_speed_mph = 40.0\ndesired_speed_mph = 65.0\n\
         leader_profile = [{{ time_s = 0.0, speed_mph = 40.0 }}]\n",
        followers.len() + 1
    );
    for (headway, speed) in followers {
        text += &format!("[[platoon.followers]]\nheadway_m = {headway}\nspeed_mph = {speed}\n");
    }
    text
}

/// `s*` and the IDM acceleration as printed, computed here independently.
fn idm(v: f64, gap: f64, dv: f64, clamped: bool) -> f64 {
    let (v0, t, s0, a, b): (f64, f64, f64, f64, f64) = (65.0 * MPH, 1.6, 2.0, 0.73, 1.67);
    let mut dynamic = v * t + v * dv / (2.0 * (a * b).sqrt());
    if clamped {
        dynamic = dynamic.max(0.0);
    }
    let star = s0 + dynamic;
    let acc = a * (1.0 - (v / v0).powi(4) - (star / gap.max(0.1)).powi(2));
    acc.max(-BRAKING)
}

/// `(s, v)` of every vehicle after `steps` steps of `dt`, integrated here.
fn reference(followers: &[(f64, f64)], clamped: bool, dt: f64, steps: usize) -> Vec<(f64, f64)> {
    let mut state = vec![(1000.0, 40.0 * MPH)];
    for &(headway, speed) in followers {
        let s = state.last().unwrap().0 - headway;
        state.push((s, speed * MPH));
    }
    for _ in 0..steps {
        let accelerations: Vec<f64> = (0..state.len())
            .map(|i| {
                if i == 0 {
                    0.0
                } else {
                    let (s, v) = state[i];
                    let (s_lead, v_lead) = state[i - 1];
                    idm(v, s_lead - LENGTH - s, v - v_lead, clamped)
                }
            })
            .collect();
        for (i, (s, v)) in state.iter_mut().enumerate() {
            let acc = accelerations[i];
            if acc * dt + *v >= 0.0 {
                *s += *v * dt + 0.5 * acc * dt * dt;
                *v += acc * dt;
            } else {
                *s += *v * *v / (-2.0 * acc);
                *v = 0.0;
            }
        }
    }
    state
}

#[test]
fn a_platoon_away_from_equilibrium_matches_an_independent_integration() {
    let (dt, steps) = (0.1, 600);
    for (form, clamped) in [("treiber2000", false), ("clamped", true)] {
        let config = ScenarioConfig::from_toml_str(&config(form, &FOLLOWERS)).unwrap();
        let expected_form = if clamped {
            DesiredGap::Clamped
        } else {
            DesiredGap::Treiber2000
        };
        assert_eq!(config.idm.desired_gap, expected_form);
        let mut scene = Scene::from_config(&config, 0).unwrap();
        for (vehicle, &(headway, speed)) in scene.vehicles()[1..].iter().zip(&FOLLOWERS) {
            assert!((vehicle.state.v - speed * MPH).abs() <= 1e-12, "{headway}");
        }
        for _ in 0..steps {
            scene.step_autonomous(dt).unwrap();
        }
        let expected = reference(&FOLLOWERS, clamped, dt, steps);
        for (vehicle, (s, v)) in scene.vehicles().iter().zip(&expected) {
            assert!(
                (vehicle.state.s - s).abs() <= 1e-9 * s.abs()
                    && (vehicle.state.v - v).abs() <= 1e-9,
                "{form}: vehicle {}: ({}, {}) vs ({s}, {v})",
                vehicle.id.0,
                vehicle.state.s,
                vehicle.state.v
            );
        }
    }
    // The two forms differ here: followers start much slower than their leaders.
    let printed = reference(&FOLLOWERS, false, dt, steps);
    let clamped = reference(&FOLLOWERS, true, dt, steps);
    let largest = printed
        .iter()
        .zip(&clamped)
        .map(|(a, b)| (a.0 - b.0).abs())
        .fold(0.0, f64::max);
    assert!(largest > 0.1, "{largest}");
}

#[test]
fn follower_states_are_checked() {
    let err = ScenarioConfig::from_toml_str(&config("clamped", &FOLLOWERS[..2]))
        .and_then(|c| {
            let mut c = c;
            c.platoon.as_mut().unwrap().vehicles = 5;
            Scene::from_config(&c, 0).map(|_| c)
        })
        .unwrap_err();
    assert!(
        matches!(&err, ConfigError::OutOfRange { field, .. } if field == "platoon.followers"),
        "{err}"
    );
    let err = ScenarioConfig::from_toml_str(&config("clamped", &[(-3.0, 20.0)]))
        .and_then(|c| Scene::from_config(&c, 0).map(|_| c))
        .unwrap_err();
    assert!(
        err.to_string().contains("platoon.followers[0].headway_m"),
        "{err}"
    );
    let err = ScenarioConfig::from_toml_str(&config("clamped", &[(30.0, 80.0)]))
        .and_then(|c| Scene::from_config(&c, 0).map(|_| c))
        .unwrap_err();
    assert!(
        err.to_string().contains("platoon.followers[0].speed_mph"),
        "{err}"
    );
}
