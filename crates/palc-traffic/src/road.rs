//! Road geometry in Frenet coordinates.
//!
//! `s` runs along the road (m); `l` is lateral, positive to the left (m). Lane 0 is the
//! ego's initial lane with its centre at `l = 0`; lane `j` has its centre at `l = j w`
//! for lane width `w`, so with two 3.5 m lanes the road edges are at `l = -1.75` and
//! `l = 5.25` (docs/ARCHITECTURE.md, conventions).

use serde::{Deserialize, Serialize};

/// Most lanes a road may have (`road.lanes`): far more than any road, and few enough
/// that the per-lane work of a scene stays small.
pub const MAX_LANES: u32 = 64;

/// Index of a lane, counted from the ego's initial lane (0) to the left.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct Lane(pub u32);

/// A straight multi-lane road section.
///
/// `s` is unbounded: vehicles keep driving past `length`, which only bounds where a
/// scenario may place vehicles at its start (see
/// docs/experiments/0015-test-bed-geometry-and-platoon.md).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Road {
    /// Length of the section in which vehicles are placed at the start (m).
    pub length: f64,
    /// Width of every lane (m).
    pub lane_width: f64,
    /// Number of lanes.
    pub lanes: u32,
}

impl Road {
    /// The paper's test bed (Section III.A): two lanes, 3.5 m wide, 200 m long.
    pub fn paper() -> Road {
        Road {
            length: 200.0,
            lane_width: 3.5,
            lanes: 2,
        }
    }

    /// Lateral position of the centre of `lane` (m).
    pub fn lane_centre(&self, lane: Lane) -> f64 {
        f64::from(lane.0) * self.lane_width
    }

    /// Right road edge (m), half a lane to the right of lane 0's centre.
    pub fn right_edge(&self) -> f64 {
        -0.5 * self.lane_width
    }

    /// Left road edge (m).
    pub fn left_edge(&self) -> f64 {
        (f64::from(self.lanes) - 0.5) * self.lane_width
    }

    /// The lane whose centre is nearest to `l`, clamped to the road's lanes.
    pub fn nearest_lane(&self, l: f64) -> Lane {
        let index = (l / self.lane_width).round();
        let max = f64::from(self.lanes.saturating_sub(1));
        // Clamped to [0, lanes - 1] first, so the cast cannot truncate; NaN maps to lane 0.
        Lane(index.clamp(0.0, max) as u32)
    }

    /// Whether a body of width `width` centred at `l` overlaps `lane` laterally.
    ///
    /// This is the occupancy rule for vehicles that change lanes (the ego): a vehicle
    /// occupies every lane its body touches, so `|l - centre| < (lane_width + width) / 2`.
    pub fn occupies(&self, l: f64, width: f64, lane: Lane) -> bool {
        (l - self.lane_centre(lane)).abs() < 0.5 * (self.lane_width + width)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_road_matches_the_conventions() {
        let road = Road::paper();
        assert_eq!(road.lane_centre(Lane(1)), 3.5);
        assert_eq!(road.right_edge(), -1.75);
        assert_eq!(road.left_edge(), 5.25);
        assert_eq!(road.nearest_lane(1.6), Lane(0));
        assert_eq!(road.nearest_lane(1.9), Lane(1));
        assert_eq!(road.nearest_lane(9.0), Lane(1));
        assert_eq!(road.nearest_lane(f64::NAN), Lane(0));
    }

    #[test]
    fn a_vehicle_on_the_marking_occupies_both_lanes() {
        let road = Road::paper();
        assert!(road.occupies(1.75, 1.8, Lane(0)));
        assert!(road.occupies(1.75, 1.8, Lane(1)));
        assert!(!road.occupies(0.0, 1.8, Lane(1)));
        assert!(road.occupies(0.9, 1.8, Lane(1)));
    }
}
