//! Which rows of the weight matrix a correction rule may change.

use std::fmt;

use palc_planner::FEATURE_COUNT;
use serde::{Deserialize, Serialize};

/// A set of weight rows, named as in the paper (`"w1"` .. `"w10"`).
///
/// The correction rules change only these rows; the others keep their prior values
/// (up to the convex projection, which may still shrink a fixed coupling row when a
/// learned diagonal makes a stage block indefinite, see [`crate::project_convex`]).
///
/// The default is `["w1", "w2"]`: per step, `-w2 / (2 w1)` is a lateral target with
/// stiffness `w1`, which is exactly what the start of a lane change needs. An
/// independent prototype personalized 60 / 60 grid cases with these two rows and
/// counter-steered in 7 / 60 when the heading and cross terms were learned too
/// (docs/experiments/0010-learnable-rows-and-feature-scale.md).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "Vec<String>", into = "Vec<String>")]
pub struct LearnableRows([bool; FEATURE_COUNT]);

impl LearnableRows {
    /// All ten rows (the paper's setting).
    pub const ALL: LearnableRows = LearnableRows([true; FEATURE_COUNT]);

    /// No row: the correction returns the prior weights (projected).
    pub const NONE: LearnableRows = LearnableRows([false; FEATURE_COUNT]);

    /// The rows with the given 0-based indices (row `j` holds the paper's `w_{j+1}`);
    /// indices `>= 10` are ignored.
    pub fn from_indices(indices: impl IntoIterator<Item = usize>) -> Self {
        let mut mask = [false; FEATURE_COUNT];
        for j in indices {
            if let Some(m) = mask.get_mut(j) {
                *m = true;
            }
        }
        LearnableRows(mask)
    }

    /// `true` when 0-based row `row` may change.
    pub fn contains(&self, row: usize) -> bool {
        self.0.get(row).copied().unwrap_or(false)
    }

    /// The 0-based indices of the learnable rows, in order.
    pub fn indices(&self) -> impl Iterator<Item = usize> + '_ {
        (0..FEATURE_COUNT).filter(|&j| self.0[j])
    }

    /// `true` when no row may change.
    pub fn is_empty(&self) -> bool {
        !self.0.iter().any(|&m| m)
    }
}

impl Default for LearnableRows {
    fn default() -> Self {
        LearnableRows::from_indices([0, 1])
    }
}

impl fmt::Display for LearnableRows {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<String> = self.indices().map(|j| format!("w{}", j + 1)).collect();
        write!(f, "[{}]", names.join(", "))
    }
}

impl TryFrom<Vec<String>> for LearnableRows {
    type Error = String;

    fn try_from(names: Vec<String>) -> Result<Self, Self::Error> {
        let mut mask = [false; FEATURE_COUNT];
        for name in &names {
            let index = name
                .strip_prefix('w')
                .and_then(|n| n.parse::<usize>().ok())
                .filter(|n| (1..=FEATURE_COUNT).contains(n))
                .ok_or_else(|| format!("learnable row `{name}` must be one of w1 .. w10"))?;
            mask[index - 1] = true;
        }
        Ok(LearnableRows(mask))
    }
}

impl From<LearnableRows> for Vec<String> {
    fn from(rows: LearnableRows) -> Self {
        rows.indices().map(|j| format!("w{}", j + 1)).collect()
    }
}
