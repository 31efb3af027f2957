//! A drive of varied scenes (`[drive]`): each user drives a sequence of lane
//! changes, each in a scene it has not met before, learning throughout.
//!
//! The paper repeats one scene until the user stops taking over; a driver never
//! meets the same traffic twice. In a drive every lane change is driven once, in
//! its own scene, from the experience of every lane change before it: the
//! takeover rate over the drive is the number a driver would feel.
//!
//! The scenes are drawn once per drive config ([`DriveConfig::scenes`]), so every
//! user, style and method meets the same sequence, and no scene comes twice: a
//! share `grid_share` are cells of the evaluation's grid (speed case, headway,
//! seed), each at most once, in a random order; the rest, and every scene once
//! the cells are used up, are drawn uniformly from ranges around the grid (the
//! ego's speed, the other vehicles' speed below it, the target lane's headway)
//! with a new scene seed, scenes no other experiment uses. A scene in which a user's run is refused (its standard ALC
//! never starts, its start rule is met before the plan) is skipped for that user:
//! the experience passes through it unchanged (the runner's
//! [`crate::runner::execute`]) and the lane change is not counted.

use palc_traffic::SpeedCaseConfig;
use rand::seq::SliceRandom;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use palc_harness::Method;

use crate::EvalError;

/// The lane changes of a drive when the config leaves them out.
pub const DEFAULT_LANE_CHANGES: usize = 100;

/// The most lane changes a drive may have: a drive is a chain the runner executes
/// one lane change after another, so its length is its wall time.
pub const MAX_LANE_CHANGES: usize = 10_000;

/// How far the drawn scenes reach past the grid, on every range: the ego's speed
/// and the speed difference (mph) and the headway (m). Five of each is the
/// grid's own step between neighbouring headways (5 m) and the difference between
/// its two speed differences (5 mph): one grid step beyond the grid on each side.
const REACH_MPH: f64 = 5.0;
const REACH_M: f64 = 5.0;

/// The smallest speed difference a drawn scene has (mph): the ego must be faster
/// than the traffic it leaves, or the lane change has no reason.
const MIN_DIFFERENCE_MPH: f64 = 1.0;

/// The smallest drawn headway (m): below it the target lane's vehicles overlap.
const MIN_HEADWAY_M: f64 = 15.0;

/// The seeds of drawn scenes: above every seed the test bed's grids use (1-4),
/// so a drawn scene's traffic is never a grid cell's.
const DRAWN_SEEDS: std::ops::RangeInclusive<u64> = 1_000..=1_000_000;

/// `[drive]`: who drives, how many lane changes, and the scenes' ranges.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveConfig {
    /// Names of the user kinds that drive (every style of the grid); none: no drive.
    pub users: Vec<String>,
    /// The methods that drive; the grid's when left out.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub methods: Option<Vec<Method>>,
    /// Lane changes (scenes) per drive; [`DEFAULT_LANE_CHANGES`] when left out.
    #[serde(default)]
    pub lane_changes: Option<usize>,
    /// Seed of the scene draws.
    #[serde(default)]
    pub seed: u64,
    /// Share of the scenes that are grid cells, in [0, 1]; 0.5 when left out.
    #[serde(default)]
    pub grid_share: Option<f64>,
    /// The ego's speed of a drawn scene (mph); the grid's range widened by 5 mph when left out.
    #[serde(default)]
    pub ego_mph: Option<[f64; 2]>,
    /// How much slower than the ego the other vehicles drive (mph); the grid's
    /// range widened by 5 mph (and at least 1) when left out.
    #[serde(default)]
    pub difference_mph: Option<[f64; 2]>,
    /// The target lane's headway of a drawn scene (m); the grid's widened by 5 m
    /// (and at least 15) when left out.
    #[serde(default)]
    pub headway_m: Option<[f64; 2]>,
}

/// The cells of the grid a drive is drawn around: its speed cases, headways and seeds.
#[derive(Debug, Clone, Copy)]
pub struct GridCells<'a> {
    /// The grid's speed cases.
    pub speed_cases: &'a [SpeedCaseConfig],
    /// The grid's headways (m).
    pub headways_m: &'a [f64],
    /// The grid's scene seeds.
    pub seeds: &'a [u64],
}

/// One scene of a drive.
#[derive(Debug, Clone, PartialEq)]
pub struct DriveScene {
    /// The speed case: a grid case, or a drawn one named by its speeds.
    pub speed_case: SpeedCaseConfig,
    /// The target lane's headway (m).
    pub headway_m: f64,
    /// The scene seed.
    pub seed: u64,
}

impl DriveConfig {
    /// Whether any user drives.
    pub fn is_empty(&self) -> bool {
        self.users.is_empty()
    }

    /// The lane changes of each drive.
    pub fn lane_changes(&self) -> usize {
        self.lane_changes.unwrap_or(DEFAULT_LANE_CHANGES)
    }

