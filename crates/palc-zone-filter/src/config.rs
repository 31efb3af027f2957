//! Model configuration.

use serde::{Deserialize, Serialize};

use crate::{error::ZoneError, features::FeatureSet};

/// Which covariance model separates the classes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Discriminant {
    /// The paper's GDA: one covariance shared by both classes (Eq. 8 as corrected),
    /// so the boundary is a hyperplane in feature space.
    #[default]
    Linear,
    /// One covariance per class: a quadratic boundary, which can describe a band
    /// around the user's path (NOTES.md, prototype finding 6).
    Quadratic,
}

/// How a zone model is built. Maps one to one onto a TOML table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ZoneConfig {
    /// Which features describe a position (default: the paper's six, Eq. 1).
    pub feature_set: FeatureSet,
    /// Shared (paper) or per-class covariance.
    pub discriminant: Discriminant,
    /// Ridge added to the covariance in standardized coordinates:
    /// `Sigma_reg = D (R + ridge I) D`, with `D` the per-feature scales and `R`
    /// the correlation-like matrix. Scale-free; finite and `>= 0`.
    ///
    /// Default 0: the maximum-likelihood model of Eqs. (5)-(8), with a
    /// pseudo-inverse for singular covariances (zero-variance features and
    /// directions get weight 0; see the `gaussian` module). A positive ridge is
    /// deliberate shrinkage: it damps every direction whose standardized
    /// variance is not large against it, also those that separate the classes
    /// (1e-6 changed posteriors by up to 0.39 on paper features), and gives a
    /// boundary even when the classes have no within-class spread.
    pub ridge: f64,
    /// Quadratic discriminant only: weight `alpha` in `[0, 1]` of the shared
    /// covariance in each class covariance, `(1 - alpha) Sigma_c + alpha Sigma`
    /// (Friedman's regularized discriminant analysis). 0 is plain QDA.
    pub quadratic_pooling: f64,
}

impl Default for ZoneConfig {
    fn default() -> Self {
        ZoneConfig {
            feature_set: FeatureSet::Paper,
            discriminant: Discriminant::Linear,
            ridge: 0.0,
            quadratic_pooling: 0.0,
        }
    }
}

impl ZoneConfig {
    /// Checks every field.
    ///
    /// # Errors
    /// [`ZoneError::InvalidConfig`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), ZoneError> {
        if !(self.ridge.is_finite() && self.ridge >= 0.0) {
            return Err(ZoneError::InvalidConfig {
                field: "ridge",
                value: self.ridge,
                bound: "finite and >= 0",
            });
        }
        if !(0.0..=1.0).contains(&self.quadratic_pooling) {
            return Err(ZoneError::InvalidConfig {
                field: "quadratic_pooling",
                value: self.quadratic_pooling,
                bound: "in [0, 1]",
            });
        }
        Ok(())
    }
}
