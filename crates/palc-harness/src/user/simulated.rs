//! The built-in simulated user: a style refined by a family, with an optional
//! spread of its parameters between lane changes.

use palc_planner::State;
use rand_chacha::ChaCha8Rng;

use crate::HarnessError;
use crate::setup::{Setup, target_gaps_safe};
use crate::user::User;
use crate::user::expectation::{
    Expectation, ExpectedLaneChange, MAX_LATERAL_ACCELERATION_MPS2, MAX_LATERAL_JERK_MPS3,
    TakeoverRule,
};
use crate::user::family::{Family, SpeedRule};
use crate::user::profile::TABLE_END_TOLERANCE_M;
use crate::user::situation::Situation;
use crate::user::spread::Spread;
use crate::user::style::Style;

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
    /// [`HarnessError::InvalidConfig`] naming the field of a parameter out of its bound.
    pub fn new(
        name: impl Into<String>,
        style: Style,
        family: Family,
        deviation_m: f64,
        spread: Option<Spread>,
    ) -> Result<Self, HarnessError> {
        style.validate("user.style")?;
        family.validate("user.family")?;
        if !(deviation_m.is_finite() && deviation_m > 0.0) {
            return Err(HarnessError::InvalidConfig {
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
    pub fn paper(style: Style) -> Result<Self, HarnessError> {
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

    /// The lane change a user of `style` and `family` expects in `setup`, checked
    /// for sanity; the error says what failed.
    fn expectation(
        &self,
        style: &Style,
        family: &Family,
        setup: &Setup,
    ) -> Result<Expectation, HarnessError> {
        let refuse = |reason: String| HarnessError::Scenario {
            scenario: setup.label.clone(),
            reason: format!("user `{}`: {reason}", self.name),
        };
        let situations = &setup.situations;
        let dt = setup.dt;
        let window = situations.len().saturating_sub(1);
        let decision_step = situations
            .iter()
            .position(|s| family.start.decides(s, style.time_headway_s))
            .ok_or_else(|| {
                refuse(format!(
                    "its {} start rule is never met within the {:.1} s search window",
                    family.start.name(),
                    window as f64 * dt
                ))
            })?;
        if decision_step == 0 {
            return Err(refuse(format!(
                "its {} start rule is already met when planning starts (time headway {:.2} s): \
                 the user would have changed lanes before the system plans",
                family.start.name(),
                situations[0].time_headway_s
            )));
        }
        let accepting = Style {
            min_lead_gap_s: family.min_lead_gap_s.unwrap_or(style.min_lead_gap_s),
            min_lag_gap_s: family.min_lag_gap_s.unwrap_or(style.min_lag_gap_s),
            ..*style
        };
        // The reaction delay in whole steps, rounding up (1e-9 absorbs a delay
        // that is a multiple of the step up to rounding).
        let reaction_steps = (family.reaction_s / dt - 1e-9).ceil().max(0.0) as usize;
        let earliest = decision_step + reaction_steps;
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
        // (docs/paper-mapping.md, "Users who wait for safe gaps").
        let safety = &setup.safety;
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
            if !safety.users_wait_for_safe_gaps {
                return true;
            }
            let target_speed = target_speed_at(&situations[i], setup.set_speed);
            let mut own = setup.lane_keeping[i];
            (i..=i.saturating_add(duration_steps).min(window)).all(|j| {
                let keeping = setup.lane_keeping[j];
                if j > i {
                    own = match speed_rule_step(family.speed, own[1], target_speed, dt) {
                        Some(v) => [own[0] + 0.5 * (own[1] + v) * dt, v],
                        None => keeping,
                    };
                }
                let seen = situations[j].seen_from(own[0] - keeping[0], own[1]);
                target_gaps_safe(&situations[j], safety) && target_gaps_safe(&seen, safety)
            })
        };
        let start_step = (earliest..=window)
            .find(|&i| accepting.accepts(&situations[i]) && safe(i))
            .ok_or_else(|| {
                refuse(format!(
                    "the target lane's gaps never become acceptable to it (lead {:.2} s, lag \
                     {:.2} s{}) within the search window after its decision at step {decision_step}",
                    accepting.min_lead_gap_s,
                    accepting.min_lag_gap_s,
                    if safety.users_wait_for_safe_gaps {
                        ", and the RSS safe distance at every step of the lane change"
                    } else {
                        ""
                    }
                ))
            })?;
        let lane_change = ExpectedLaneChange {
            start_s: start_step as f64 * dt,
            duration_s,
            from_l: 0.0,
            to_l: setup.target_l,
            profile: family.profile.clone(),
        };
        let target_speed = target_speed_at(&situations[start_step], setup.set_speed);
        let states = expected_states(setup, &lane_change, start_step, family.speed, target_speed);
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
        sanity(&expectation, setup).map_err(refuse)?;
        Ok(expectation)
    }
}

/// The states of the expected lane change: the ego keeping its lane until the
/// start, then moving laterally along the profile at the speed of `speed`.
fn expected_states(
    setup: &Setup,
    lane_change: &ExpectedLaneChange,
    start_step: usize,
    speed: SpeedRule,
    target_speed: f64,
) -> Vec<State> {
    let dt = setup.dt;
    let n = setup.situations.len();
    let mut states: Vec<State> = Vec::with_capacity(n);
    for i in 0..n {
        let [keeping_s, keeping_v] = setup.lane_keeping[i.min(setup.lane_keeping.len() - 1)];
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
fn sanity(expectation: &Expectation, setup: &Setup) -> Result<(), String> {
    let lane_change = &expectation.lane_change;
    let window_s = (setup.situations.len().saturating_sub(1)) as f64 * setup.dt;
    if lane_change.end_s() > window_s + 1e-9 {
        return Err(format!(
            "its lane change ends at {:.2} s, after the {window_s:.1} s search window",
            lane_change.end_s()
        ));
    }
    let width = (lane_change.to_l - lane_change.from_l).abs();
    let start = lane_change.lateral(lane_change.start_s);
    let end = lane_change.lateral(lane_change.end_s());
    if (start - lane_change.from_l).abs() > TABLE_END_TOLERANCE_M
        || (end - lane_change.to_l).abs() > TABLE_END_TOLERANCE_M
    {
        return Err(format!(
            "its lane change goes from l = {start:.3} m to l = {end:.3} m, not from the lane \
             centre at {:.3} m to the target lane's at {:.3} m",
            lane_change.from_l, lane_change.to_l
        ));
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
        return Err(format!(
            "its lane change leaves the two lanes (l = {:.3} m, outside [{low:.3}, {high:.3}] m)",
            state.l
        ));
    }
    let (acceleration, jerk) = lane_change.peak_acceleration_and_jerk();
    if acceleration > MAX_LATERAL_ACCELERATION_MPS2 || jerk > MAX_LATERAL_JERK_MPS3 {
        return Err(format!(
            "its {} profile over {:.2} s is not smooth enough: lateral acceleration {acceleration:.1} \
             m/s² (at most {MAX_LATERAL_ACCELERATION_MPS2}), jerk {jerk:.0} m/s³ (at most \
             {MAX_LATERAL_JERK_MPS3})",
            lane_change.profile.name(),
            lane_change.duration_s
        ));
    }
    Ok(())
}

impl User for SimulatedUser {
    fn name(&self) -> &str {
        &self.name
    }

    fn nominal(&self, setup: &Setup) -> Result<Expectation, HarnessError> {
        self.expectation(&self.style, &self.family, setup)
    }

    /// The next lane change; a user with spread draws its parameters anew, and
    /// draws again (up to [`MAX_DRAWS`] times) while the drawn lane change fails
    /// its sanity checks, so that one unlucky draw does not end a run.
    fn next(&mut self, setup: &Setup) -> Result<Expectation, HarnessError> {
        let Some(spread) = self.spread.filter(Spread::is_active) else {
            return self.nominal(setup);
        };
        let mut last = None;
        for _ in 0..MAX_DRAWS {
            let Some(rng) = self.rng.as_mut() else { break };
            let (style, family) = spread.draw(&self.style, &self.family, rng);
            match self.expectation(&style, &family, setup) {
                Ok(expectation) => return Ok(expectation),
                Err(error) => last = Some(error),
            }
        }
        Err(last.unwrap_or_else(|| HarnessError::Scenario {
            scenario: setup.label.clone(),
            reason: format!("user `{}` has no generator for its spread", self.name),
        }))
    }

    fn has_spread(&self) -> bool {
        self.spread.is_some_and(|s| s.is_active())
    }
}
