//! Safety of a lane change: gaps, times to collision, collisions and the RSS
//! longitudinal safe distance, measured step by step in the scene; and the check
//! that the safety layer applies to every plan before the ego drives it.
//!
//! Which vehicles count at a step: those in a lane that the ego's body occupies
//! (the scene's occupancy rule, [`palc_traffic::Road::occupies`]). Their roles:
//! the scene's preceding vehicle, and the leader and follower on the target lane
//! (the nearest ahead and behind, as the ego sees them at that step).
//!
//! The safe distance is the longitudinal one of the Responsibility-Sensitive Safety
//! model (Shalev-Shwartz, Shammah and Shashua, 2017, Definition 1): a rear vehicle
//! at `v_r` behind a front vehicle at `v_f` keeps at least
//!
//! ```text
//! d_min = [ v_r ρ + ½ a_acc ρ² + (v_r + ρ a_acc)² / (2 b_min) − v_f² / (2 b_max) ]⁺
//! ```
//!
//! The ego is responsible for the distance to every vehicle ahead of it in a lane
//! it occupies, and for the distance to every vehicle behind it in a lane it has
//! entered (a cut-in); the vehicle behind it in its own lane keeps its own distance.
//! A collision is an overlap of the two footprints (length × width rectangles
//! aligned with the road).

use palc_traffic::{Driver, Lane, Scene, Vehicle};
use serde::{Deserialize, Serialize};

use crate::HarnessError;

/// Parameters of the RSS safe distance; defaults in `configs/learn.toml` (`[safety]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SafetyConfig {
    /// Whether the safety layer acts: refuses unsafe plans (driving the standard
    /// ALC's instead), makes the standard ALC wait for safe target-lane gaps and
    /// refuses scenes without a safe lane change. Off by default: in the paper's
    /// scenes, where the ego closes on the preceding vehicle at constant speed, no
    /// lane change keeps the RSS distance to it
    /// (docs/experiments/0031-the-safety-layer-and-the-papers-scenes.md). The
    /// measures are taken either way.
    pub enforce: bool,
    /// Whether the simulated users of this configuration start their lane change
    /// only when both target-lane gaps stay at least the safe distance below at
    /// every step of the lane change started there (on the ego's lane-keeping
    /// motion), besides their style's own gap acceptance: users whose preferred
    /// lane change is safe. Off by default: the paper's users accept any positive
    /// gap behind them (docs/experiments/0038-users-who-wait-for-safe-gaps.md).
    pub users_wait_for_safe_gaps: bool,
    /// Response time `ρ` of the rear vehicle (s).
    pub response_time_s: f64,
    /// Largest acceleration `a_acc` of the rear vehicle during its response (m/s²).
    pub max_acceleration_mps2: f64,
    /// Smallest braking `b_min` the rear vehicle applies after its response (m/s²).
    pub min_braking_mps2: f64,
    /// Largest braking `b_max` of the front vehicle (m/s²).
    pub max_braking_mps2: f64,
}

impl Default for SafetyConfig {
    /// ρ = 0.5 s, the response time of an automated system (a human's is 1-1.5 s);
    /// a_acc = 1.5 m/s², the ego ACC's own limit; and `b_min = b_max` = 6 m/s²:
    /// vehicles of one class that brake alike
    /// (docs/experiments/0030-safety-measures-acc-and-gap-seeking.md).
    fn default() -> Self {
        Self {
            enforce: false,
            users_wait_for_safe_gaps: false,
            response_time_s: 0.5,
            max_acceleration_mps2: 1.5,
            min_braking_mps2: 6.0,
            max_braking_mps2: 6.0,
        }
    }
}

impl SafetyConfig {
    /// Checks every field against its bound.
    pub fn validate(&self, table: &str) -> Result<(), HarnessError> {
        let fields = [
            ("response_time_s", self.response_time_s, 0.0, 5.0),
            (
                "max_acceleration_mps2",
                self.max_acceleration_mps2,
                0.0,
                10.0,
            ),
            ("min_braking_mps2", self.min_braking_mps2, 0.1, 15.0),
            ("max_braking_mps2", self.max_braking_mps2, 0.1, 15.0),
        ];
        for (name, value, min, max) in fields {
            if !(value.is_finite() && (min..=max).contains(&value)) {
                return Err(HarnessError::InvalidConfig {
                    field: format!("{table}.{name}"),
                    value,
                    bound: format!("a value in [{min:?}, {max:?}]"),
                });
            }
        }
        if self.min_braking_mps2 > self.max_braking_mps2 {
            return Err(HarnessError::InvalidConfig {
                field: format!("{table}.min_braking_mps2"),
                value: self.min_braking_mps2,
                bound: format!(
                    "at most `{table}.max_braking_mps2` = {:?}",
                    self.max_braking_mps2
                ),
            });
        }
        Ok(())
    }

