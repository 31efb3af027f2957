//! The planning set-up of one scenario: when planning starts, how far it looks
//! ahead, what the surrounding vehicles are predicted to do, and when each user
//! would start.
//!
//! Planning starts at a trigger earlier than any user (a time headway to the
//! preceding vehicle larger than every style's), so that the planner decides
//! when to move laterally with its time-indexed weights (NOTES.md, "Let the
//! planner decide when to move"). The horizon covers the standard ALC's end plus
//! a margin, so that no user's lane change ends after the terminal condition pins
//! the lateral position.

use palc_traffic::{Driver, EgoState, Lane, Scene, ballistic_step};

use crate::HarnessError;
use crate::acc::{AccConfig, acc_leader};
use crate::config::PlanningConfig;
use crate::safety::SafetyConfig;
use palc_user::{ExpectedLaneChange, Situation, Style, StylePreset, UserScene};

use crate::refusal::Refusal;

/// Everything the loop needs about one scenario, computed once at the trigger.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The scenario's label in messages, e.g. `collector-high / 40 m / seed 1 / neutral`.
    pub label: String,
    /// The scene at the trigger; every lane change starts from a clone of it.
    pub scene: Scene,
    /// Time from the scene's start to the trigger (s).
    pub trigger_time_s: f64,
    /// Planning horizon K.
    pub horizon: usize,
    /// Step (s).
    pub dt: f64,
    /// Ego speed at the trigger (m/s).
    pub ego_speed: f64,
    /// The ego's set speed: its speed at the start of the scene (m/s).
    pub set_speed: f64,
    /// The ego's ACC.
    pub acc: AccConfig,
    /// The safe distance of the safety layer.
    pub safety: SafetyConfig,
    /// The ego keeping its lane under its ACC: `(s − origin_s, v)` at steps `0..`
    /// of the search window. Plans take their reference speeds from it.
    pub lane_keeping: Vec<[f64; 2]>,
    /// Ego longitudinal position at the trigger (m); plans use `s` relative to it.
    pub origin_s: f64,
    /// What a user sees at each step `0..` of the search window, the ego keeping its lane.
    pub situations: Vec<Situation>,
    /// Predicted preceding vehicle `(s − origin_s, l)` at steps `0..` of the
    /// search window (plans read steps `0..=K`).
    pub preceding: Vec<[f64; 2]>,
    /// Predicted adjacent vehicle `(s − origin_s, l)` at steps `0..` of the search window.
    pub adjacent: Vec<[f64; 2]>,
    /// Start step of the standard ALC.
    pub standard_start_step: usize,
    /// The standard ALC's style (`planning.standard_alc`): its gap rule is what the
    /// ego's gap seeking waits for, and its lead gap what the relative-onset
    /// prediction assumes a user needs until the user has accepted a smaller one
    /// (not under the safety layer, where it requires the safe distance instead).
    pub standard_alc: Style,
    /// The first step of the search window at which the ego keeping its lane seeks
    /// a gap (as close to the preceding vehicle as the standard ALC's start headway;
    /// from then on it drops back while the gap beside it is not acceptable).
    pub gap_seeking_from: Option<usize>,
    /// Lateral position of the target lane's centre (m).
    pub target_l: f64,
}

