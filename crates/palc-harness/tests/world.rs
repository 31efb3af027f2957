//! The world a lane change is driven in ([`palc_harness::World`]): palc's own
//! traffic reported through the interface gives the loop's results bit for bit,
//! open and closed loop, both methods, with and without the safety layer; the
//! loop reads the traffic a world reports; a world that fails or loses a vehicle
//! ends the run with an error naming it.

use palc_harness::{
    LearnConfig, LearningLoop, Method, NoObserver, PalcTraffic, RunResult, UserConfig, World,
    WorldError,
};
use palc_traffic::{EgoState, Observed, Scene};

fn config(method: Method, style: &str, closed_loop: bool, enforce: bool) -> LearnConfig {
    let text = include_str!("../../../configs/learn.toml")
        .replace(
            "enabled = false                    # off: one plan",
            &format!("enabled = {closed_loop} # one plan"),
        )
        .replace(
            "enforce = false                    # measure only",
            &format!("enforce = {enforce} # measure only"),
        );
    let config = LearnConfig::from_toml_str(&text).unwrap();
    assert_eq!(config.planning.closed_loop.enabled, closed_loop);
    let user = UserConfig {
        style: style.parse().unwrap(),
        ..config.user.clone()
    };
    config.with_method(method).with_user(user)
}

/// The run's results without its compute times, which differ from run to run.
fn results(mut result: RunResult) -> RunResult {
    for record in &mut result.records {
        record.times = Default::default();
    }
    result
}

fn run(config: &LearnConfig, world: Option<Box<dyn World>>) -> Result<RunResult, String> {
    let learning = LearningLoop::new(config, None).map_err(|e| e.to_string())?;
    let learning = match world {
        Some(world) => learning.in_world(world),
        None => learning,
    };
    learning.run(&mut NoObserver).map_err(|e| e.to_string())
}

#[test]
fn palc_traffic_through_the_interface_gives_the_same_runs() {
    let cases = [
        (Method::Palc, "aggressive", false, false),
        (Method::Palc, "cautious", true, false),
        (Method::Paper, "neutral", false, false),
        (Method::Palc, "neutral", true, true),
    ];
    for (method, style, closed_loop, enforce) in cases {
        let config = config(method, style, closed_loop, enforce);
        let own = run(&config, None);
        let through = run(&config, Some(Box::new(PalcTraffic::default())));
        match (own, through) {
            (Ok(own), Ok(through)) => {
                assert!(!own.records.is_empty());
                let (own, through) = (results(own), results(through));
                assert_eq!(own.records, through.records, "{method:?} {style}");
                assert_eq!(own.summary, through.summary, "{method:?} {style}");
                assert_eq!(own.experience.weights, through.experience.weights);
            }
            (own, through) => assert_eq!(own.err(), through.err(), "{method:?} {style}"),
        }
    }
}

/// palc's own traffic that fails at a given step, or loses its last vehicle.
#[derive(Debug)]
struct Failing {
    inner: PalcTraffic,
    steps: usize,
    fail_at: usize,
    lose_vehicle: bool,
}

impl World for Failing {
    fn name(&self) -> &str {
        "failing"
    }

    fn place(&mut self, scene: &Scene, dt: f64) -> Result<(), WorldError> {
        self.inner.place(scene, dt)
    }

    fn step(&mut self, ego: &EgoState) -> Result<Vec<Observed>, WorldError> {
        self.steps += 1;
        let mut observed = self.inner.step(ego)?;
        if self.steps == self.fail_at {
            if self.lose_vehicle {
                observed.pop();
            } else {
                return Err(WorldError::new("the simulator closed its connection"));
            }
        }
        Ok(observed)
    }
}

#[test]
fn a_world_that_fails_or_loses_a_vehicle_ends_the_run_with_its_error() {
    let config = config(Method::Palc, "neutral", false, false);
    for lose_vehicle in [false, true] {
        let world = Failing {
            inner: PalcTraffic::default(),
            steps: 0,
            fail_at: 7,
            lose_vehicle,
        };
        let learning = LearningLoop::new(&config, None)
            .unwrap()
            .in_world(Box::new(world));
        let error = learning.run(&mut NoObserver).unwrap_err();
        assert!(
            matches!(error, palc_harness::HarnessError::World { .. }),
            "{error}"
        );
        let cause = std::error::Error::source(&error).unwrap().to_string();
        assert!(error.to_string().contains("failing"), "{error}");
        if lose_vehicle {
            assert!(cause.contains("was not reported"), "{cause}");
        } else {
            assert!(cause.contains("closed its connection"), "{cause}");
        }
    }
}

/// palc's own traffic reported 2 m further along the road than it is.
#[derive(Debug, Default)]
struct Shifted(PalcTraffic);

impl World for Shifted {
    fn name(&self) -> &str {
        "shifted"
    }

    fn place(&mut self, scene: &Scene, dt: f64) -> Result<(), WorldError> {
        self.0.place(scene, dt)
    }

    fn step(&mut self, ego: &EgoState) -> Result<Vec<Observed>, WorldError> {
        let mut observed = self.0.step(ego)?;
        for report in &mut observed {
            report.s += 2.0;
        }
        Ok(observed)
    }
}

#[test]
fn the_loop_reads_the_traffic_the_world_reports() {
    let config = config(Method::Palc, "neutral", false, false);
    let own = run(&config, None).unwrap();
    let shifted = run(&config, Some(Box::new(Shifted::default()))).unwrap();
    let (own, shifted) = (&own.records[0], &shifted.records[0]);
    assert_eq!(own.driven_l, shifted.driven_l);
    // Every gap to a vehicle ahead is 2 m longer after the first step.
    let gap = |r: &palc_harness::LaneChangeRecord| r.safety.min_gap_preceding_m.unwrap();
    assert!(
        (gap(shifted) - gap(own) - 2.0).abs() < 1e-6,
        "{} {}",
        gap(shifted),
        gap(own)
    );
}
