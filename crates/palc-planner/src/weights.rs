//! The 10 x K weight matrix of Eq. (15) and the feature matrix of Eq. (34).

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