    /// Checks the numbers of `[table]` (`drive` or `quick.drive`); names are
    /// checked by the evaluation config.
    pub fn validate(&self, table: &str) -> Result<(), EvalError> {
        if self.methods.as_ref().is_some_and(Vec::is_empty) {
            return Err(EvalError::invalid(
                format!("{table}.methods"),
                "empty",
                "at least one method (leave it out for the grid's)",
            ));
        }
        if let Some(n) = self.lane_changes {
            if !(1..=MAX_LANE_CHANGES).contains(&n) {
                return Err(EvalError::invalid(
                    format!("{table}.lane_changes"),
                    n,
                    format!("1 to {MAX_LANE_CHANGES}"),
                ));
            }
        }
        if let Some(share) = self.grid_share {
            if !(share.is_finite() && (0.0..=1.0).contains(&share)) {
                return Err(EvalError::invalid(
                    format!("{table}.grid_share"),
                    format_args!("{share:?}"),
                    "a share in [0, 1]",
                ));
            }
        }
        for (field, range, least) in [
            ("ego_mph", self.ego_mph, MIN_DIFFERENCE_MPH),
            ("difference_mph", self.difference_mph, MIN_DIFFERENCE_MPH),
            ("headway_m", self.headway_m, MIN_HEADWAY_M),
        ] {
            let Some([low, high]) = range else { continue };
            let finite = low.is_finite() && high.is_finite();
            if !(finite && least <= low && low <= high && high <= 1_000.0) {
                return Err(EvalError::invalid(
                    format!("{table}.{field}"),
                    format_args!("[{low:?}, {high:?}]"),
                    format!("[low, high] with {least} <= low <= high <= 1000"),
                ));
            }
        }
        Ok(())
    }

    /// The scenes of every drive of this config (`[table]`) around `grid`, in driving order.
    ///
    /// # Errors
    /// [`EvalError::InvalidConfig`] when a drawn scene's other vehicles would not
    /// move (the ego's speed at most the speed difference).
    pub fn scenes(&self, table: &str, grid: GridCells<'_>) -> Result<Vec<DriveScene>, EvalError> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        let (ego, difference, headway) = self.ranges(grid);
        if ego[0] <= difference[1] {
            return Err(EvalError::invalid(
                format!("{table}.ego_mph"),
                format_args!("[{:?}, {:?}]", ego[0], ego[1]),
                format!(
                    "a lowest speed above the largest difference, {:?} mph, so the other vehicles move",
                    difference[1]
                ),
            ));
        }
        let share = self.grid_share.unwrap_or(0.5);
        let mut cells: Vec<DriveScene> = (grid.speed_cases.iter())
            .flat_map(|case| {
                (grid.headways_m.iter()).flat_map(move |&headway_m| {
                    (grid.seeds.iter()).map(move |&seed| DriveScene {
                        speed_case: case.clone(),
                        headway_m,
                        seed,
                    })
                })
            })
            .collect();
        cells.shuffle(&mut rng);
        let mut cells = cells.into_iter();
        let draw = |rng: &mut ChaCha8Rng, [low, high]: [f64; 2]| {
            if low < high {
                rng.random_range(low..=high)
            } else {
                low
            }
        };
        let mut scenes = Vec::with_capacity(self.lane_changes());
        for _ in 0..self.lane_changes() {
            // Every draw is taken whichever the scene, so the sequence of drawn
            // scenes does not depend on which scenes are grid cells.
            let on_grid = rng.random_range(0.0..1.0) < share;
            let ego_mph = round(draw(&mut rng, ego));
            let others_mph = round(ego_mph - draw(&mut rng, difference));
            let headway_m = round(draw(&mut rng, headway));
            let seed = rng.random_range(DRAWN_SEEDS);
            let cell = if on_grid { cells.next() } else { None };
            scenes.push(match cell {
                Some(cell) => cell,
                None => DriveScene {
                    speed_case: SpeedCaseConfig {
                        name: format!("drawn-{ego_mph}-{others_mph}"),
                        ego_mph,
                        others_mph,
                    },
                    headway_m,
                    seed,
                },
            });
        }
        Ok(scenes)
    }

    /// The drawn scenes' ranges: the config's, or the grid's widened by one step.
    fn ranges(&self, grid: GridCells<'_>) -> ([f64; 2], [f64; 2], [f64; 2]) {
        let span = |values: &mut dyn Iterator<Item = f64>| {
            values.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], v| {
                [lo.min(v), hi.max(v)]
            })
        };
        let [ego_low, ego_high] = span(&mut grid.speed_cases.iter().map(|c| c.ego_mph));
        let [diff_low, diff_high] =
            span(&mut grid.speed_cases.iter().map(|c| c.ego_mph - c.others_mph));
        let [head_low, head_high] = span(&mut grid.headways_m.iter().copied());
        let ego = self
            .ego_mph
            .unwrap_or([ego_low - REACH_MPH, ego_high + REACH_MPH]);
        let difference = self.difference_mph.unwrap_or([
            (diff_low - REACH_MPH).max(MIN_DIFFERENCE_MPH),
            diff_high + REACH_MPH,
        ]);
        let headway = self
            .headway_m
            .unwrap_or([(head_low - REACH_M).max(MIN_HEADWAY_M), head_high + REACH_M]);
        (ego, difference, headway)
    }
}