    /// The RSS safe distance (m) of a rear vehicle at `rear_v` behind a front one at `front_v`.
    pub fn safe_distance(&self, rear_v: f64, front_v: f64) -> f64 {
        self.rss().distance(rear_v, front_v)
    }

    /// The RSS parameters, as a user sees them ([`palc_user::SafeDistance`]).
    pub fn rss(&self) -> palc_user::SafeDistance {
        palc_user::SafeDistance {
            response_time_s: self.response_time_s,
            max_acceleration_mps2: self.max_acceleration_mps2,
            min_braking_mps2: self.min_braking_mps2,
            max_braking_mps2: self.max_braking_mps2,
        }
    }
}

pub use crate::violation::{Role, Violation};

/// What the safety measures found over one lane change.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SafetyMetrics {
    /// Smallest net gap to the preceding vehicle while in its lane (m).
    pub min_gap_preceding_m: Option<f64>,
    /// Smallest net gap to the target-lane lead vehicle while in the target lane (m).
    pub min_gap_target_lead_m: Option<f64>,
    /// Smallest net gap to the target-lane lag vehicle while in the target lane (m).
    pub min_gap_target_lag_m: Option<f64>,
    /// Smallest time to collision with the preceding vehicle (s), closing steps only.
    pub min_ttc_preceding_s: Option<f64>,
    /// Smallest time to collision with the target-lane lead vehicle (s).
    pub min_ttc_target_lead_s: Option<f64>,
    /// Smallest time to collision with the target-lane lag vehicle (s).
    pub min_ttc_target_lag_s: Option<f64>,
    /// Whether the ego's footprint overlapped another vehicle's at any step.
    pub collision: bool,
    /// Steps at which a gap the ego is responsible for was below the safe distance,
    /// or at which the footprints overlapped.
    pub rss_violations: usize,
    /// The first of them; `None` exactly when the lane change was safe.
    pub first_violation: Option<Violation>,
}

impl SafetyMetrics {
    /// Whether the lane change was free of collisions and safe-distance violations.
    pub fn is_safe(&self) -> bool {
        !self.collision && self.rss_violations == 0
    }

    /// The smallest net gap to any of the three vehicles (m).
    pub fn min_gap_m(&self) -> Option<f64> {
        [
            self.min_gap_preceding_m,
            self.min_gap_target_lead_m,
            self.min_gap_target_lag_m,
        ]
        .into_iter()
        .flatten()
        .min_by(f64::total_cmp)
    }

    /// The smallest time to collision with any of the three vehicles (s).
    pub fn min_ttc_s(&self) -> Option<f64> {
        [
            self.min_ttc_preceding_s,
            self.min_ttc_target_lead_s,
            self.min_ttc_target_lag_s,
        ]
        .into_iter()
        .flatten()
        .min_by(f64::total_cmp)
    }
}

/// Measures the safety of one lane change, one scene step at a time.
#[derive(Debug, Clone)]
pub struct SafetyMonitor {
    config: SafetyConfig,
    start_lane: Lane,
    target_lane: Lane,
    preceding: Option<u32>,
    metrics: SafetyMetrics,
}

impl SafetyMonitor {
    /// A monitor for a lane change from the ego's lane in `scene` to the lane whose
    /// centre is nearest `target_l`.
    pub fn new(config: SafetyConfig, scene: &Scene, target_l: f64) -> Self {
        let start_lane = scene.ego().map_or(Lane(0), |e| e.lane);
        Self {
            config,
            start_lane,
            target_lane: scene.road().nearest_lane(target_l),
            preceding: scene.preceding().map(|v| v.id.0),
            metrics: SafetyMetrics::default(),
        }
    }

