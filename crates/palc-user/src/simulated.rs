//! The built-in simulated user: a style refined by a family, with an optional
//! spread of its parameters between lane changes.

use palc_planner::State;
use rand_chacha::ChaCha8Rng;

use crate::User;
use crate::error::{UserError, UserRefusal};
use crate::expectation::{
    Expectation, ExpectedLaneChange, MAX_LATERAL_ACCELERATION_MPS2, MAX_LATERAL_JERK_MPS3,
    TakeoverRule,
};
use crate::family::{Family, SpeedRule};
use crate::profile::TABLE_END_TOLERANCE_M;
use crate::scene::UserScene;
use crate::situation::Situation;
use crate::spread::Spread;
use crate::start::{NoStart, StartModel};
use crate::style::Style;

/// Most draws of one lane change's parameters (a draw whose lane change fails the
/// sanity checks is drawn again).
pub const MAX_DRAWS: usize = 100;

/// A simulated user: a nominal [`Style`] refined by a [`Family`], the deviation
/// threshold of its takeovers and, optionally, a [`Spread`] of its parameters.
#[derive(Debug, Clone)]
pub struct SimulatedUser {
    name: String,
    style: Style,
    family: Family,
    deviation_m: f64,
    spread: Option<Spread>,
    rng: Option<ChaCha8Rng>,
}

impl SimulatedUser {
    /// A user named `name` (in messages) of `style` and `family`, taking over
    /// beyond `deviation_m` of lateral deviation, with `spread` if given.
    ///
    /// # Errors
    /// [`UserError::InvalidConfig`] naming the field of a parameter out of its bound.
    pub fn new(
        name: impl Into<String>,
        style: Style,
        family: Family,
        deviation_m: f64,
        spread: Option<Spread>,
    ) -> Result<Self, UserError> {
        style.validate("user.style")?;
        family.validate("user.family")?;
        if !(deviation_m.is_finite() && deviation_m > 0.0) {
            return Err(UserError::InvalidConfig {
                field: "planning.takeover_threshold_m".to_owned(),
                value: deviation_m,
                bound: "a finite value > 0".to_owned(),
            });
        }
        if let Some(spread) = &spread {
            spread.validate("user.spread")?;
        }
        Ok(Self {
            name: name.into(),
            style,
            family,
            deviation_m,
            rng: spread.map(|s| s.rng()),
            spread,
        })
    }

    /// The paper's user of `style`: no family rules, no spread, the paper's 0.3 m.
    pub fn paper(style: Style) -> Result<Self, UserError> {
        Self::new("paper", style, Family::default(), 0.3, None)
    }

    /// The nominal style.
    pub fn style(&self) -> Style {
        self.style
    }

    /// The family.
    pub fn family(&self) -> &Family {
        &self.family
    }