/// A drawn number to 0.1: a scene's name and the CSV show it as drawn.
fn round(x: f64) -> f64 {
    (x * 10.0).round() / 10.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two speed cases, two headways, two seeds.
    fn grid() -> GridCells<'static> {
        static CASES: std::sync::OnceLock<Vec<SpeedCaseConfig>> = std::sync::OnceLock::new();
        let cases = CASES.get_or_init(|| {
            vec![
                SpeedCaseConfig {
                    name: "collector-high".into(),
                    ego_mph: 45.0,
                    others_mph: 40.0,
                },
                SpeedCaseConfig {
                    name: "arterial-slow".into(),
                    ego_mph: 65.0,
                    others_mph: 55.0,
                },
            ]
        });
        GridCells {
            speed_cases: cases,
            headways_m: &[50.0, 30.0],
            seeds: &[1, 2],
        }
    }

    #[test]
    fn scenes_are_drawn_from_the_seed_around_the_grid() {
        let config = DriveConfig {
            users: vec!["deterministic".into()],
            lane_changes: Some(400),
            seed: 7,
            ..DriveConfig::default()
        };
        let scenes = config.scenes("drive", grid()).unwrap();
        assert_eq!(scenes.len(), 400);
        assert_eq!(
            scenes,
            config.scenes("drive", grid()).unwrap(),
            "one seed, one drive"
        );
        let other = DriveConfig {
            seed: 8,
            ..config.clone()
        };
        assert_ne!(scenes, other.scenes("drive", grid()).unwrap());
        // Every grid cell once (2 cases x 2 headways x 2 seeds), no scene twice.
        let on_grid = scenes.iter().filter(|s| s.seed <= 2).count();
        assert_eq!(on_grid, 8);
        for (i, scene) in scenes.iter().enumerate() {
            assert!(!scenes[..i].contains(scene), "scene {i} again: {scene:?}");
        }
        for scene in scenes.iter().filter(|s| s.seed > 2) {
            let case = &scene.speed_case;
            assert!((40.0..=70.0).contains(&case.ego_mph), "{case:?}");
            let difference = case.ego_mph - case.others_mph;
            assert!((1.0 - 0.1..=15.0 + 0.1).contains(&difference), "{case:?}");
            assert!((25.0..=55.0).contains(&scene.headway_m), "{scene:?}");
            assert!(DRAWN_SEEDS.contains(&scene.seed));
        }
    }

    #[test]
    fn the_grid_share_decides_grid_cells_without_moving_the_drawn_scenes() {
        let all_drawn = DriveConfig {
            lane_changes: Some(50),
            grid_share: Some(0.0),
            ..DriveConfig::default()
        };
        let all_grid = DriveConfig {
            grid_share: Some(1.0),
            ..all_drawn.clone()
        };
        let drawn = all_drawn.scenes("drive", grid()).unwrap();
        let cells = all_grid.scenes("drive", grid()).unwrap();
        let is_drawn = |s: &DriveScene| s.speed_case.name.starts_with("drawn-");
        assert!(drawn.iter().all(is_drawn));
        // The eight cells first, then, used up, drawn scenes: the same as without cells.
        assert!(cells[..8].iter().all(|s| s.seed <= 2 && !is_drawn(s)));
        assert_eq!(cells[8..], drawn[8..]);
        let half = DriveConfig {
            grid_share: Some(0.5),
            ..all_drawn.clone()
        };
        for (i, scene) in half.scenes("drive", grid()).unwrap().iter().enumerate() {
            assert!(
                scene == &drawn[i] || cells[..8].contains(scene),
                "scene {i}: {scene:?}"
            );
        }
    }

    #[test]
    fn bad_numbers_are_refused_with_the_field() {
        let bad = [
            (
                DriveConfig {
                    lane_changes: Some(0),
                    ..DriveConfig::default()
                },
                "drive.lane_changes",
            ),
            (
                DriveConfig {
                    grid_share: Some(f64::NAN),
                    ..DriveConfig::default()
                },
                "drive.grid_share",
            ),
            (
                DriveConfig {
                    headway_m: Some([40.0, 30.0]),
                    ..DriveConfig::default()
                },
                "drive.headway_m",
            ),
            (
                DriveConfig {
                    ego_mph: Some([0.0, 30.0]),
                    ..DriveConfig::default()
                },
                "drive.ego_mph",
            ),
        ];
        for (config, field) in bad {
            let error = config.validate("drive").unwrap_err().to_string();
            assert!(error.contains(field), "{error}");
        }
        let slow = DriveConfig {
            ego_mph: Some([10.0, 20.0]),
            difference_mph: Some([5.0, 12.0]),
            ..DriveConfig::default()
        };
        slow.validate("drive").unwrap();
        let error = slow.scenes("drive", grid()).unwrap_err().to_string();
        assert!(error.contains("drive.ego_mph"), "{error}");
    }
}
