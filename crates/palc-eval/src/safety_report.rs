//! REPORT.md's safety section: collisions, RSS safe-distance violations, the
//! safety layer's refusals and the distributions of the smallest gaps and times to
//! collision, per experiment and method
//! (docs/experiments/0030-safety-measures-acc-and-gap-seeking.md,
//! docs/experiments/0031-the-safety-layer-and-the-papers-scenes.md and
//! docs/experiments/0032-the-safe-set-up-measured.md).

use std::fmt::Write as _;

use palc_harness::{Method, safety::SafetyMetrics};

use crate::plan::Experiment;
use crate::results::{Iteration, RunRow};
use crate::stats::percentile;

/// Writes the section.
pub fn section(out: &mut String, rows: &[RunRow], methods: &[Method]) {
    let _ = writeln!(out, "## Safety of every executed lane change\n");
    let _ = writeln!(
        out,
        "Every lane change is measured step by step in the scene: the net gap and time to collision \
         to the preceding vehicle and to the target lane's lead and lag vehicles (while the ego \
         occupies their lane), footprint overlaps (collisions) and the RSS longitudinal safe distance \
         (response 0.5 s, 1.5 m/s² during it, 6 m/s² braking for both vehicles; \
         `[planning.safety]`). *System* counts the steps the system drove (the plan up to a \
         takeover); *user* the steps the simulated user drove after a takeover. The safety layer \
         checks every plan before it is driven and drives the standard ALC's plan instead of an \
         unsafe one (a refusal), when the config turns it on (`planning.safety.enforce`). \
         Whatever drives the ego (plan, re-plan or user), the longitudinal guard \
         (`planning.acc.guard`, on by default) caps its acceleration by the ACC's law behind \
         the vehicle ahead in a lane it moves into and by the ACC's emergency brake in its \
         own lane; the lateral path stays the driver's \
         (docs/experiments/0034-the-longitudinal-guard.md). The paper's set-up otherwise \
         holds every speed constant and \
         has no safety layer: under the layer alone none of its scenes has a safe lane change \
         (the ego closes on the preceding vehicle, or on the target lane's platoon, below the \
         safe distance) and every cell is refused, so its figures are measured on scenes the \
         layer would refuse (docs/experiments/0031-the-safety-layer-and-the-papers-scenes.md); \
         `configs/reproduce-safe.toml` is the same evaluation with the ego's ACC, the safety layer \
         and users who start only into gaps at the safe distance (`cargo xtask reproduce-paper` \
         writes its report to `safe/REPORT.md`, and the stress scenes of `configs/stress/` under \
         the same set-up to `stress/`).\n"
    );
    let _ = writeln!(
        out,
        "| experiment | method | lane changes | system: collisions | system: RSS violations | user: collisions | user: RSS violations | refusals | min gap preceding, p5 / min (m) | min gap target lead, p5 / min (m) | min gap target lag, p5 / min (m) | min TTC, p5 / min (s) |"
    );
    let _ = writeln!(
        out,
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    let mut totals = Totals::default();
    for experiment in [
        Experiment::Grid,
        Experiment::Transfer,
        Experiment::Timing,
        Experiment::ClosedLoop,
        Experiment::Matrix,
        Experiment::Accumulation,
        Experiment::Ablation,
        Experiment::AblationTransfer,
    ] {
        for &method in methods {
            let iterations: Vec<&Iteration> = rows
                .iter()
                .filter(|r| r.spec.experiment == experiment && r.spec.method == method)
                .flat_map(|r| &r.iterations)
                .collect();
            if iterations.is_empty() {
                continue;
            }
            let count = |f: &dyn Fn(&Iteration) -> bool| iterations.iter().filter(|i| f(i)).count();
            let distribution = |f: &dyn Fn(&SafetyMetrics) -> Option<f64>| {
                let values: Vec<f64> = iterations.iter().filter_map(|i| f(&i.safety)).collect();
                low_tail(values)
            };
            // An ablation run's method is its rung's label rule: every such rung.
            let who = match experiment {
                Experiment::Ablation | Experiment::AblationTransfer => {
                    format!("rungs with `{}` labels", method.name())
                }
                _ => format!("`{}`", method.name()),
            };
            let counts = Totals {
                system_collisions: count(&|i| i.safety.collision),
                system_violations: count(&|i| i.safety.rss_violations > 0),
                user_collisions: count(&|i| i.user_safety.collision),
                user_violations: count(&|i| i.user_safety.rss_violations > 0),
            };
            totals.add(&counts);
            let _ = writeln!(
                out,
                "| {} | {who} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                experiment.name(),
                iterations.len(),
                counts.system_collisions,
                counts.system_violations,
                counts.user_collisions,
                counts.user_violations,
                count(&|i| i.safety_refusal.is_some()),
                distribution(&|s| s.min_gap_preceding_m),
                distribution(&|s| s.min_gap_target_lead_m),
                distribution(&|s| s.min_gap_target_lag_m),
                distribution(&SafetyMetrics::min_ttc_s),
            );
        }
    }
    let _ = writeln!(out);
    let _ = writeln!(out, "{}\n", verdict(&totals));
    let first_user_violation = rows
        .iter()
        .flat_map(|r| r.iterations.iter().map(move |i| (r, i)))
        .find_map(|(r, i)| i.user_safety.first_violation.map(|v| (r, v)));
    if let Some((row, violation)) = first_user_violation {
        let _ = writeln!(
            out,
            "A user-driven violation, for example (`{}`): {violation}. The simulated user's own \
             lane change is the user's choice; the system neither plans nor drives it.\n",
            row.spec.label()
        );
    }
}

/// Lane changes with a collision or an RSS violation, over every experiment and
/// method, in the steps the system drove and in those the user drove.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
struct Totals {
    system_collisions: usize,
    system_violations: usize,
    user_collisions: usize,
    user_violations: usize,
}

impl Totals {
    fn add(&mut self, other: &Totals) {
        self.system_collisions += other.system_collisions;
        self.system_violations += other.system_violations;
        self.user_collisions += other.user_collisions;
        self.user_violations += other.user_violations;
    }
}

/// The sentence that sets the totals against the target of no collision and no
/// RSS violation in any executed lane change, system- or user-driven.
fn verdict(t: &Totals) -> String {
    let met = *t == Totals::default();
    let mut sentence = "Target: no collision and no RSS violation in any executed lane change of \
                        any experiment, system- or user-driven: "
        .to_owned();
    if met {
        sentence.push_str("met.");
    } else {
        sentence.push_str(&format!(
            "**not met** (lane changes with a collision: {} system-driven, {} user-driven; with \
             an RSS violation: {} system-driven, {} user-driven).",
            t.system_collisions, t.user_collisions, t.system_violations, t.user_violations
        ));
    }
    sentence
}

/// `p5 / min` of `values` (nearest-rank percentile) with one decimal, `-` when
/// there are none.
fn low_tail(mut values: Vec<f64>) -> String {
    if values.is_empty() {
        return "-".to_owned();
    }
    values.sort_by(f64::total_cmp);
    format!("{:.1} / {:.1}", percentile(&values, 0.05), values[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_low_tail_is_the_fifth_percentile_and_the_minimum() {
        assert_eq!(low_tail(Vec::new()), "-");
        let values: Vec<f64> = (0..=100).map(f64::from).rev().collect();
        assert_eq!(low_tail(values), "5.0 / 0.0");
        assert_eq!(low_tail(vec![3.25]), "3.2 / 3.2");
    }

    #[test]
    fn the_target_is_met_only_without_any_collision_or_violation() {
        assert!(verdict(&Totals::default()).ends_with(": met."));
        let one_user_violation = Totals {
            user_violations: 1,
            ..Totals::default()
        };
        let text = verdict(&one_user_violation);
        assert!(text.contains("**not met**"), "{text}");
        assert!(
            text.contains("RSS violation: 0 system-driven, 1 user-driven"),
            "{text}"
        );
    }
}
