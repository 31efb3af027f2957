//! The 10 x K weight matrix of Eq. (15), one stage's weights by name, and the feature
//! matrix of Eq. (34).

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

/// Number of features per stage (rows of `w` and `Φ`, Eq. 34).
pub const FEATURE_COUNT: usize = 10;

/// Row indices (0-based) of the ten features of Eq. (34); row `j` holds the
/// paper's `w_{j+1}` and `Φ_{j+1}`.
pub mod feature {
    /// `l²` (paper `w1`).
    pub const L_SQUARED: usize = 0;
    /// `l` (paper `w2`).
    pub const L: usize = 1;
    /// `φ²` (paper `w3`).
    pub const PHI_SQUARED: usize = 2;
    /// `φ` (paper `w4`).
    pub const PHI: usize = 3;
    /// `l δ` (paper `w5`).
    pub const L_DELTA: usize = 4;
    /// `φ δ` (paper `w6`).
    pub const PHI_DELTA: usize = 5;
    /// `s δ` (paper `w7`).
    pub const S_DELTA: usize = 6;
    /// `δ²` (paper `w8`).
    pub const DELTA_SQUARED: usize = 7;
    /// Squared distance to the preceding vehicle (paper `w9`).
    pub const DIST_PRECEDING: usize = 8;
    /// Squared distance to the adjacent vehicle (paper `w10`).
    pub const DIST_ADJACENT: usize = 9;
    /// Short names of the rows, for reports and error messages.
    pub const NAMES: [&str; super::FEATURE_COUNT] = [
        "l^2",
        "l",
        "phi^2",
        "phi",
        "l*delta",
        "phi*delta",
        "s*delta",
        "delta^2",
        "dist_p^2",
        "dist_a^2",
    ];
}

macro_rules! stage_matrix {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Debug, Clone, PartialEq)]
        #[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
        #[cfg_attr(feature = "serde", serde(transparent))]
        pub struct $name(Vec<[f64; FEATURE_COUNT]>);

        impl $name {
            /// Wraps `K` columns of ten entries; column `i - 1` belongs to stage `i`.
            pub fn from_columns(columns: Vec<[f64; FEATURE_COUNT]>) -> Self {
                Self(columns)
            }

            /// `K` copies of the same column.
            pub fn constant(horizon: usize, column: [f64; FEATURE_COUNT]) -> Self {
                Self(vec![column; horizon])
            }

            /// `K` columns of zeros.
            pub fn zeros(horizon: usize) -> Self {
                Self(vec![[0.0; FEATURE_COUNT]; horizon])
            }

            /// Number of stages `K` (columns).
            pub fn horizon(&self) -> usize {
                self.0.len()
            }

            /// All columns, stage 1 first.
            pub fn columns(&self) -> &[[f64; FEATURE_COUNT]] {
                &self.0
            }

            /// All columns, mutable.
            pub fn columns_mut(&mut self) -> &mut [[f64; FEATURE_COUNT]] {
                &mut self.0
            }

            /// Column `column` (0-based; it weighs stage `column + 1`).
            pub fn column(&self, column: usize) -> Option<&[f64; FEATURE_COUNT]> {
                self.0.get(column)
            }

            /// Entry in row `row` (feature, 0-based) and column `column` (0-based).
            pub fn get(&self, row: usize, column: usize) -> Option<f64> {
                self.0.get(column).and_then(|c| c.get(row)).copied()
            }

            /// Row `row` (one feature over all stages).
            pub fn row(&self, row: usize) -> impl Iterator<Item = f64> + '_ {
                self.0.iter().filter_map(move |c| c.get(row).copied())
            }

            /// Consumes the matrix and returns its columns.
            pub fn into_columns(self) -> Vec<[f64; FEATURE_COUNT]> {
                self.0
            }
        }
    };
}

stage_matrix!(
    /// The weight matrix `w ∈ R^{10 x K}` of Eq. (15), stored column by column.
    ///
    /// Serialized as a list of `K` arrays of ten numbers.
    Weights
);

