//! What the gap-acceptance set reads in a [`Situation`] and an [`Onset`]: the
//! value of a cue of the vehicle ahead whose fall to a threshold decides the
//! lane change (the driver model's [`Cue`], of which the set reads
//! [`READ_BY_THE_READINGS`]), and the target lane's gaps to its leader and
//! follower as time gaps.

use palc_aggregator::Onset;
use palc_user::Situation;

use crate::driver::READ_BY_THE_READINGS;
use crate::driver::prior::Cue;

/// The target-lane gaps as time gaps (s): `(lead, lag)`.
pub(crate) fn lead_time_gap(s: &Situation) -> Option<f64> {
    s.target_lead_times_s().map(|(gap, _)| gap)
}
pub(crate) fn lag_time_gap(s: &Situation) -> Option<f64> {
    s.target_lag_times_s().map(|(gap, _)| gap)
}
pub(crate) fn ttc(s: &Situation) -> Option<f64> {
    Some(s.preceding_ttc_s()).filter(|t| t.is_finite())
}

/// `cue`'s value at `s` as a threshold decision reads it: behind a vehicle ahead
/// (a positive time headway), and finite; `None` for a cue the set does not
/// read. The value is the cue's urgency negated ([`Cue::urgency`]: the rule at
/// threshold `θ` decides where the value is at most `θ`), so the driver model
/// defines it once.
pub(crate) fn cue_value(cue: Cue, s: &Situation) -> Option<f64> {
    // The set speed enters the incentive only, which the set does not read.
    (READ_BY_THE_READINGS.contains(&cue))
        .then(|| -cue.urgency(s, 0.0))
        .filter(|x| x.is_finite())
}

/// `cue`'s value an onset recorded at its start; `None` for a cue the set does
/// not read or an onset without it.
pub(crate) fn onset_value(cue: Cue, onset: &Onset) -> Option<f64> {
    match cue {
        Cue::TimeHeadway => Some(onset.time_headway_s),
        Cue::TimeToCollision => onset.ttc_s,
        Cue::DistanceGap => Some(onset.gap_m),
        Cue::Incentive | Cue::HeadwayOrTtc => None,
    }
}
