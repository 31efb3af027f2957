//! Unit conversions at the edge of the crate.
//!
//! Everything inside palc is SI; the paper states its speeds in miles per hour,
//! so configs may too, and they are converted exactly once, when a config is read.

/// Metres per second in one mile per hour (exact: 1609.344 m / 3600 s).
pub const MPS_PER_MPH: f64 = 0.447_04;

/// Converts a speed from miles per hour to metres per second.
pub fn mph_to_mps(mph: f64) -> f64 {
    mph * MPS_PER_MPH
}

/// Converts a speed from metres per second to miles per hour.
pub fn mps_to_mph(mps: f64) -> f64 {
    mps / MPS_PER_MPH
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forty_five_mph_is_twenty_point_one_mps() {
        assert!((mph_to_mps(45.0) - 20.1168).abs() < 1e-12);
        assert!((mps_to_mph(mph_to_mps(65.0)) - 65.0).abs() < 1e-12);
    }
}