stage_matrix!(
    /// The feature matrix `Φ(ψ) ∈ R^{10 x K}` of Eq. (34), stored column by column;
    /// column `i - 1` holds the features of `X_{i-1}, U_{i-1}`.
    Features
);

impl Weights {
    /// The Frobenius inner product `w · Φ` (the learned part of the cost, Eq. 15).
    ///
    /// Returns `None` when the horizons differ.
    pub fn dot(&self, features: &Features) -> Option<f64> {
        if self.horizon() != features.horizon() {
            return None;
        }
        Some(
            self.columns()
                .iter()
                .zip(features.columns())
                .map(|(w, f)| w.iter().zip(f).map(|(a, b)| a * b).sum::<f64>())
                .sum(),
        )
    }
}

/// The ten weights of one stage `i` (one column `w_{·,i}` of Eq. 15), by name.
///
/// Each field weighs the feature of the same name in Eq. (34), evaluated at `X_{i-1}`
/// and `U_{i-1}`; every weight is a cost weight (the planner minimizes `w · Φ`).
/// The stage's Hessian block must be positive semidefinite ([`check_convexity`]
/// states the rule): `l_squared`, `phi_squared`, `delta_squared` and the distance
/// weights `>= 0`, and the couplings `l_delta`, `phi_delta`, `s_delta` small enough.
///
/// ```
/// use palc_planner::{StageWeights, Weights, feature};
///
/// let stage = StageWeights { l_squared: 0.1, phi_squared: 1.0, delta_squared: 10.0, ..StageWeights::ZERO };
/// let weights = Weights::uniform(40, stage);
/// assert_eq!(weights.get(feature::DELTA_SQUARED, 39), Some(10.0));
/// assert_eq!(weights.stage(0), Some(stage));
/// ```
///
/// [`check_convexity`]: crate::check_convexity
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
#[cfg_attr(feature = "serde", serde(default, deny_unknown_fields))]
pub struct StageWeights {
    /// `w1`, weight of `l²`: keeps the car near `l = 0` (the original lane's centre).
    pub l_squared: f64,
    /// `w2`, weight of `l`: a constant lateral pull, to the left when negative.
    pub l: f64,
    /// `w3`, weight of `φ²`: penalizes heading away from the road.
    pub phi_squared: f64,
    /// `w4`, weight of `φ`: a constant pull on the heading.
    pub phi: f64,
    /// `w5`, weight of `l δ`: couples the lateral position and the steering angle.
    pub l_delta: f64,
    /// `w6`, weight of `φ δ`: couples the heading and the steering angle.
    pub phi_delta: f64,
    /// `w7`, weight of `s δ`: couples the longitudinal position and the steering angle,
    /// which is why `s` should be passed relative to the ego's start.
    pub s_delta: f64,
    /// `w8`, weight of `δ²`: smooth steering.
    pub delta_squared: f64,
    /// `w9`, weight of `dist^p`, the squared distance to the predicted preceding vehicle.
    pub dist_preceding: f64,
    /// `w10`, weight of `dist^a`, the squared distance to the predicted adjacent vehicle
    /// on the target lane.
    pub dist_adjacent: f64,
}

impl StageWeights {
    /// All ten weights zero.
    pub const ZERO: Self = Self {
        l_squared: 0.0,
        l: 0.0,
        phi_squared: 0.0,
        phi: 0.0,
        l_delta: 0.0,
        phi_delta: 0.0,
        s_delta: 0.0,
        delta_squared: 0.0,
        dist_preceding: 0.0,
        dist_adjacent: 0.0,
    };

    /// The weights as one column of the 10 x K matrix, row `j` holding `w_{j+1}`
    /// (the rows of [`feature`]).
    pub fn to_column(self) -> [f64; FEATURE_COUNT] {
        let mut c = [0.0; FEATURE_COUNT];
        c[feature::L_SQUARED] = self.l_squared;
        c[feature::L] = self.l;
        c[feature::PHI_SQUARED] = self.phi_squared;
        c[feature::PHI] = self.phi;
        c[feature::L_DELTA] = self.l_delta;
        c[feature::PHI_DELTA] = self.phi_delta;
        c[feature::S_DELTA] = self.s_delta;
        c[feature::DELTA_SQUARED] = self.delta_squared;
        c[feature::DIST_PRECEDING] = self.dist_preceding;
        c[feature::DIST_ADJACENT] = self.dist_adjacent;
        c
    }

