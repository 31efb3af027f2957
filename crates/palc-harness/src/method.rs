//! The two methods palc runs side by side, composed from the crates' options.
//!
//! - `paper`: the printed method with only its equation errors corrected:
//!   system-driven samples labelled safe (y = 1) and user-driven samples unsafe
//!   (y = 0); shared-covariance GDA on the six features of Eq. (1); the projection
//!   of Eqs. (27)-(32); hard lateral bounds; the zone-centre expert (Eqs. 24-26);
//!   Abbeel & Ng's projection method on all ten weight rows (Eqs. 33-36).
//! - `palc`: the design palc defends by measurement
//!   (docs/experiments/0005-the-two-methods.md): the lesson expert (the executed
//!   trajectory re-planned through the QP), the target rule (iterative learning of
//!   each stage's lateral target) on the lateral rows w1 and w2 only, and no zone by
//!   default, because in measurement a zone on top made convergence worse.

use palc_aggregator::AggregatorOptions;
use serde::{Deserialize, Serialize};

/// A learning method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// The printed method with its equation errors corrected.
    Paper,
    /// palc's repaired method.
    #[default]
    Palc,
}

impl Method {
    /// Both methods, in report order.
    pub const ALL: [Method; 2] = [Method::Paper, Method::Palc];

    /// The method's name in configs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Method::Paper => "paper",
            Method::Palc => "palc",
        }
    }

    /// The method with this name.
    pub fn named(name: &str) -> Option<Method> {
        Method::ALL.into_iter().find(|m| m.name() == name)
    }

    /// The aggregator options this method runs with when a config gives none:
    /// [`AggregatorOptions::paper`] or `palc`'s defaults.
    pub fn aggregator_options(self) -> AggregatorOptions {
        match self {
            Method::Paper => AggregatorOptions::paper(),
            Method::Palc => AggregatorOptions::default(),
        }
    }
}

/// Who drove a sample, and so its label (Eq. 2: y = 1 is "perceived safe").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Driver {
    /// The system drove this position, before the takeover.
    System,
    /// The user drove this position, after the takeover.
    User,
    /// The system would have driven this position had the user not taken over.
    Rejected,
}

/// How a method labels a lesson's positions: `Some(true)` safe, `Some(false)` unsafe,
/// `None` not used.
pub fn label(method: Method, driver: Driver) -> Option<bool> {
    match (method, driver) {
        // The paper (Section II.C.1): system-driven y = 1, user-driven y = 0.
        (Method::Paper, Driver::System) => Some(true),
        (Method::Paper, Driver::User) => Some(false),
        (Method::Paper, Driver::Rejected) => None,
        // palc: what the user accepted or drove is safe; what the user rejected is not.
        (Method::Palc, Driver::System | Driver::User) => Some(true),
        (Method::Palc, Driver::Rejected) => Some(false),
    }
}