    /// The lane change a user of `style` and `family` expects in `scene`, checked
    /// for sanity; the error says what failed.
    fn expectation(
        &self,
        style: &Style,
        family: &Family,
        scene: &UserScene<'_>,
    ) -> Result<Expectation, UserError> {
        let refuse = |refusal: UserRefusal| UserError::Refused {
            user: self.name.clone(),
            refusal,
        };
        let situations = scene.situations;
        let dt = scene.dt;
        let window = scene.window();
        let model = StartModel::of(style, family);
        let duration_s = family
            .profile
            .own_duration_s()
            .unwrap_or(style.lane_change_duration_s);
        // With `users_wait_for_safe_gaps`, the gaps must also be at the RSS safe
        // distance at every step of the lane change started there, as the user sees
        // the ego's motion coming (the lane keeping's): a start checked at its first
        // step alone put the user 18.6 m behind the target lane's leader, below the
        // 19.9 m RSS distance, at step 69 (collector-high / 35 m / seed 1, cautious),
        // and the safety layer refused the plans that copied it
        // (docs/experiments/0038-users-who-wait-for-safe-gaps.md).
        // A user with a speed of its own (speed matching) checks the gaps on its
        // own motion from the start on as well: checked on the lane keeping's alone,
        // a speed-matching user slowing towards the target lane's speed fell 7.1 m
        // ahead of the lag vehicle against an RSS distance of 8.1 m (collector-high
        // / 50 m / seed 1). The lane keeping's stays checked too: the plans that copy
        // the start drive at its speed, and the safety layer refused them otherwise.
        // Saturating: a custom style's duration may exceed any window (the sanity
        // check below refuses it), and its step count must not overflow here.
        let duration_steps = (duration_s / dt).ceil() as usize;
        let safe = |i: usize| {
            let Some(safe_gaps) = scene.safe_gaps else {
                return true;
            };
            let target_speed = target_speed_at(&situations[i], scene.set_speed);
            let mut own = scene.lane_keeping[i];
            (i..=i.saturating_add(duration_steps).min(window)).all(|j| {
                let keeping = scene.lane_keeping[j];
                if j > i {
                    own = match speed_rule_step(family.speed, own[1], target_speed, dt) {
                        Some(v) => [own[0] + 0.5 * (own[1] + v) * dt, v],
                        None => keeping,
                    };
                }
                let seen = situations[j].seen_from(own[0] - keeping[0], own[1]);
                safe_gaps.target_gaps_safe(&situations[j]) && safe_gaps.target_gaps_safe(&seen)
            })
        };
        let (decision_step, start_step) = model
            .start_step(&situations[..=window], dt, scene.set_speed, safe)
            .map_err(|no_start| {
                refuse(match no_start {
                    NoStart::NeverDecides => UserRefusal::StartRuleNeverMet {
                        rule: family.start.name().to_owned(),
                        window_s: window as f64 * dt,
                    },
                    NoStart::DecidedAtFirstStep => UserRefusal::StartRuleMetAtTrigger {
                        rule: family.start.name().to_owned(),
                        time_headway_s: situations[0].time_headway_s,
                    },
                    NoStart::GapsNeverAcceptable { decision_step } => {
                        UserRefusal::GapsNeverAcceptable {
                            min_lead_gap_s: model.min_lead_gap_s,
                            min_lag_gap_s: model.min_lag_gap_s,
                            safe_distance: scene.safe_gaps.is_some(),
                            decision_step,
                        }
                    }
                })
            })?;
        let lane_change = ExpectedLaneChange {
            start_s: start_step as f64 * dt,
            duration_s,
            from_l: 0.0,
            to_l: scene.target_l,
            profile: family.profile.clone(),
        };
        let target_speed = target_speed_at(&situations[start_step], scene.set_speed);
        let states = expected_states(scene, &lane_change, start_step, family.speed, target_speed);
        let expectation = Expectation {
            lane_change,
            decision_step,
            start_step,
            states,
            takeover: TakeoverRule {
                deviation_m: self.deviation_m,
                perceived_safety: family.perceived_safety,
            },
            speed: family.speed,
            target_speed,
        };
        sanity(&expectation, scene).map_err(refuse)?;
        Ok(expectation)
    }
}

/// The states of the expected lane change: the ego keeping its lane until the
/// start, then moving laterally along the profile at the speed of `speed`.
fn expected_states(
    scene: &UserScene<'_>,
    lane_change: &ExpectedLaneChange,
    start_step: usize,
    speed: SpeedRule,
    target_speed: f64,
) -> Vec<State> {
    let dt = scene.dt;
    let n = scene.situations.len();
    let mut states: Vec<State> = Vec::with_capacity(n);
    for i in 0..n {
        let [keeping_s, keeping_v] = scene.lane_keeping[i.min(scene.lane_keeping.len() - 1)];
        let own = states
            .last()
            .filter(|_| i > start_step)
            .and_then(|previous| {
                let v = speed_rule_step(speed, previous.v, target_speed, dt)?;
                Some((previous.s + 0.5 * (previous.v + v) * dt, v))
            });
        let (s, v) = own.unwrap_or((keeping_s, keeping_v));
        states.push(State {
            s,
            v,
            l: lane_change.lateral(i as f64 * dt),
            phi: 0.0,
        });
    }
    for i in 0..n.saturating_sub(1) {
        let run = (states[i].v * dt).max(1e-9);
        states[i].phi = (states[i + 1].l - states[i].l) / run;
    }
    states
}

/// The speed a speed-matching user heads for once it starts in `seen`: the target
/// lane's leader's, else its follower's, else the ego's set speed.
fn target_speed_at(seen: &Situation, set_speed: f64) -> f64 {
    seen.target_lead_speed
        .or(seen.target_lag_speed)
        .unwrap_or(set_speed)
}

