//! The order in which the runner starts the runs of a plan.
//!
//! A run is *ready* once the runs it needs have ended: the run whose experience
//! it starts from (`RunSpec::experience_from`) and, for a run that repeats an
//! earlier one ([`crate::shared_runs`]), its original. Each run starts as soon as
//! it is ready and a worker is free, so no worker waits for a whole phase or
//! wave to end while runs could start.
//!
//! Among the ready runs, the one on the longest chain of computed runs (through
//! it, from the first run of the chain to the last) starts first, ties in plan
//! order: critical-path list scheduling (Hu 1961; Graham 1969 bounds any such
//! list schedule within twice the optimum). A drive is a chain of a hundred lane
//! changes, each learning from the one before; started first, it runs beside the
//! many short runs instead of after them. Every run of a chain has the chain's
//! length, so a chain once started goes on before the next chain of the same
//! length starts (plan order): a thread follows one drive, whose driver estimate
//! extends the one before (the harness keeps the last posteriors), instead of
//! advancing every drive by one lane change in turn. The order changes no result:
//! a run's row depends only on its spec and the experience it starts from.

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
    /// For each run, the computed runs on the longest chain through it.
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
        // Runs need only earlier runs, so the chains below a run are known from
        // the back and the chains above it from the front. A repeat costs no
        // computation.
        let own = |id: usize| usize::from(original.get(id).is_none_or(|&of| of == id));
        let mut below = vec![0; n];
        for id in (0..n).rev() {
            let next = needed_by[id].iter().map(|&d| below[d]).max().unwrap_or(0);
            below[id] = own(id) + next;
        }
        let mut above = vec![0; n];
        for id in 0..n {
            for &next in &needed_by[id] {
                above[next] = above[next].max(above[id] + own(id));
            }
        }
        let chain: Vec<usize> = (0..n).map(|id| above[id] + below[id]).collect();
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

    /// The computed runs on the longest chain through run `id`.
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
        // Every run of a chain of single links has the chain's length.
        for spec in plan.all() {
            if let Some(source) = spec.experience_from {
                if schedule.needed_by[source].len() == 1 && schedule.waiting_on[spec.id] == 1 {
                    assert_eq!(schedule.chain(source), schedule.chain(spec.id));
                }
            }
        }
    }

    #[test]
    fn a_chain_once_started_goes_on_before_another_of_its_length_starts() {
        // Accumulation over every speed case: chains of several scenes.
        let mut selection = selection();
        selection.grid.speed_cases = testbed().speed_cases.to_vec();
        selection.transfer.accumulation_users = vec!["deterministic".into()];
        let plan = expand(&selection, &testbed()).unwrap();
        let original: Vec<usize> = (0..plan.len()).collect();
        let schedule = Schedule::new(&plan, &original);
        let order = order(&plan, &original);
        let runs: Vec<_> = plan.all().collect();
        let longest = schedule.chain(order[0]);
        assert!(longest > 2, "the test plan has chains of runs");
        // On one thread, the runs of the longest chains come one chain at a
        // time: a run that learns from a run with experience (the second scene
        // of a chain on) follows it at once.
        let on_longest: Vec<usize> = (order.iter().copied())
            .take_while(|&id| schedule.chain(id) == longest)
            .collect();
        let mut followed = 0;
        for pair in on_longest.windows(2) {
            let source = runs[pair[1]].experience_from;
            if source.is_some_and(|s| runs[s].experience_from.is_some()) {
                assert_eq!(source, Some(pair[0]), "{pair:?}");
                followed += 1;
            }
        }
        assert!(followed > 0, "the test plan has chains of three runs");
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
        // A repeat adds nothing: its chain is no longer than its original's.
        assert!(schedule.chain(b) <= schedule.chain(a));
        let order = order(&plan, &original);
        let at = |id| order.iter().position(|&x| x == id).unwrap();
        assert!(at(a) < at(b));
    }
}
