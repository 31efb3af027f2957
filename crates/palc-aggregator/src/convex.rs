//! The convex set the weights are kept in, and the projection onto it.

use palc_planner::{FEATURE_COUNT, Weights, feature};
use serde::{Deserialize, Serialize};

use crate::{AggregatorError, LearnableRows};

/// Relative margin kept in the Schur complement: a column with
/// `Σ c_j² / d_j > (1 - SCHUR_MARGIN / 2) w8` has its couplings shrunk until
/// `Σ c_j² / d_j <= (1 - SCHUR_MARGIN) w8`, so that rounding in any later check of the
/// same block cannot turn it indefinite, and projecting twice changes nothing.
pub const SCHUR_MARGIN: f64 = 1e-9;

/// A state diagonal at or below this fraction of the block's largest entry counts
/// as zero, and its coupling is set to zero. It is ten times the relative tolerance of
/// `palc_planner::check_convexity`, so a block this module accepts is accepted there.
pub const DIAGONAL_ZERO_RATIO: f64 = 1e-9;

/// The convex set of weights for which the planner's QP is convex (NOTES.md,
/// "Convexity"):
///
/// - `w1, w3, w8 >= min_curvature` (lateral stiffness, heading and steering
///   curvature strictly positive, so that the plan is unique and smooth);
/// - `w9, w10 >= 0` (the squared distances add curvature `w9 + w10` to `s` and `l`);
/// - each stage block `[[Q_i, F_i/2], [F_iᵀ/2, R_i]]` of Eqs. (16)-(19) positive
///   semidefinite. Over `(s, l, φ, δ)` it is an arrow matrix with diagonal
///   `(w9 + w10, w1 + w9 + w10, w3, w8)` and couplings `c = (w7, w5, w6) / 2` to `δ`,
///   PSD iff `Σ c_j² / d_j <= w8` with `c_j = 0` wherever `d_j = 0` (so `w7 = 0` when
///   `w9 = w10 = 0`).
///
/// The set is an intersection of half-spaces and a PSD cone (affine in `w`), hence
/// convex; a convex combination of two members is a member, which is why
/// [`crate::resample_weights`] keeps weights convex.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ConvexSet {
    /// Lower bound `ε` on `w1`, `w3` and `w8`; must be finite and `> 0`. Default `1e-6`.
    pub min_curvature: f64,
}

impl Default for ConvexSet {
    fn default() -> Self {
        ConvexSet {
            min_curvature: 1e-6,
        }
    }
}

impl ConvexSet {
    /// Checks the field.
    pub fn validate(&self) -> Result<(), AggregatorError> {
        if self.min_curvature.is_finite() && self.min_curvature > 0.0 {
            Ok(())
        } else {
            Err(AggregatorError::InvalidOption {
                field: "convex_set.min_curvature",
                value: self.min_curvature,
                bound: "finite and > 0",
            })
        }
    }
}

/// Projects `weights` onto the [`ConvexSet`], column by column.
///
/// Per column: first the bounds (`w1, w3, w8` raised to `ε`, `w9, w10` to 0);
/// then, with the diagonals fixed, the couplings are moved to the nearest point (in
/// Euclidean distance) of the ellipsoid `Σ c_j² / d_j <= (1 - SCHUR_MARGIN) w8`, i.e.
/// `c_j ← c_j d_j / (d_j + λ)` with the multiplier `λ >= 0` found by bisection.
/// Couplings in `learnable` rows are moved first, with the fixed ones kept; only if
/// the fixed couplings alone break the block are they shrunk as well (convexity wins
/// over "other rows keep their prior values"). A column already in the set is
/// returned unchanged. This is not the exact Euclidean projection onto the set (that
/// is a small semidefinite program per column) but it is idempotent, keeps the signs
/// of every coupling, and never changes a diagonal more than the bounds require.
///
/// # Errors
/// [`AggregatorError::NonFinite`] for a NaN or infinite weight, and
/// [`AggregatorError::InvalidOption`] for an invalid `set`.
pub fn project_convex(
    weights: &Weights,
    set: &ConvexSet,
    learnable: &LearnableRows,
) -> Result<Weights, AggregatorError> {
    set.validate()?;
    let mut columns = weights.columns().to_vec();
    for (k, column) in columns.iter_mut().enumerate() {
        for (j, &x) in column.iter().enumerate() {
            if !x.is_finite() {
                return Err(AggregatorError::NonFinite {
                    field: format!("weights[{k}][{j}]"),
                    value: x,
                });
            }
        }
        project_column(column, set.min_curvature, learnable);
    }
    Ok(Weights::from_columns(columns))
}