    /// Measures the scene at `step`.
    pub fn observe(&mut self, step: usize, scene: &Scene) {
        let Some(ego) = scene.ego() else { return };
        let road = scene.road();
        let mut worst: Option<Violation> = None;
        let others = || {
            scene
                .vehicles()
                .iter()
                .filter(|v| !matches!(v.driver, Driver::External { .. }))
        };
        // The target lane's lead and lag: its nearest vehicles ahead of and behind the ego.
        let nearest_on_target = |ahead: bool| {
            others()
                .filter(|v| v.lane == self.target_lane && (v.state.s > ego.state.s) == ahead)
                .min_by(|a, b| {
                    (a.state.s - ego.state.s)
                        .abs()
                        .total_cmp(&(b.state.s - ego.state.s).abs())
                })
                .map(|v| v.id.0)
        };
        let (lead, lag) = (nearest_on_target(true), nearest_on_target(false));
        for other in others() {
            let collided = overlap(ego, other);
            self.metrics.collision |= collided;
            if !collided && !road.occupies(ego.state.l, ego.width, other.lane) {
                continue;
            }
            let ahead = other.state.s > ego.state.s;
            let (gap, rear_v, front_v) = if ahead {
                (other.rear() - ego.state.s, ego.state.v, other.state.v)
            } else {
                (ego.rear() - other.state.s, other.state.v, ego.state.v)
            };
            let role = match Some(other.id.0) {
                id if id == self.preceding => Role::Preceding,
                id if id == lead => Role::TargetLead,
                id if id == lag => Role::TargetLag,
                _ => Role::Other,
            };
            let closing = rear_v - front_v;
            let ttc = (closing > 0.0).then(|| gap.max(0.0) / closing);
            let (gap_slot, ttc_slot) = match role {
                Role::Preceding => (
                    &mut self.metrics.min_gap_preceding_m,
                    &mut self.metrics.min_ttc_preceding_s,
                ),
                Role::TargetLead => (
                    &mut self.metrics.min_gap_target_lead_m,
                    &mut self.metrics.min_ttc_target_lead_s,
                ),
                Role::TargetLag => (
                    &mut self.metrics.min_gap_target_lag_m,
                    &mut self.metrics.min_ttc_target_lag_s,
                ),
                Role::Other => (&mut None, &mut None),
            };
            *gap_slot = Some(gap_slot.map_or(gap, |g: f64| g.min(gap)));
            if let Some(ttc) = ttc {
                *ttc_slot = Some(ttc_slot.map_or(ttc, |t: f64| t.min(ttc)));
            }
            let responsible = ahead || other.lane != self.start_lane;
            let safe = self.config.safe_distance(rear_v, front_v);
            if collided || (responsible && gap < safe) {
                let violation = Violation {
                    step,
                    role,
                    vehicle: other.id.0,
                    gap_m: gap,
                    safe_distance_m: safe,
                };
                let shortfall = |v: &Violation| v.safe_distance_m - v.gap_m;
                if worst.is_none_or(|w| shortfall(&violation) > shortfall(&w)) {
                    worst = Some(violation);
                }
            }
        }
        if let Some(violation) = worst {
            self.metrics.rss_violations += 1;
            self.metrics.first_violation.get_or_insert(violation);
        }
    }

    /// What was measured.
    pub fn metrics(&self) -> SafetyMetrics {
        self.metrics
    }
}

/// Whether the footprints of `a` and `b` (length × width, aligned with the road) overlap.
fn overlap(a: &Vehicle, b: &Vehicle) -> bool {
    let lateral = (a.state.l - b.state.l).abs() < 0.5 * (a.width + b.width);
    let longitudinal = a.rear() < b.state.s && b.rear() < a.state.s;
    lateral && longitudinal
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_safe_distance_follows_the_rss_formula() {
        let config = SafetyConfig::default();
        // Equal speeds and equal braking: v ρ + ½ a ρ² + ((v + ρ a)² − v²) / (2 b).
        let v: f64 = 20.0;
        let expected = v * 0.5 + 0.5 * 1.5 * 0.25 + ((v + 0.75).powi(2) - v * v) / 12.0;
        assert!((config.safe_distance(v, v) - expected).abs() < 1e-12);
        // A front vehicle much faster than the rear one needs no distance.
        assert_eq!(config.safe_distance(5.0, 30.0), 0.0);
        // Monotone: faster rear, larger distance; faster front, smaller.
        assert!(config.safe_distance(25.0, 20.0) > config.safe_distance(20.0, 20.0));
        assert!(config.safe_distance(20.0, 25.0) < config.safe_distance(20.0, 20.0));
    }

    #[test]
    fn bad_parameters_name_their_field() {
        SafetyConfig::default().validate("safety").unwrap();
        let bad = SafetyConfig {
            min_braking_mps2: 0.0,
            ..SafetyConfig::default()
        };
        let err = bad.validate("safety").unwrap_err().to_string();
        assert!(err.contains("safety.min_braking_mps2"), "{err}");
    }

    #[test]
    fn a_violation_reads_as_a_sentence() {
        let violation = Violation {
            step: 37,
            role: Role::TargetLag,
            vehicle: 4,
            gap_m: 6.12,
            safe_distance_m: 14.2,
        };
        assert_eq!(
            violation.to_string(),
            "unsafe gap: target-lane lag vehicle 4 at 6.1 m, safe distance 14.2 m at step 37"
        );
    }
}
