//! The checks every config and scene input goes through: each names the field it
//! checks, the value and the bound it breaks, as a [`ConfigError::OutOfRange`].

use crate::error::ConfigError;

/// Largest plausible road speed in a config (mph); bigger values are most likely km/h.
pub const MAX_SPEED_MPH: f64 = 100.0;

/// The error of `field` holding `value` outside `bound`.
pub(crate) fn out_of_range(field: &str, value: f64, bound: &str) -> ConfigError {
    ConfigError::OutOfRange {
        field: field.to_owned(),
        value,
        bound: bound.to_owned(),
    }
}

/// Finite and strictly positive.
pub(crate) fn positive(field: &str, value: f64) -> Result<f64, ConfigError> {
    in_range(
        field,
        value,
        f64::MIN_POSITIVE,
        f64::MAX,
        "finite and above 0",
    )
}

/// Finite and not negative.
pub(crate) fn non_negative(field: &str, value: f64) -> Result<f64, ConfigError> {
    in_range(field, value, 0.0, f64::MAX, "finite and at least 0")
}

/// Within `[min, max]` and not NaN; `bound` describes the range for the message.
pub(crate) fn in_range(
    field: &str,
    value: f64,
    min: f64,
    max: f64,
    bound: &str,
) -> Result<f64, ConfigError> {
    if value >= min && value <= max {
        Ok(value)
    } else {
        Err(out_of_range(field, value, bound))
    }
}

/// A speed in mph within `(0, MAX_SPEED_MPH]`, or within `[0, ..]` when `allow_zero`.
pub(crate) fn speed_mph(field: &str, value: f64, allow_zero: bool) -> Result<f64, ConfigError> {
    let ok = value <= MAX_SPEED_MPH
        && if allow_zero {
            value >= 0.0
        } else {
            value > 0.0
        };
    if ok {
        Ok(value)
    } else {
        let lower = if allow_zero { "[0" } else { "(0" };
        Err(out_of_range(
            field,
            value,
            &format!("in {lower}, {MAX_SPEED_MPH}] mph (a larger value may be in km/h)"),
        ))
    }
}
