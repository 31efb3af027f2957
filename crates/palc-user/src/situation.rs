//! What a user sees at one step: the gaps to the vehicles around the ego.

/// What the user sees at one step: the preceding vehicle on the ego's lane and
/// the nearest vehicles ahead and behind on the target lane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Situation {
    /// Time headway to the preceding vehicle: net gap / ego speed (s).
    pub time_headway_s: f64,
    /// Net gap to the preceding vehicle (m); infinite when there is none.
    pub preceding_gap_m: f64,
    /// Speed of the preceding vehicle (m/s); `None` when there is none.
    pub preceding_speed: Option<f64>,
    /// Net gap to the leader on the target lane (m); `None` when there is none.
    pub target_lead_gap_m: Option<f64>,
    /// Net gap to the follower on the target lane (m); `None` when there is none.
    /// Negative while that vehicle is alongside the ego.
    pub target_lag_gap_m: Option<f64>,
    /// Ego speed (m/s).
    pub ego_speed: f64,
    /// Speed of the leader on the target lane (m/s); `None` when there is none.
    pub target_lead_speed: Option<f64>,
    /// Speed of the follower on the target lane (m/s); `None` when there is none.
    pub target_lag_speed: Option<f64>,
}

impl Situation {
    /// The same scene seen from an ego `ahead_m` further along its lane (negative:
    /// behind) at `ego_speed`: the target lane's gaps shifted by that distance (the
    /// lead's shorter, the lag's longer), the vehicles where they were.
    pub fn seen_from(&self, ahead_m: f64, ego_speed: f64) -> Situation {
        Situation {
            target_lead_gap_m: self.target_lead_gap_m.map(|gap| gap - ahead_m),
            target_lag_gap_m: self.target_lag_gap_m.map(|gap| gap + ahead_m),
            ego_speed,
            ..*self
        }
    }

    /// Whether the time headway to the preceding vehicle is positive and at most
    /// `time_headway_s`.
    pub fn decides_at(&self, time_headway_s: f64) -> bool {
        self.time_headway_s > 0.0 && self.time_headway_s <= time_headway_s
    }

    /// Time to collision with the preceding vehicle (s): the net gap over the
    /// closing speed; infinite when the ego does not close on it.
    pub fn preceding_ttc_s(&self) -> f64 {
        let closing = self.ego_speed - self.preceding_speed.unwrap_or(f64::INFINITY);
        if closing > 0.0 {
            self.preceding_gap_m.max(0.0) / closing
        } else {
            f64::INFINITY
        }
    }

    /// Whether a target-lane vehicle is beside the ego: present, with a net gap
    /// of zero or less (their lengths overlap). Nobody steers into a vehicle
    /// beside them.
    pub fn target_vehicle_beside(&self) -> bool {
        self.target_lead_gap_m.is_some_and(|g| g <= 0.0)
            || self.target_lag_gap_m.is_some_and(|g| g <= 0.0)
    }

    /// The target lane's leader as `(net gap as a time gap at the ego's speed,
    /// time to collision)` (s); the time to collision is infinite when not closing.
    pub fn target_lead_times_s(&self) -> Option<(f64, f64)> {
        let (gap, speed) = (self.target_lead_gap_m?, self.target_lead_speed?);
        Some(gap_times(gap, self.ego_speed, self.ego_speed - speed))
    }

    /// The target lane's follower as `(net gap as a time gap at the follower's
    /// speed, time to collision)` (s).
    pub fn target_lag_times_s(&self) -> Option<(f64, f64)> {
        let (gap, speed) = (self.target_lag_gap_m?, self.target_lag_speed?);
        Some(gap_times(gap, speed, speed - self.ego_speed))
    }
}

/// `(gap / rear speed, gap / closing speed)`, each infinite when its divisor is not positive.
fn gap_times(gap: f64, rear_speed: f64, closing: f64) -> (f64, f64) {
    let over = |divisor: f64| {
        if divisor > 0.0 {
            gap / divisor
        } else if gap > 0.0 {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        }
    };
    (
        over(rear_speed),
        if closing > 0.0 {
            gap.max(0.0) / closing
        } else {
            f64::INFINITY
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seen() -> Situation {
        Situation {
            time_headway_s: 1.0,
            preceding_gap_m: 20.0,
            preceding_speed: Some(15.0),
            target_lead_gap_m: Some(10.0),
            target_lag_gap_m: Some(-2.0),
            ego_speed: 20.0,
            target_lead_speed: Some(25.0),
            target_lag_speed: Some(22.0),
        }
    }

    #[test]
    fn times_to_collision_divide_the_gap_by_the_closing_speed() {
        let s = seen();
        assert!((s.preceding_ttc_s() - 4.0).abs() < 1e-12);
        let (gap, ttc) = s.target_lead_times_s().unwrap();
        assert!((gap - 0.5).abs() < 1e-12 && ttc.is_infinite());
        let (gap, ttc) = s.target_lag_times_s().unwrap();
        assert!((gap + 2.0 / 22.0).abs() < 1e-12 && ttc == 0.0);
        let alone = Situation {
            preceding_speed: None,
            target_lead_gap_m: None,
            ..s
        };
        assert!(alone.preceding_ttc_s().is_infinite());
        assert!(alone.target_lead_times_s().is_none());
    }
}
