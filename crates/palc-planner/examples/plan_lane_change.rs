// Plan one lane change to the left with the planner alone (paper Eqs. 9-23), once
// inside a consistent safe zone with hard bounds and once through an inconsistent
// zone with soft bounds, and print both trajectories as CSV.
//
// Run with `cargo run -p palc-planner --example plan_lane_change`.

use palc_planner::{
    LateralBound, LateralBoundsMode, PlanError, Planner, PlannerConfig, Position, Problem,
    StageWeights, State, Terminal,
};

fn main() -> Result<(), PlanError> {
    // A 4 s horizon in steps of 0.1 s (K = 40) at 20 m/s; s is relative to the ego.
    let config = PlannerConfig {
        horizon: 40,
        dt: 0.1,
        lateral_bounds_mode: LateralBoundsMode::Hard,
        ..PlannerConfig::default()
    };
    let (k, dt, speed) = (config.horizon, config.dt, 20.0);
    let t = |i: usize| dt * i as f64;

    // The cost w · Φ of Eqs. (15) and (34), the same weights at every stage: stay near
    // the lane centre unless pulled (w1), keep the heading (w3), steer smoothly (w8).
    let weights = StageWeights {
        l_squared: 0.1,
        phi_squared: 1.0,
        delta_squared: 10.0,
        ..StageWeights::ZERO
    };
    // The safe zone of the zone filter: the road edges, but not past l = 1 m (the
    // lane marking is at 1.75 m) during the first second.
    let zone: Vec<Option<LateralBound>> = (0..=k)
        .map(|i| Some(LateralBound::new(-1.75, if i <= 10 { 1.0 } else { 5.25 })))
        .collect();

    // Every input is checked as it is given; an error names the field.
    let problem = Problem::builder(k)
        .initial(State {
            s: 0.0,
            v: speed,
            l: 0.0,
            phi: 0.0,
        })?
        .reference_speed(vec![speed; k])?
        .uniform_weights(weights)?
        // A slower vehicle 30 m ahead in the ego lane and a faster one 20 m behind on
        // the target lane, predicted at constant speed.
        .preceding(
            (0..k)
                .map(|i| Position {
                    s: 30.0 + 18.0 * t(i),
                    l: 0.0,
                })
                .collect(),
        )?
        .adjacent(
            (0..k)
                .map(|i| Position {
                    s: -20.0 + 22.0 * t(i),
                    l: 3.5,
                })
                .collect(),
        )?
        // End in the centre of the target lane, heading along the road (Eq. 21).
        .terminal(Terminal {
            s: None,
            v: speed,
            l: 3.5,
        })?
        .lateral_bounds(zone)?
        .build()?;

    println!("zone,step,t,s,v,l,phi,a,delta,violation");
    let mut planner = Planner::new(config.clone())?;
    let plan = planner.plan(&problem)?;
    print_csv("hard", &plan, dt);

    // A learned zone that excludes the target lane's centre at the end (l <= 3 m from
    // 3 s on): with hard bounds the planner refuses it, with soft bounds it plans
    // through it at a cost of 100 per metre of violation and step.
    let mut inconsistent = problem.clone();
    for bound in inconsistent.lateral_bounds.iter_mut().skip(30).flatten() {
        bound.max = Some(3.0);
    }
    if let Err(refused) = planner.plan(&inconsistent) {
        eprintln!("hard bounds refuse the inconsistent zone: {refused}");
    }
    let soft = PlannerConfig {
        lateral_bounds_mode: LateralBoundsMode::Soft { weight: 100.0 },
        ..config
    };
    let plan = Planner::new(soft)?.plan(&inconsistent)?;
    print_csv("soft", &plan, dt);
    Ok(())
}

fn print_csv(zone: &str, plan: &palc_planner::Plan, dt: f64) {
    for (i, x) in plan.states.iter().enumerate() {
        // The last state has no control.
        let u = plan.controls.get(i).copied().unwrap_or_default();
        println!(
            "{zone},{i},{:.2},{:.3},{:.3},{:.4},{:.5},{:.4},{:.5},{:.4}",
            dt * i as f64,
            x.s,
            x.v,
            x.l,
            x.phi,
            u.a,
            u.delta,
            plan.lateral_violation[i],
        );
    }
}
