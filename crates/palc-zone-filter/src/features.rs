//! The feature map of Eq. (1) and its configurable variants.

use serde::{Deserialize, Serialize};

use crate::error::{ZoneError, check_finite};

/// The largest number of features any [`FeatureSet`] produces.
pub const MAX_FEATURES: usize = 6;

/// Which relative features describe a position (Eq. 1 and variants for experiments).
///
/// Every set is computed by [`features`], the single place where features are
/// made. Signs: `ds = s_other - s_ego`, `dl = l_other - l_ego`, so a vehicle
/// ahead has `ds > 0` and a vehicle to the left has `dl > 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeatureSet {
    /// The paper's six features, Eq. (1): `[ds_p, dl_p, dist_p, ds_a, dl_a, dist_a]`,
    /// with `dist` the Euclidean distance `sqrt(ds^2 + dl^2)` in metres.
    #[default]
    Paper,
    /// The paper's features without the distance columns: `[ds_p, dl_p, ds_a, dl_a]`.
    ///
    /// `dist` is almost collinear with `ds` whenever `|ds| >> |dl|` (NOTES.md,
    /// "Feature conditioning"); this set removes that near-singularity.
    NoDistance,
    /// Time gaps instead of longitudinal gaps: `[ds_p / v, dl_p, ds_a / v, dl_a]`,
    /// with `v` the ego speed (s, m, s, m). Meant to transfer between speeds.
    TimeGap,
}

impl FeatureSet {
    /// The number of features this set produces.
    pub const fn dimension(self) -> usize {
        match self {
            FeatureSet::Paper => 6,
            FeatureSet::NoDistance | FeatureSet::TimeGap => 4,
        }
    }

    /// Column names, in order, as used in CSV files.
    pub const fn names(self) -> &'static [&'static str] {
        match self {
            FeatureSet::Paper => &["ds_p", "dl_p", "dist_p", "ds_a", "dl_a", "dist_a"],
            FeatureSet::NoDistance => &["ds_p", "dl_p", "ds_a", "dl_a"],
            FeatureSet::TimeGap => &["tg_p", "dl_p", "tg_a", "dl_a"],
        }
    }
}

/// Where the ego and the two surrounding vehicles are, in Frenet coordinates (m, m/s).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FeatureInput {
    /// Ego longitudinal position s (m).
    pub ego_s: f64,
    /// Ego lateral position l (m, positive to the left).
    pub ego_l: f64,
    /// Ego speed (m/s); used only by [`FeatureSet::TimeGap`].
    pub ego_speed: f64,
    /// Preceding vehicle `[s, l]` (m).
    pub preceding: [f64; 2],
    /// Adjacent vehicle on the target lane `[s, l]` (m).
    pub adjacent: [f64; 2],
}

/// Fills `out[..set.dimension()]` with the features of `input` (Eq. 1 or a variant).
///
/// This is the one function that makes features; [`features`] wraps it.
/// It allocates nothing, so the zone projection can call it per grid point.
///
/// # Errors
/// [`ZoneError::NonFinite`] for a NaN or infinite input,
/// [`ZoneError::NonPositiveSpeed`] for the time-gap set with `ego_speed <= 0`,
/// [`ZoneError::LengthMismatch`] if `out` is shorter than the dimension.
pub fn features_into(
    set: FeatureSet,
    input: &FeatureInput,
    out: &mut [f64],
) -> Result<(), ZoneError> {
    let named = [
        ("ego_s", input.ego_s),
        ("ego_l", input.ego_l),
        ("preceding.s", input.preceding[0]),
        ("preceding.l", input.preceding[1]),
        ("adjacent.s", input.adjacent[0]),
        ("adjacent.l", input.adjacent[1]),
    ];
    for (name, value) in named {
        check_finite(value, || name.to_owned())?;
    }
    if out.len() < set.dimension() {
        return Err(ZoneError::LengthMismatch {
            what: "feature output buffer",
            expected: set.dimension(),
            found: out.len(),
        });
    }
    if set == FeatureSet::TimeGap {
        let v = input.ego_speed;
        check_finite(v, || "ego_speed".to_owned())?;
        if v <= 0.0 {
            return Err(ZoneError::NonPositiveSpeed {
                field: "ego_speed".to_owned(),
                value: v,
            });
        }
    }
    write_checked_features(set, input, out);
    Ok(())
}

/// The arithmetic of [`features_into`], for an input it has accepted: the zone
/// projection checks a line's scene once and then varies only the finite `ego_l`.
#[inline]
pub(crate) fn write_checked_features(set: FeatureSet, input: &FeatureInput, out: &mut [f64]) {
    let ds_p = input.preceding[0] - input.ego_s;
    let dl_p = input.preceding[1] - input.ego_l;
    let ds_a = input.adjacent[0] - input.ego_s;
    let dl_a = input.adjacent[1] - input.ego_l;
    match set {
        FeatureSet::Paper => {
            out[..6].copy_from_slice(&[ds_p, dl_p, ds_p.hypot(dl_p), ds_a, dl_a, ds_a.hypot(dl_a)]);
        }
        FeatureSet::NoDistance => out[..4].copy_from_slice(&[ds_p, dl_p, ds_a, dl_a]),
        FeatureSet::TimeGap => {
            let v = input.ego_speed;
            out[..4].copy_from_slice(&[ds_p / v, dl_p, ds_a / v, dl_a]);
        }
    }
}

/// The features of `input` as a vector of length `set.dimension()` (Eq. 1 or a variant).
///
/// # Errors
/// As [`features_into`].
pub fn features(set: FeatureSet, input: &FeatureInput) -> Result<Vec<f64>, ZoneError> {
    let mut out = vec![0.0; set.dimension()];
    features_into(set, input, &mut out)?;
    Ok(out)
}