impl Setup {
    /// Drives the ego in its lane under its ACC until the trigger, then predicts
    /// the scene over the search window, the ego still keeping its lane under its ACC.
    pub fn new(scene: &Scene, config: &PlanningConfig, label: &str) -> Result<Setup, HarnessError> {
        config.validate()?;
        let refused = |refusal: Refusal| HarnessError::Refused {
            scenario: label.to_owned(),
            refusal: Box::new(refusal),
        };
        let ego = scene.ego().ok_or_else(|| refused(Refusal::NoEgo))?;
        let set_speed = ego.state.v;
        if set_speed.is_nan() || set_speed <= 0.0 {
            return Err(refused(Refusal::EgoNotMoving {
                speed_mps: set_speed,
            }));
        }
        if scene.preceding().is_none() {
            return Err(refused(Refusal::NoPreceding));
        }

        let mut scene = scene.clone();
        let approach_steps = (config.max_approach_s / config.dt).ceil() as usize;
        let mut trigger = None;
        for step in 0..=approach_steps {
            if situation(&scene).time_headway_s <= config.trigger_time_headway_s {
                trigger = Some(step);
                break;
            }
            lane_keeping_step(&mut scene, config, set_speed, None)?;
        }
        if trigger.is_none() {
            return Err(refused(Refusal::NeverTriggers {
                trigger_time_headway_s: config.trigger_time_headway_s,
                max_approach_s: config.max_approach_s,
            }));
        }
        let trigger_time_s = scene.time();
        let origin_s = scene.ego().map_or(0.0, |e| e.state.s);
        let ego_speed = scene.ego().map_or(set_speed, |e| e.state.v);
        if ego_speed <= 0.0 {
            return Err(refused(Refusal::StoppedBeforeTrigger {
                speed_mps: ego_speed,
            }));
        }

        let window = (config.search_window_s / config.dt).ceil() as usize;
        let mut rollout = scene.clone();
        let mut situations = Vec::with_capacity(window + 1);
        let mut preceding = Vec::with_capacity(window + 1);
        let mut adjacent = Vec::with_capacity(window + 1);
        let mut lane_keeping = Vec::with_capacity(window + 1);
        let mut gap_seeking_from = None;
        for step in 0..=window {
            situations.push(situation(&rollout));
            lane_keeping.push(
                rollout
                    .ego()
                    .map_or([0.0, ego_speed], |e| [e.state.s - origin_s, e.state.v]),
            );
            preceding.push(relative(
                rollout.preceding().map(|v| (v.state.s, v.state.l)),
                origin_s,
            ));
            adjacent.push(relative(
                rollout.adjacent().map(|v| (v.state.s, v.state.l)),
                origin_s,
            ));
            // The ego seeks a gap once it is as close to the preceding vehicle as
            // the standard ALC's start headway, so that every user (whose headway
            // is longer) has decided to change lanes; the search then goes on.
            if gap_seeking_from.is_none()
                && situations[step].decides_at(config.standard_alc.time_headway_s)
            {
                gap_seeking_from = Some(step);
            }
            if step < window {
                lane_keeping_step(
                    &mut rollout,
                    config,
                    set_speed,
                    gap_seeking_from.map(|_| &situations[step]),
                )?;
            }
        }

        let standard = &config.standard_alc;
        let own_start = standard.start_step(&situations).ok_or_else(|| {
            refused(Refusal::StandardNeverStarts {
                window_s: config.search_window_s,
            })
        })?;
        let mut latest_user = 0;
        for style in StylePreset::ALL.map(StylePreset::style) {
            let start = style.start_step(&situations).ok_or_else(|| {
                refused(Refusal::StyleNeverStarts {
                    time_headway_s: style.time_headway_s,
                    window_s: config.search_window_s,
                })
            })?;
            latest_user = latest_user.max(start);
        }
        let delay = (config.standard_alc_min_delay_s / config.dt).ceil() as usize;
        let duration = (standard.lane_change_duration_s / config.dt).ceil() as usize;
        let earliest = own_start.max(latest_user + delay);
        // Nobody, the system included, starts behind a vehicle it has reached.
        let behind = |start: usize| situations[start].time_headway_s > 0.0;
        let standard_start_step = (earliest..=window.saturating_sub(duration))
            .find(|&start| {
                behind(start)
                    && (!config.safety.enforce
                        || (situations.get(start..=start + duration))
                            .is_some_and(|w| w.iter().all(|s| target_gaps_safe(s, &config.safety))))
            })
            .ok_or_else(|| {
                let (duration_s, window_s) =
                    (standard.lane_change_duration_s, config.search_window_s);
                refused(if config.safety.enforce {
                    Refusal::StandardGapsUnsafe {
                        duration_s,
                        window_s,
                    }
                } else {
                    Refusal::StandardBehindPreceding {
                        duration_s,
                        window_s,
                        time_headway_s: situations
                            .get(earliest)
                            .map_or(f64::NAN, |s| s.time_headway_s),
                        delay_steps: delay,
                    }
                })
            })?;
        let end_s = standard_start_step as f64 * config.dt
            + standard.lane_change_duration_s
            + config.horizon_margin_s;
        let horizon = (end_s / config.dt).ceil() as usize;
        if horizon > window {
            return Err(refused(Refusal::HorizonBeyondWindow { horizon, window }));
        }
        Ok(Setup {
            label: label.to_owned(),
            scene,
            trigger_time_s,
            horizon,
            dt: config.dt,
            ego_speed,
            set_speed,
            acc: config.acc,
            safety: config.safety,
            lane_keeping,
            origin_s,
            situations,
            preceding,
            adjacent,
            standard_start_step,
            standard_alc: config.standard_alc,
            gap_seeking_from,
            target_l: config.target_l,
        })
    }

