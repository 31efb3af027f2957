//! Labelled samples (Eq. 2 semantics).

use serde::{Deserialize, Serialize};

use crate::error::ZoneError;

/// The class y of a position (Eq. 2).
///
/// The crate does not decide which positions are safe: the caller labels them.
/// In the paper, positions driven by the system before a takeover are `Safe`
/// and positions driven by the user after it are `Unsafe`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(try_from = "u8", into = "u8")]
pub enum Label {
    /// y = 0: taken over by the user (perceived unsafe).
    Unsafe,
    /// y = 1: not taken over (perceived safe).
    Safe,
}

impl Label {
    /// The paper's numeric class: 1 for safe, 0 for unsafe.
    pub const fn y(self) -> u8 {
        match self {
            Label::Unsafe => 0,
            Label::Safe => 1,
        }
    }

    /// The other class.
    pub const fn flipped(self) -> Label {
        match self {
            Label::Unsafe => Label::Safe,
            Label::Safe => Label::Unsafe,
        }
    }
}

impl TryFrom<u8> for Label {
    type Error = String;
    fn try_from(y: u8) -> Result<Self, Self::Error> {
        match y {
            0 => Ok(Label::Unsafe),
            1 => Ok(Label::Safe),
            other => Err(format!("label y = {other} must be 0 or 1")),
        }
    }
}

impl From<Label> for u8 {
    fn from(label: Label) -> u8 {
        label.y()
    }
}

/// One labelled position in feature space: `(x_i, y_i)` of Eqs. (5)-(8).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sample {
    /// The features, in the order of the model's [`crate::FeatureSet`].
    pub x: Vec<f64>,
    /// The class.
    pub y: Label,
}

impl Sample {
    /// A sample from its features and label.
    pub fn new(x: Vec<f64>, y: Label) -> Self {
        Sample { x, y }
    }
}

/// Checks that `x` has `dimension` finite entries; `what` names it in errors.
pub(crate) fn check_point(
    x: &[f64],
    dimension: usize,
    what: impl Fn() -> String,
) -> Result<(), ZoneError> {
    if x.len() != dimension {
        return Err(ZoneError::DimensionMismatch {
            what: what(),
            expected: dimension,
            found: x.len(),
        });
    }
    for (j, &value) in x.iter().enumerate() {
        if !value.is_finite() {
            return Err(ZoneError::NonFinite {
                field: format!("{} feature {j}", what()),
                value,
            });
        }
    }
    Ok(())
}
