//! The re-plan that the benchmark and the latency example time: the project's
//! learn config with its horizon stretched to K = 121 steps, an aggressive user's
//! experience after two lessons (weights and zone), and the first closed-loop
//! re-plan, one step into the lane change, so that it plans K − 1 = 120 steps.

use palc_aggregator::{AggregatorOptions, Experience};
use palc_harness::closed_loop::{ClosedLoop, Policy, Replan};
use palc_harness::{LearnConfig, LearningLoop, NoObserver, Setup, StylePreset, UserConfig};
use palc_planner::{Plan, PlannerConfig, State};
use palc_traffic::{EgoState, Scene};

/// Steps of the re-plan.
pub const REPLAN_STEPS: usize = 120;

/// Everything one re-plan reads.
pub struct Fixture {
    pub driver: ClosedLoop,
    pub setup: Setup,
    pub experience: Experience,
    pub options: AggregatorOptions,
    pub scene: Scene,
    pub tail: Vec<State>,
}

impl Fixture {
    pub fn new() -> Fixture {
        let text = include_str!("../../../configs/learn.toml");
        let mut config = LearnConfig::from_toml_str(text)
            .expect("the project's config")
            .with_user(UserConfig::preset(StylePreset::Aggressive));
        let horizon = palc_harness::prepare(&config).expect("a scenario").horizon;
        let extra = (REPLAN_STEPS + 1) as f64 - horizon as f64;
        config.planning.horizon_margin_s += extra * config.planning.dt;
        let setup = palc_harness::prepare(&config).expect("the stretched scenario");
        assert_eq!(setup.horizon, REPLAN_STEPS + 1);
        let mut run = LearningLoop::new(&config, None).expect("a loop");
        for _ in 0..2 {
            run.step(&mut NoObserver).expect("a lane change");
        }
        let experience = run.experience().clone();
        let plan: Plan = run.next_plan().clone();
        let options = palc_harness::aggregator_options(&config);
        let planner = PlannerConfig {
            horizon: setup.horizon,
            dt: setup.dt,
            ..config.planner.clone()
        };
        let driver = ClosedLoop::new(planner, 1, None).expect("a driver");
        let mut scene = setup.scene.clone();
        let first = plan.states[1];
        scene
            .step(
                setup.dt,
                EgoState {
                    s: first.s + setup.origin_s,
                    l: first.l,
                    v: first.v,
                    heading: first.phi,
                },
            )
            .expect("a step");
        Fixture {
            driver,
            setup,
            experience,
            options,
            scene,
            tail: plan.states[1..].to_vec(),
        }
    }

    /// One re-plan with the learned weights and zone.
    pub fn replan(&self) -> Replan {
        self.driver
            .replan(
                &self.setup,
                &self.experience,
                &self.options,
                &self.scene,
                &self.tail,
                1,
                Policy::Learned,
            )
            .expect("a re-plan")
    }
}