    /// The scene's ego state of a plan state (plan frame, `s` from the trigger).
    pub(crate) fn ego_state(&self, state: &palc_planner::State) -> EgoState {
        EgoState {
            s: state.s + self.origin_s,
            l: state.l,
            v: state.v.max(0.0),
            heading: state.phi,
        }
    }

    /// The scenario as a user sees it: plain numbers, no harness types.
    pub fn user_scene(&self) -> UserScene<'_> {
        UserScene {
            dt: self.dt,
            situations: &self.situations,
            lane_keeping: &self.lane_keeping,
            set_speed: self.set_speed,
            target_l: self.target_l,
            safe_gaps: (self.safety.users_wait_for_safe_gaps).then(|| self.safety.rss()),
        }
    }

    /// The lane change a user of `style` expects in this scenario, or `None` when
    /// the user would not start within the horizon.
    pub fn expected(&self, style: &Style) -> Option<ExpectedLaneChange> {
        let start = style.start_step(&self.situations[..=self.horizon])?;
        let expected = ExpectedLaneChange::quintic(
            start as f64 * self.dt,
            style.lane_change_duration_s,
            0.0,
            self.target_l,
        );
        (expected.end_s() <= self.horizon as f64 * self.dt + 1e-9).then_some(expected)
    }

    /// The acceleration of the ego keeping its lane in `scene` at `step` of the
    /// search window: the ACC and, from [`Setup::gap_seeking_from`] on, the gap
    /// seeking of the lane-keeping prediction ([`Setup::lane_keeping`]), so that a
    /// driver who keeps its lane moves as that prediction.
    pub(crate) fn lane_keeping_acceleration(&self, scene: &Scene, step: usize) -> f64 {
        let seeking = self.gap_seeking_from.is_some_and(|from| step >= from);
        let seen = seeking.then(|| situation(scene));
        lane_keeping_acceleration(
            scene,
            &self.acc,
            &self.safety,
            &self.standard_alc,
            self.set_speed,
            seen.as_ref(),
        )
    }

    /// The standard ALC's own lane change in this scenario.
    pub fn standard_lane_change(&self, standard: &Style) -> ExpectedLaneChange {
        ExpectedLaneChange::quintic(
            self.standard_start_step as f64 * self.dt,
            standard.lane_change_duration_s,
            0.0,
            self.target_l,
        )
    }

    /// Extends the horizon so that it covers a lane change ending at `end_s` plus
    /// `margin_s` (a user who changes lanes after the standard ALC). Never shortens it.
    ///
    /// # Errors
    /// [`HarnessError::Refused`] when that horizon exceeds the search window.
    pub fn cover(&mut self, end_s: f64, margin_s: f64) -> Result<(), HarnessError> {
        let needed = ((end_s + margin_s) / self.dt - 1e-9).ceil().max(0.0) as usize;
        let window = self.situations.len().saturating_sub(1);
        if needed > window {
            return Err(HarnessError::Refused {
                scenario: self.label.clone(),
                refusal: Box::new(Refusal::LaneChangeBeyondWindow {
                    end_s,
                    needed,
                    window,
                }),
            });
        }
        self.horizon = self.horizon.max(needed);
        Ok(())
    }

    /// Checks the paper's premise in this scenario: the standard ALC starts later and
    /// moves slower than each style. Returns what does not hold, naming the style.
    pub fn check_conservative(
        &self,
        standard: &Style,
        styles: &[StylePreset],
    ) -> Result<(), Refusal> {
        let standard_start = self.standard_start_step as f64 * self.dt;
        for preset in styles {
            let (name, style) = (preset.name().to_owned(), preset.style());
            let Some(expected) = self.expected(&style) else {
                return Err(Refusal::StyleNotWithinHorizon { style: name });
            };
            if expected.start_s >= standard_start {
                return Err(Refusal::StandardNotLater {
                    standard_start_s: standard_start,
                    style: name,
                    user_start_s: expected.start_s,
                });
            }
            if style.lane_change_duration_s >= standard.lane_change_duration_s {
                return Err(Refusal::StandardNotSlower {
                    standard_duration_s: standard.lane_change_duration_s,
                    style: name,
                    user_duration_s: style.lane_change_duration_s,
                });
            }
        }
        Ok(())
    }
}

