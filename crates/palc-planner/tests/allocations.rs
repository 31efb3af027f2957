//! The Riccati backend allocates nothing inside its iterations: with the buffers sized
//! by an earlier plan of the same pattern, plans that take different numbers of
//! interior-point iterations make exactly the same heap allocations (those of the plan
//! itself: the result vectors).
//!
//! This binary installs dhat's counting allocator, so it holds this test alone.

mod common;

use common::lane_change;
use palc_planner::{LateralBound, LateralBoundsMode, Planner, PlannerConfig};

#[global_allocator]
static ALLOCATOR: dhat::Alloc = dhat::Alloc;

#[test]
fn allocations_do_not_grow_with_the_iterations() {
    let _profiler = dhat::Profiler::builder().testing().build();
    for mode in [
        LateralBoundsMode::Hard,
        LateralBoundsMode::Soft { weight: 100.0 },
    ] {
        let config = PlannerConfig {
            horizon: 60,
            dt: 0.1,
            lateral_bounds_mode: mode,
            ..PlannerConfig::default()
        };
        let easy = lane_change(&config, 20.0);
        // The same pattern, with bounds that hold the car in its lane for half the
        // horizon, then a late, steep lane change: more iterations.
        let mut hard = easy.clone();
        for step in 1..35 {
            hard.lateral_bounds[step] = Some(LateralBound::new(-0.2, 0.2));
        }
        for column in hard.weights.columns_mut() {
            column[0] = 5.0;
        }
        let mut planner = Planner::new(config).unwrap();
        planner.plan(&easy).unwrap();
        // The counts are process-wide: the test harness's own thread may allocate
        // while a plan runs (seen once on a loaded machine: 4 blocks more). The
        // plan's allocations are the same every time, so the fewest over a few
        // plans are the plan's own.
        let count = |planner: &mut Planner, problem| {
            (0..5)
                .map(|_| {
                    let before = dhat::HeapStats::get().total_blocks;
                    let plan = planner.plan(problem).unwrap();
                    let after = dhat::HeapStats::get().total_blocks;
                    (after - before, plan.stats.iterations)
                })
                .min()
                .expect("five plans")
        };
        let (easy_blocks, easy_iterations) = count(&mut planner, &easy);
        let (hard_blocks, hard_iterations) = count(&mut planner, &hard);
        println!(
            "{mode:?}: {easy_iterations} iterations, {easy_blocks} blocks; {hard_iterations} iterations, {hard_blocks} blocks"
        );
        assert!(
            hard_iterations > easy_iterations,
            "{mode:?}: {hard_iterations} vs {easy_iterations} iterations"
        );
        assert_eq!(
            easy_blocks, hard_blocks,
            "{mode:?}: {easy_iterations} iterations allocated {easy_blocks} blocks, {hard_iterations} allocated {hard_blocks}"
        );
    }
}
