//! The named constants of the importer: how a lane change is told from a lane keep, where
//! it starts and ends, when the traffic's lane centre replaces the map's, and what counts
//! as a merge. Each constant says which failure it prevents.

/// Half-width of the centred least-squares window of the lateral speed (s): the speed at a
/// sample is the slope of the straight line fitted to the lateral positions within ±0.5 s
/// (±5 samples at 10 Hz, a first-order Savitzky–Golay derivative). A plain difference of
/// neighbours turns 3 cm of position noise into ±0.4 m/s and splits one lane change into
/// many; a wider window blurs the start and end by more than a sample.
pub const LATERAL_SPEED_HALF_WINDOW_S: f64 = 0.5;

/// Fewest samples in a (truncated) least-squares window: a line through fewer than three
/// points has no noise reduction and made the first and last samples of a track look like
/// lane changes in progress.
pub const LATERAL_SPEED_MIN_SAMPLES: usize = 3;

/// Lateral speed towards the target lane above which a vehicle is changing lanes (m/s).
/// The lane change is the maximal run of samples around the crossing where the speed
/// exceeds it. Below about 0.1 m/s the NGSIM tracks' drift within a lane (and 3 cm of noise
/// through the ±0.5 s window, about 0.03 m/s) joined lane keeping to the lane change;
/// above 0.2 m/s the start of a quintic lane change of 3.6 m in 5 s moves by more than
/// 0.6 s. At 0.15 m/s that start is 0.46 s after the quintic's.
pub const LATERAL_SPEED_THRESHOLD_MPS: f64 = 0.15;

/// Margin of lateral trace recorded before the start and after the end (s), as far as the
/// track reaches, with negative times before the start.
pub const TRACE_MARGIN_S: f64 = 1.0;

/// Difference between the map's lane centre and the traffic's (m) above which the
/// traffic's is used. Converted maps (NGSIM) draw some lanes off the cars' paths; a
/// trace relative to a centre that is off by more than this would start or end away
/// from zero or the lane width.
pub const CENTRE_TOLERANCE_M: f64 = 0.2;

/// Fewest lane-keeping samples within a lanelet for its traffic centre (3 s at 10 Hz): a
/// median of a few samples of one vehicle is that vehicle's habit, not the lane's centre.
pub const CENTRE_MIN_SAMPLES: usize = 30;

/// Samples this close in time to any lateral lanelet change of the same vehicle (s) are
/// not lane keeping and are left out of the traffic centre, so that the lane changes
/// themselves do not pull the centre towards the marking.
pub const CENTRE_EXCLUSION_S: f64 = 3.0;

/// How much farther the target lane must continue than the start lane (m) for the lane
/// change to be a merge (the start lane ends within the map). Lanes that all end at the
/// map's edge end within a few metres of each other; an on-ramp or auxiliary lane ends
/// tens of metres before its neighbour does.
pub const MERGE_MARGIN_M: f64 = 20.0;

/// Ego speed below which no time headway is given (m/s): a headway divides by the speed,
/// and a nearly stopped car's headway is meaningless rather than large.
pub const HEADWAY_MIN_SPEED_MPS: f64 = 0.5;

/// Consecutive centre points closer than this (m) are merged when lanelets are joined into
/// a corridor: a zero-length segment has no direction and no lateral offset.
pub const POINT_MERGE_M: f64 = 1e-3;

/// The largest coordinate (m) of a lanelet vertex or a vehicle position: far
/// beyond any map (the Earth's circumference is 4·10⁷ m), small enough that
/// the squares and differences of the import stay finite (a coordinate of 1e308
/// is finite, but the lateral offset computed from it is not).
pub(crate) const MAX_COORDINATE_M: f64 = 1e9;