    /// The weights of one column of the 10 x K matrix (the inverse of
    /// [`to_column`](Self::to_column)).
    pub fn from_column(c: [f64; FEATURE_COUNT]) -> Self {
        Self {
            l_squared: c[feature::L_SQUARED],
            l: c[feature::L],
            phi_squared: c[feature::PHI_SQUARED],
            phi: c[feature::PHI],
            l_delta: c[feature::L_DELTA],
            phi_delta: c[feature::PHI_DELTA],
            s_delta: c[feature::S_DELTA],
            delta_squared: c[feature::DELTA_SQUARED],
            dist_preceding: c[feature::DIST_PRECEDING],
            dist_adjacent: c[feature::DIST_ADJACENT],
        }
    }
}

impl From<[f64; FEATURE_COUNT]> for StageWeights {
    fn from(column: [f64; FEATURE_COUNT]) -> Self {
        Self::from_column(column)
    }
}

impl From<StageWeights> for [f64; FEATURE_COUNT] {
    fn from(stage: StageWeights) -> Self {
        stage.to_column()
    }
}

impl Weights {
    /// The same named weights at every one of the `horizon` stages.
    pub fn uniform(horizon: usize, stage: StageWeights) -> Self {
        Self::constant(horizon, stage.to_column())
    }

    /// One column per stage, stage 1 first.
    pub fn from_stages(stages: impl IntoIterator<Item = StageWeights>) -> Self {
        Self::from_columns(stages.into_iter().map(StageWeights::to_column).collect())
    }

    /// The named weights of column `column` (0-based; they weigh stage `column + 1`).
    pub fn stage(&self, column: usize) -> Option<StageWeights> {
        self.column(column).copied().map(StageWeights::from_column)
    }

    /// The named weights of every stage, stage 1 first.
    pub fn stages(&self) -> impl Iterator<Item = StageWeights> + '_ {
        self.columns()
            .iter()
            .copied()
            .map(StageWeights::from_column)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stage_weights_follow_the_rows_of_feature_names() {
        let column: [f64; FEATURE_COUNT] = std::array::from_fn(|j| j as f64 + 1.0);
        let stage = StageWeights::from_column(column);
        // Row j holds the paper's w_{j+1}, named in feature::NAMES.
        let named = [
            ("l^2", stage.l_squared),
            ("l", stage.l),
            ("phi^2", stage.phi_squared),
            ("phi", stage.phi),
            ("l*delta", stage.l_delta),
            ("phi*delta", stage.phi_delta),
            ("s*delta", stage.s_delta),
            ("delta^2", stage.delta_squared),
            ("dist_p^2", stage.dist_preceding),
            ("dist_a^2", stage.dist_adjacent),
        ];
        for (j, (name, w)) in named.into_iter().enumerate() {
            assert_eq!(feature::NAMES[j], name);
            assert_eq!(w, (j + 1) as f64, "w{} ({name})", j + 1);
        }
        assert_eq!(stage.to_column(), column);
    }

    #[test]
    fn weights_round_trip_through_stages() {
        let columns: Vec<[f64; FEATURE_COUNT]> = (0..5)
            .map(|i| std::array::from_fn(|j| (10 * i + j) as f64))
            .collect();
        let weights = Weights::from_columns(columns.clone());
        let stages: Vec<StageWeights> = weights.stages().collect();
        assert_eq!(stages.len(), 5);
        assert_eq!(Weights::from_stages(stages), weights);
        assert_eq!(weights.stage(5), None);
        assert_eq!(
            Weights::uniform(3, StageWeights::from_column(columns[2])),
            Weights::constant(3, columns[2])
        );
    }
}