/// The user's speed one step after `v` under its own speed rule, or `None` when it
/// leaves its speed to the ego's lane keeping. Accelerating: the speed gap times
/// 1/s, bounded, as the user drives after a takeover
/// (`User::acceleration_after_takeover`).
fn speed_rule_step(speed: SpeedRule, v: f64, target_speed: f64, dt: f64) -> Option<f64> {
    match speed {
        SpeedRule::Accelerating {
            max_acceleration_mps2,
        } => {
            let a = (target_speed - v).clamp(-max_acceleration_mps2, max_acceleration_mps2);
            Some(v + a * dt)
        }
        SpeedRule::Constant => None,
    }
}

/// The sanity checks of an expected lane change: it ends inside the search
/// window, goes from the current lane's centre to the target lane's, stays
/// between the two lanes, and is smooth (bounded lateral acceleration and jerk).
fn sanity(expectation: &Expectation, scene: &UserScene<'_>) -> Result<(), UserRefusal> {
    let lane_change = &expectation.lane_change;
    let window_s = scene.window_s();
    if lane_change.end_s() > window_s + 1e-9 {
        return Err(UserRefusal::EndsAfterWindow {
            end_s: lane_change.end_s(),
            window_s,
        });
    }
    let width = (lane_change.to_l - lane_change.from_l).abs();
    let start = lane_change.lateral(lane_change.start_s);
    let end = lane_change.lateral(lane_change.end_s());
    if (start - lane_change.from_l).abs() > TABLE_END_TOLERANCE_M
        || (end - lane_change.to_l).abs() > TABLE_END_TOLERANCE_M
    {
        return Err(UserRefusal::NotCentreToCentre {
            start_l: start,
            end_l: end,
            from_l: lane_change.from_l,
            to_l: lane_change.to_l,
        });
    }
    let (low, high) = (
        lane_change.from_l.min(lane_change.to_l) - 0.5 * width,
        lane_change.from_l.max(lane_change.to_l) + 0.5 * width,
    );
    if let Some(state) = expectation
        .states
        .iter()
        .find(|x| !(low..=high).contains(&x.l))
    {
        return Err(UserRefusal::LeavesLanes {
            l: state.l,
            low,
            high,
        });
    }
    let (acceleration, jerk) = lane_change.peak_acceleration_and_jerk();
    if acceleration > MAX_LATERAL_ACCELERATION_MPS2 || jerk > MAX_LATERAL_JERK_MPS3 {
        return Err(UserRefusal::NotSmooth {
            profile: lane_change.profile.name().to_owned(),
            duration_s: lane_change.duration_s,
            acceleration_mps2: acceleration,
            max_acceleration_mps2: MAX_LATERAL_ACCELERATION_MPS2,
            jerk_mps3: jerk,
            max_jerk_mps3: MAX_LATERAL_JERK_MPS3,
        });
    }
    Ok(())
}

impl User for SimulatedUser {
    fn name(&self) -> &str {
        &self.name
    }

    fn nominal(&self, scene: &UserScene<'_>) -> Result<Expectation, UserError> {
        self.expectation(&self.style, &self.family, scene)
    }

    /// The next lane change; a user with spread draws its parameters anew, and
    /// draws again (up to [`MAX_DRAWS`] times) while the drawn lane change fails
    /// its sanity checks, so that one unlucky draw does not end a run.
    fn next(&mut self, scene: &UserScene<'_>) -> Result<Expectation, UserError> {
        let Some(spread) = self.spread.filter(Spread::is_active) else {
            return self.nominal(scene);
        };
        let mut last = None;
        for _ in 0..MAX_DRAWS {
            let Some(rng) = self.rng.as_mut() else { break };
            let (style, family) = spread.draw(&self.style, &self.family, rng);
            match self.expectation(&style, &family, scene) {
                Ok(expectation) => return Ok(expectation),
                Err(error) => last = Some(error),
            }
        }
        Err(last.unwrap_or_else(|| UserError::Refused {
            user: self.name.clone(),
            refusal: UserRefusal::NoSpreadGenerator,
        }))
    }

    fn has_spread(&self) -> bool {
        self.spread.is_some_and(|s| s.is_active())
    }
}
