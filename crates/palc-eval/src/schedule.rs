//! The order in which the runner starts the runs of a plan.
//!
//! A run is *ready* once the runs it needs have ended: the run whose experience
//! it starts from (`RunSpec::experience_from`) and, for a run that repeats an
//! earlier one ([`crate::shared_runs`]), its original. Each run starts as soon as
//! it is ready and a worker is free, so no worker waits for a whole phase or
//! wave to end while runs could start.
//!
//! Among the ready runs, the one heading the longest chain of computed runs that
//! wait on it starts first, ties in plan order: critical-path list scheduling
//! (Hu 1961; Graham 1969 bounds any such list schedule within twice the optimum).
//! A drive is a chain of a hundred lane changes, each learning from the one
//! before; started first, it runs beside the many short runs instead of after
//! them. The order changes no result: a run's row depends only on its spec and
//! the experience it starts from.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use crate::plan::RunPlan;

/// Which runs are ready, and which become ready when a run ends.
#[derive(Debug)]
pub struct Schedule {
    /// For each run, how many of the runs it needs have not ended.
    waiting_on: Vec<usize>,
    /// For each run, the runs that need it.
    needed_by: Vec<Vec<usize>>,
    /// For each run, the computed runs on the longest chain that starts with it.
    chain: Vec<usize>,
    /// Ready runs: the longest chain first, then the lowest index.
    ready: BinaryHeap<(usize, Reverse<usize>)>,
}

impl Schedule {
    /// The schedule of `plan`, where run `i` repeats run `original[i]` (itself
    /// when it repeats none, [`crate::shared_runs::originals`]). A source out of
    /// the plan is needed by no wait: the run finds no experience there.
    pub fn new(plan: &RunPlan, original: &[usize]) -> Schedule {
        let n = plan.len();
        let mut waiting_on = vec![0; n];
        let mut needed_by: Vec<Vec<usize>> = vec![Vec::new(); n];
        for spec in plan.all() {
            let id = spec.id;
            let mut needs: Vec<usize> = spec.experience_from.into_iter().collect();
            if let Some(&of) = original.get(id).filter(|&&of| of != id) {
                needs.push(of);
            }
            needs.sort_unstable();
            needs.dedup();
            for need in needs.into_iter().filter(|&need| need < n) {
                waiting_on[id] += 1;
                needed_by[need].push(id);
            }
        }
        // Runs need only earlier runs, so the chains are known from the back.
        // A repeat costs no computation.
        let mut chain = vec![0; n];
        for id in (0..n).rev() {
            let own = usize::from(original.get(id).is_none_or(|&of| of == id));
            let below = needed_by[id].iter().map(|&d| chain[d]).max().unwrap_or(0);
            chain[id] = own + below;
        }
        let ready = (0..n)
            .filter(|&id| waiting_on[id] == 0)
            .map(|id| (chain[id], Reverse(id)))
            .collect();
        Schedule {
            waiting_on,
            needed_by,
            chain,
            ready,
        }
    }

    /// The ready run to start next, removed from the ready runs.
    pub fn next_ready(&mut self) -> Option<usize> {
        self.ready.pop().map(|(_, Reverse(id))| id)
    }

    /// Marks run `id` ended: the runs that needed only it are ready.
    pub fn ended(&mut self, id: usize) {
        for &next in &self.needed_by[id] {
            self.waiting_on[next] -= 1;
            if self.waiting_on[next] == 0 {
                self.ready.push((self.chain[next], Reverse(next)));
            }
        }
    }

    /// The computed runs on the longest chain that starts with run `id`.
    pub fn chain(&self, id: usize) -> usize {
        self.chain[id]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::tests::{selection, testbed};
    use crate::plan::{Experiment, expand};

    /// Starts every run in the schedule's order, one at a time.
    fn order(plan: &RunPlan, original: &[usize]) -> Vec<usize> {
        let mut schedule = Schedule::new(plan, original);
        let mut order = Vec::new();
        while let Some(id) = schedule.next_ready() {
            order.push(id);
            schedule.ended(id);
        }
        order
    }

    #[test]
    fn every_run_starts_once_after_the_runs_it_needs() {
        let plan = expand(&selection(), &testbed()).unwrap();
        let original: Vec<usize> = (0..plan.len()).map(|i| i - i % 3).collect();
        let order = order(&plan, &original);
        assert_eq!(order.len(), plan.len());
        let mut position = vec![usize::MAX; plan.len()];
        for (at, &id) in order.iter().enumerate() {
            assert_eq!(position[id], usize::MAX, "run {id} started twice");
            position[id] = at;
        }
        for spec in plan.all() {
            if let Some(source) = spec.experience_from {
                assert!(position[source] < position[spec.id]);
            }
            assert!(position[original[spec.id]] <= position[spec.id]);
        }
    }

    #[test]
    fn the_longest_chain_starts_first() {
        let plan = expand(&selection(), &testbed()).unwrap();
        let original: Vec<usize> = (0..plan.len()).collect();
        let schedule = Schedule::new(&plan, &original);
        let longest = (0..plan.len()).map(|id| schedule.chain(id)).max().unwrap();
        assert!(longest > 1, "the test plan has chains of runs");
        let first = order(&plan, &original)[0];
        assert_eq!(schedule.chain(first), longest);
        // A run no run learns from is a chain of one.
        let alone = plan
            .all()
            .find(|s| s.experiment == Experiment::Timing)
            .unwrap();
        assert_eq!(schedule.chain(alone.id), 1);
    }

    #[test]
    fn a_repeat_adds_nothing_to_a_chain_and_waits_for_its_original() {
        let plan = expand(&selection(), &testbed()).unwrap();
        let mut original: Vec<usize> = (0..plan.len()).collect();
        let (a, b) = (0, plan.first.len() - 1);
        original[b] = a;
        let schedule = Schedule::new(&plan, &original);
        assert_eq!(schedule.waiting_on[b], 1);
        assert!(schedule.needed_by[a].contains(&b));
        let below = schedule.needed_by[b]
            .iter()
            .map(|&d| schedule.chain(d))
            .max();
        assert_eq!(schedule.chain(b), below.unwrap_or(0));
        let order = order(&plan, &original);
        let at = |id| order.iter().position(|&x| x == id).unwrap();
        assert!(at(a) < at(b));
    }
}
