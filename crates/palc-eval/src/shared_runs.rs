//! Runs that repeat another run of the plan, computed once and shared.
//!
//! Experiments overlap: the ablation's `paper` rung runs the grid's `paper` cells,
//! a transfer run is also a pair of the transfer matrix, and the first scene of an
//! accumulation chain is one too. A run repeats an earlier one when the executor
//! gives both the same identity ([`crate::runner::Executor::identity`]: what
//! determines the result) and both start from the same experience, that is from
//! no run or from runs that repeat each other. The runner computes the first of
//! them (its original) and gives every repeat the original's row under its own
//! spec, and the original's experience.

use std::collections::HashMap;

use crate::plan::{RunPlan, RunSpec};

/// The original of every run of `plan`, by run index: the first run of the plan
/// with the same identity and a source with the same original; a run is its own
/// original when it repeats no earlier run, or when `identity` gives none.
pub fn originals(plan: &RunPlan, identity: impl Fn(&RunSpec) -> Option<String>) -> Vec<usize> {
    let mut first_of: HashMap<(String, Option<usize>), usize> = HashMap::new();
    let mut original: Vec<usize> = Vec::with_capacity(plan.len());
    for spec in plan.all() {
        let id = original.len();
        debug_assert_eq!(spec.id, id);
        // A source comes earlier in the plan, so its original is known; a
        // source out of the plan is kept as it is.
        let source = (spec.experience_from).map(|s| original.get(s).copied().unwrap_or(s));
        let of = match identity(spec) {
            Some(key) => *first_of.entry((key, source)).or_insert(id),
            None => id,
        };
        original.push(of);
    }
    original
}

/// How many runs repeat each original that has repeats.
pub fn repeats(original: &[usize]) -> HashMap<usize, usize> {
    let mut count = HashMap::new();
    for (id, &of) in original.iter().enumerate() {
        if of != id {
            *count.entry(of).or_default() += 1;
        }
    }
    count
}

/// The outputs of originals that have repeats not yet given theirs, by run index.
pub struct Shared<R, X> {
    outputs: HashMap<usize, (R, Option<X>)>,
    left: HashMap<usize, usize>,
}

impl<R: Clone, X: Clone> Shared<R, X> {
    /// Nothing shared yet; `original` from [`originals`].
    pub fn new(original: &[usize]) -> Shared<R, X> {
        Shared {
            outputs: HashMap::new(),
            left: repeats(original),
        }
    }

    /// Whether run `id` is an original that some run repeats.
    pub fn has_repeats(&self, id: usize) -> bool {
        self.left.contains_key(&id)
    }

    /// Keeps the output of original `id` when a run repeats it.
    pub fn keep(&mut self, id: usize, output: &(R, Option<X>)) {
        if self.has_repeats(id) {
            self.outputs.insert(id, output.clone());
        }
    }

    /// The output of original `of`, when it has ended.
    pub fn output(&self, of: usize) -> Option<&(R, Option<X>)> {
        self.outputs.get(&of)
    }

    /// Counts one repeat of `of` served; the output is dropped after the last.
    pub fn served(&mut self, of: usize) {
        if let Some(left) = self.left.get_mut(&of) {
            *left -= 1;
            if *left == 0 {
                self.left.remove(&of);
                self.outputs.remove(&of);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::tests::{selection, testbed};
    use crate::plan::{Experiment, expand};

    /// An identity that ignores the experiment, as a harness config does.
    fn cell(spec: &RunSpec) -> Option<String> {
        Some(format!("{:?}", spec.experiment_cell()))
    }

    #[test]
    fn a_run_repeats_the_first_of_its_identity_and_source_and_chains_follow() {
        let plan = expand(&selection(), &testbed()).unwrap();
        let original = originals(&plan, cell);
        let runs: Vec<&RunSpec> = plan.all().collect();
        for (id, &of) in original.iter().enumerate() {
            assert!(of <= id);
            assert_eq!(original[of], of, "an original is its own");
            assert_eq!(cell(runs[id]), cell(runs[of]));
            let source = |s: &RunSpec| s.experience_from.map(|f| original[f]);
            assert_eq!(source(runs[id]), source(runs[of]));
        }
        // A grid run has no source: every other from-scratch run of its cell repeats it.
        let grid = runs
            .iter()
            .find(|s| s.experiment == Experiment::Grid)
            .unwrap();
        assert_eq!(original[grid.id], grid.id);
        let counts = repeats(&original);
        assert_eq!(
            counts.values().sum::<usize>(),
            original
                .iter()
                .enumerate()
                .filter(|(i, o)| *i != **o)
                .count()
        );
        // Without identities nothing is shared.
        let alone = originals(&plan, |_| None);
        assert!(alone.iter().enumerate().all(|(i, &o)| i == o));
    }

    #[test]
    fn a_shared_output_is_kept_until_its_last_repeat_is_served() {
        let original = vec![0, 0, 2, 0];
        let mut shared: Shared<&str, u8> = Shared::new(&original);
        assert!(shared.has_repeats(0) && !shared.has_repeats(2));
        shared.keep(0, &("row", Some(7)));
        shared.keep(2, &("other", None));
        assert_eq!(
            shared.output(2),
            None,
            "an original without repeats is not kept"
        );
        shared.served(0);
        assert_eq!(shared.output(0), Some(&("row", Some(7))));
        shared.served(0);
        assert_eq!(shared.output(0), None);
    }
}