/// Whether both target-lane gaps in `situation` are at least the safe distance:
/// the ego behind the lead, the lag behind the ego.
pub(crate) fn target_gaps_safe(situation: &Situation, safety: &SafetyConfig) -> bool {
    safety.rss().target_gaps_safe(situation)
}

/// The acceleration of the ego keeping its lane under its ACC; when seeking a gap
/// (`seeking` holds what the ego sees now), it also drops back while the gap
/// beside it is neither acceptable to the standard ALC nor safe, below the target
/// lane's speed, so that the next gap comes alongside.
fn lane_keeping_acceleration(
    scene: &Scene,
    acc: &AccConfig,
    safety: &SafetyConfig,
    standard_alc: &Style,
    set_speed: f64,
    seeking: Option<&Situation>,
) -> f64 {
    let ego = scene.ego().map(|e| e.state).unwrap_or_default();
    let leader = acc_leader(scene);
    let acceleration = acc.ego_acceleration(ego.v, set_speed, leader, safety);
    let unacceptable =
        |seen: &&Situation| !(standard_alc.accepts(seen) && target_gaps_safe(seen, safety));
    let Some(seen) = seeking.filter(unacceptable).filter(|_| acc.enabled) else {
        return acceleration;
    };
    let flow = [seen.target_lead_speed, seen.target_lag_speed]
        .into_iter()
        .flatten()
        .min_by(f64::total_cmp);
    match flow {
        Some(flow) => {
            let target = (flow - acc.gap_seeking_speed_mps).max(0.0);
            let drop_back =
                (acc.cruise_gain * (target - ego.v)).max(-acc.comfort_deceleration_mps2);
            acceleration.min(drop_back)
        }
        None => acceleration,
    }
}

/// One simulation step with the ego keeping its lane
/// ([`lane_keeping_acceleration`]).
fn lane_keeping_step(
    scene: &mut Scene,
    config: &PlanningConfig,
    set_speed: f64,
    seeking: Option<&Situation>,
) -> Result<(), HarnessError> {
    let ego = scene.ego().map(|e| e.state).unwrap_or_default();
    let acceleration = lane_keeping_acceleration(
        scene,
        &config.acc,
        &config.safety,
        &config.standard_alc,
        set_speed,
        seeking,
    );
    let moved = ballistic_step(ego.v, acceleration, config.dt);
    let next = EgoState {
        s: ego.s + moved.distance,
        l: ego.l,
        v: moved.speed,
        heading: 0.0,
    };
    scene.step(config.dt, next)?;
    Ok(())
}

/// What a user sees in the scene: headway to the preceding vehicle, net gap to the
/// nearest vehicle ahead on the target lane.
pub(crate) fn situation(scene: &Scene) -> Situation {
    let ego = scene.ego().map(|e| e.state).unwrap_or_default();
    let ego_speed = ego.v.max(1e-6);
    let headway_gap = scene
        .preceding()
        .map_or(f64::INFINITY, |p| p.rear() - ego.s);
    let ego_rear = scene.ego().map_or(ego.s, |e| e.rear());
    // The ego itself is on the target lane once it has moved over: not its own lag.
    let target_lane = (scene.vehicles().iter())
        .filter(|v| v.lane == Lane(1) && !matches!(v.driver, Driver::External { .. }));
    let lead = target_lane
        .clone()
        .filter(|v| v.state.s > ego.s)
        .min_by(|a, b| a.state.s.total_cmp(&b.state.s));
    let lag = target_lane
        .filter(|v| v.state.s <= ego.s)
        .max_by(|a, b| a.state.s.total_cmp(&b.state.s));
    Situation {
        time_headway_s: headway_gap / ego_speed,
        preceding_gap_m: headway_gap,
        preceding_speed: scene.preceding().map(|p| p.state.v),
        target_lead_gap_m: lead.map(|v| v.rear() - ego.s),
        target_lag_gap_m: lag.map(|v| ego_rear - v.state.s),
        ego_speed,
        target_lead_speed: lead.map(|v| v.state.v),
        target_lag_speed: lag.map(|v| v.state.v),
    }
}

fn relative(position: Option<(f64, f64)>, origin_s: f64) -> [f64; 2] {
    // A missing vehicle is placed far ahead on its lane, where it affects nothing.
    position.map_or([1e4, 0.0], |(s, l)| [s - origin_s, l])
}
