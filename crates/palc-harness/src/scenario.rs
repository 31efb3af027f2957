//! Preparing a scenario from a config: the traffic scene of its cell, the
//! planning set-up at the trigger with the paper's premise checked in it
//! ([`prepare`]), and a user's nominal lane change with the horizon extended to
//! cover it.

use palc_aggregator::AggregatorOptions;
use palc_traffic::Scene;
use palc_user::{Expectation, StylePreset, User};

use crate::HarnessError;
use crate::config::LearnConfig;
use crate::refusal::Refusal;
use crate::setup::Setup;

/// The aggregator options of a config: its own table if given, else the method's.
pub fn aggregator_options(config: &LearnConfig) -> AggregatorOptions {
    config
        .aggregator
        .clone()
        .unwrap_or_else(|| config.method.aggregator_options())
}

/// Builds the scenario of a config and checks the paper's premise in it: the
/// standard ALC is later and slower than each of the paper's styles. The error
/// names the scenario and what does not hold.
pub fn prepare(config: &LearnConfig) -> Result<Setup, HarnessError> {
    config.validate()?;
    let label = config.label();
    let scene = Scene::for_cell(&config.traffic, &config.cell()?)?;
    let setup = Setup::new(&scene, &config.planning, &label)?;
    setup
        .check_conservative(&config.planning.standard_alc, &StylePreset::ALL)
        .map_err(|refusal: Refusal| HarnessError::Refused {
            scenario: label,
            refusal: Box::new(refusal),
        })?;
    Ok(setup)
}

/// The scenario of `config` with its user's nominal expected lane change: what a
/// user wants before learning starts (`palc user expect`). The horizon covers the
/// lane change, as in [`crate::LearningLoop::new`].
///
/// # Errors
/// As [`prepare`], or a user without a sane lane change in the scenario.
pub fn expectation(config: &LearnConfig) -> Result<(Setup, Expectation), HarnessError> {
    let user = config
        .user
        .simulated(config.planning.takeover_threshold_m)?;
    prepare_for(config, &user)
}

/// [`prepare`], then the user's nominal lane change, with the horizon extended to
/// cover it (a user who ends after the standard ALC).
pub(crate) fn prepare_for(
    config: &LearnConfig,
    user: &dyn User,
) -> Result<(Setup, Expectation), HarnessError> {
    let mut setup = prepare(config)?;
    let nominal = (user.nominal(&setup.user_scene()))
        .map_err(|error| HarnessError::from_user(&setup.label, error))?;
    setup.cover(
        nominal.lane_change.end_s(),
        config.planning.horizon_margin_s,
    )?;
    Ok((setup, nominal))
}
