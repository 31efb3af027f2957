//! Per-row feature scales and the feature error the correction rules minimize.

use palc_planner::{FEATURE_COUNT, Features};
use serde::{Deserialize, Serialize};

use crate::{AggregatorError, LearnableRows};

/// The typical magnitude `σ_j` of each feature row of Eq. (34), per stage.
///
/// Raw features span eight orders of magnitude (squared distances ~10³ m², `δ²`
/// ~10⁻⁴), so unscaled feature differences are dominated by the distance rows
/// (NOTES.md, prototype finding 2). The correction rules work in scaled coordinates
/// `Φ̃_j = Φ_j / σ_j`, `ω_j = w_j σ_j` (so `w · Φ = ω · Φ̃`).
///
/// Default: the magnitudes of a 3.5 m lane change at about 20 m/s over about 4 s,
/// with `s` measured from the start of the plan: `|l| ≈ 3.5 m`, `|φ| ≈ 0.05 rad`,
/// `|δ| ≈ 0.01 rad`, `s ≈ 100 m`, distances to the other vehicles ≈ 50 m:
/// `[l² 12.25, l 3.5, φ² 2.5e-3, φ 0.05, lδ 0.035, φδ 5e-4, sδ 1, δ² 1e-4,
/// dist_p² 2500, dist_a² 2500]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct FeatureScale(pub [f64; FEATURE_COUNT]);

impl Default for FeatureScale {
    fn default() -> Self {
        FeatureScale([
            12.25, 3.5, 2.5e-3, 0.05, 0.035, 5e-4, 1.0, 1e-4, 2500.0, 2500.0,
        ])
    }
}

impl FeatureScale {
    /// Checks that every scale is finite and positive.
    pub fn validate(&self) -> Result<(), AggregatorError> {
        const FIELDS: [&str; FEATURE_COUNT] = [
            "feature_scale[0] (w1)",
            "feature_scale[1] (w2)",
            "feature_scale[2] (w3)",
            "feature_scale[3] (w4)",
            "feature_scale[4] (w5)",
            "feature_scale[5] (w6)",
            "feature_scale[6] (w7)",
            "feature_scale[7] (w8)",
            "feature_scale[8] (w9)",
            "feature_scale[9] (w10)",
        ];
        for (field, &value) in FIELDS.iter().zip(&self.0) {
            if !(value.is_finite() && value > 0.0) {
                return Err(AggregatorError::InvalidOption {
                    field,
                    value,
                    bound: "finite and > 0",
                });
            }
        }
        Ok(())
    }
}

/// The scaled feature error `‖(Φ_a - Φ_b) / σ‖` (Frobenius norm over the
/// `rows` and every stage), the quantity the incremental rule never lets grow.
///
/// Returns `None` when the horizons differ.
pub fn feature_error(
    a: &Features,
    b: &Features,
    scale: &FeatureScale,
    rows: &LearnableRows,
) -> Option<f64> {
    if a.horizon() != b.horizon() {
        return None;
    }
    let mut sum = 0.0;
    for (ca, cb) in a.columns().iter().zip(b.columns()) {
        for j in rows.indices() {
            let d = (ca[j] - cb[j]) / scale.0[j];
            sum += d * d;
        }
    }
    Some(sum.sqrt())
}