/// Projects one column in place (see [`project_convex`]).
fn project_column(w: &mut [f64; FEATURE_COUNT], epsilon: f64, learnable: &LearnableRows) {
    for row in [
        feature::L_SQUARED,
        feature::PHI_SQUARED,
        feature::DELTA_SQUARED,
    ] {
        w[row] = w[row].max(epsilon);
    }
    for row in [feature::DIST_PRECEDING, feature::DIST_ADJACENT] {
        w[row] = w[row].max(0.0);
    }
    let dist = w[feature::DIST_PRECEDING] + w[feature::DIST_ADJACENT];
    let rows = [feature::S_DELTA, feature::L_DELTA, feature::PHI_DELTA];
    let diagonals = [dist, w[feature::L_SQUARED] + dist, w[feature::PHI_SQUARED]];
    let mut couplings = rows.map(|row| w[row] / 2.0);
    let r = w[feature::DELTA_SQUARED];
    let scale = diagonals
        .iter()
        .chain(&couplings)
        .fold(r.abs(), |m, x| m.max(x.abs()));
    for (c, &d) in couplings.iter_mut().zip(&diagonals) {
        if d <= DIAGONAL_ZERO_RATIO * scale {
            *c = 0.0;
        }
    }
    let budget = (1.0 - SCHUR_MARGIN) * r;
    // A column already shrunk to the budget must stay as it is (idempotence), so
    // only a column beyond half the margin is moved.
    let allowed = (1.0 - 0.5 * SCHUR_MARGIN) * r;
    let free = rows.map(|row| learnable.contains(row));
    let used_by = |couplings: &[f64; 3], pick: bool| -> f64 {
        (0..3)
            .filter(|&j| free[j] == pick && couplings[j] != 0.0)
            .map(|j| couplings[j] * couplings[j] / diagonals[j])
            .sum()
    };
    if used_by(&couplings, true) + used_by(&couplings, false) > allowed {
        let fixed = used_by(&couplings, false);
        if fixed < budget {
            shrink_onto_ellipsoid(&mut couplings, &diagonals, &free, budget - fixed);
        } else {
            for j in 0..3 {
                if free[j] {
                    couplings[j] = 0.0;
                }
            }
            shrink_onto_ellipsoid(&mut couplings, &diagonals, &free.map(|f| !f), budget);
        }
    }
    for (row, c) in rows.into_iter().zip(couplings) {
        w[row] = 2.0 * c;
    }
}

/// Moves the selected couplings to the nearest point of `Σ c_j² / d_j <= radius`
/// (the unselected ones do not count): `c_j ← c_j d_j / (d_j + λ)`, with `λ` the
/// smallest multiplier found by bisection for which the constraint holds.
fn shrink_onto_ellipsoid(
    couplings: &mut [f64; 3],
    diagonals: &[f64; 3],
    selected: &[bool; 3],
    radius: f64,
) {
    let active: Vec<usize> = (0..3)
        .filter(|&j| selected[j] && couplings[j] != 0.0)
        .collect();
    let used = |lambda: f64| -> f64 {
        active
            .iter()
            .map(|&j| {
                let c = couplings[j] * diagonals[j] / (diagonals[j] + lambda);
                c * c / diagonals[j]
            })
            .sum()
    };
    if used(0.0) <= radius {
        return;
    }
    if radius <= 0.0 {
        for &j in &active {
            couplings[j] = 0.0;
        }
        return;
    }
    // used(λ) <= Σ c_j² d_j / λ², so this λ is feasible.
    let total: f64 = active
        .iter()
        .map(|&j| couplings[j] * couplings[j] * diagonals[j])
        .sum();
    let mut high = (total / radius).sqrt();
    while used(high) > radius {
        high *= 2.0;
    }
    let mut low = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (low + high);
        if mid <= low || mid >= high {
            break;
        }
        if used(mid) > radius {
            low = mid;
        } else {
            high = mid;
        }
    }
    for &j in &active {
        couplings[j] *= diagonals[j] / (diagonals[j] + high);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn column(values: [f64; FEATURE_COUNT]) -> Weights {
        Weights::from_columns(vec![values])
    }

    #[test]
    fn a_convex_column_is_unchanged() {
        let w = column([1.0, -2.0, 5.0, 0.3, 0.1, 0.2, 0.0, 1.0, 0.0, 0.0]);
        let p = project_convex(&w, &ConvexSet::default(), &LearnableRows::ALL).unwrap();
        assert_eq!(p, w);
    }

    #[test]
    fn s_delta_coupling_is_zero_without_distance_weights() {
        let w = column([1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 3.0, 1.0, -1.0, 0.0]);
        let p = project_convex(&w, &ConvexSet::default(), &LearnableRows::ALL).unwrap();
        assert_eq!(p.get(feature::S_DELTA, 0), Some(0.0));
        assert_eq!(p.get(feature::DIST_PRECEDING, 0), Some(0.0));
    }

    #[test]
    fn negative_curvatures_are_raised_to_epsilon() {
        let w = column([-1.0, 0.0, -2.0, 0.0, 0.0, 0.0, 0.0, -3.0, 0.0, 0.0]);
        let set = ConvexSet {
            min_curvature: 0.01,
        };
        let p = project_convex(&w, &set, &LearnableRows::ALL).unwrap();
        for row in [0, 2, 7] {
            assert_eq!(p.get(row, 0), Some(0.01));
        }
    }

    #[test]
    fn learnable_couplings_shrink_before_fixed_ones() {
        // w5 fixed at 1.6, w6 learnable at 1.6 (couplings 0.8); budget w8 = 1 with
        // d_l = d_phi = 1: the fixed one uses 0.64, so w6 shrinks to fit 0.36 and w5 stays.
        let w = column([1.0, 0.0, 1.0, 0.0, 1.6, 1.6, 0.0, 1.0, 0.0, 0.0]);
        let learnable = LearnableRows::from_indices([feature::PHI_DELTA]);
        let p = project_convex(&w, &ConvexSet::default(), &learnable).unwrap();
        assert_eq!(p.get(feature::L_DELTA, 0), Some(1.6));
        let c6 = p.get(feature::PHI_DELTA, 0).unwrap() / 2.0;
        assert!((c6 - 0.6).abs() < 1e-6, "c6 = {c6}");
    }

    #[test]
    fn non_finite_weight_is_refused() {
        let w = column([1.0, f64::NAN, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
        let err = project_convex(&w, &ConvexSet::default(), &LearnableRows::ALL).unwrap_err();
        assert!(err.to_string().contains("weights[0][1]"), "{err}");
    }
}
