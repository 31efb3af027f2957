//! The re-plan that the benchmark and the latency example time: the project's
//! learn config (its horizon stretched when shorter than 121 steps), an
//! aggressive user's experience after two lessons (weights and zone), and the
//! closed-loop re-plan `K − 120` steps into the lane change, so that it plans the
//! remaining 120 steps.

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
    pub step: usize,
}

impl Fixture {
    pub fn load() -> Fixture {
        let text = include_str!("../../../../configs/learn.toml");
        let mut config = LearnConfig::from_toml_str(text)
            .expect("the project's config")
            .with_user(UserConfig::preset(StylePreset::Aggressive));
        let horizon = palc_harness::prepare(&config).expect("a scenario").horizon;
        if horizon <= REPLAN_STEPS {
            let extra = (REPLAN_STEPS + 1 - horizon) as f64;
            config.planning.horizon_margin_s += extra * config.planning.dt;
        }
        let setup = palc_harness::prepare(&config).expect("the scenario");
        let step = setup.horizon - REPLAN_STEPS;
        assert!(step >= 1);
        let mut run = LearningLoop::new(&config, None).expect("a loop");
        for _ in 0..2 {
            run.step(&mut NoObserver).expect("a lane change");
        }
        let experience = run.experience().clone();
        let plan: Plan = run.next_plan().clone();
        let options = palc_harness::advanced::aggregator_options(&config);
        let planner = PlannerConfig {
            horizon: setup.horizon,
            dt: setup.dt,
            ..config.planner.clone()
        };
        let driver = ClosedLoop::new(planner, 1, None).expect("a driver");
        let mut scene = setup.scene.clone();
        for state in &plan.states[1..=step] {
            let ego = EgoState {
                s: state.s + setup.origin_s,
                l: state.l,
                v: state.v,
                heading: state.phi,
            };
            scene.step(setup.dt, ego).expect("a step");
        }
        Fixture {
            driver,
            setup,
            experience,
            options,
            scene,
            tail: plan.states[step..].to_vec(),
            step,
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
                self.step,
                Policy::Learned,
            )
            .expect("a re-plan")
    }
}
