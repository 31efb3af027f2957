//! The grid of start models the posterior is over ([`Grid`]: every threshold of
//! every cue crossed with every reaction and pair of accepted gaps, then the
//! two-cue decision's pairs) and the start step of each of them in a scene,
//! run forward fast ([`Grid::for_each_start`]).

use std::ops::Range;

use palc_user::{Situation, StartModel};

use super::prior::{self, Cue, LAG_GAPS_S, LEAD_GAPS_S, REACTIONS_S};

/// A step index that means "never starts".
pub(super) const NEVER: u32 = u32::MAX;

/// The grid of start models: every threshold of every one-cue decision,
/// crossed with every reaction and pair of accepted gaps (hypothesis `h` below
/// [`Grid::single`] is threshold `h % thresholds` of combination
/// `h / thresholds`), then every threshold pair of the two-cue decision
/// ([`prior::paired_thresholds`]) crossed with every pair of accepted gaps,
/// without reaction (hypothesis `single + g * pairs + p` is pair `p` of gap
/// pair `g`).
#[derive(Debug, Clone)]
pub(super) struct Grid {
    /// Each one-cue decision with the index of its first threshold and its
    /// thresholds.
    pub(super) cues: Vec<(Cue, usize, Vec<f64>)>,
    /// All thresholds, of every one-cue decision.
    pub(super) thresholds: usize,
    /// The two-cue decision's pairs, as indices of all thresholds: the time
    /// headway's and the time to collision's.
    pub(super) pairs: Vec<(usize, usize)>,
}

impl Grid {
    pub(super) fn new() -> Grid {
        let mut offset = 0;
        let cues: Vec<(Cue, usize, Vec<f64>)> = (Cue::SINGLE.iter())
            .map(|&cue| {
                let thresholds = cue.thresholds();
                let first = offset;
                offset += thresholds.len();
                (cue, first, thresholds)
            })
            .collect();
        let first = |wanted: Cue| {
            (cues.iter())
                .find(|(cue, _, _)| *cue == wanted)
                .map_or(0, |(_, first, _)| *first)
        };
        let (headway, ttc) = (first(Cue::TimeHeadway), first(Cue::TimeToCollision));
        let pairs = (prior::paired_thresholds().into_iter())
            .map(|(h, t)| (headway + h, ttc + t))
            .collect();
        Grid {
            cues,
            thresholds: offset,
            pairs,
        }
    }

    pub(super) fn combinations() -> usize {
        REACTIONS_S.len() * Grid::gap_combinations()
    }

    pub(super) fn gap_combinations() -> usize {
        LEAD_GAPS_S.len() * LAG_GAPS_S.len()
    }

    /// The hypotheses of one-cue decisions, which come first.
    pub(super) fn single(&self) -> usize {
        self.thresholds * Grid::combinations()
    }

    pub(super) fn len(&self) -> usize {
        self.single() + self.pairs.len() * Grid::gap_combinations()
    }

    /// The cue and threshold of threshold index `t` (below `self.thresholds`).
    pub(super) fn threshold(&self, t: usize) -> (Cue, f64) {
        let mut rest = t;
        for (cue, _, thresholds) in &self.cues {
            if rest < thresholds.len() {
                return (*cue, thresholds[rest]);
            }
            rest -= thresholds.len();
        }
        // Past the last threshold: the last of the last cue.
        let (cue, _, thresholds) = &self.cues[self.cues.len() - 1];
        (*cue, thresholds[thresholds.len() - 1])
    }

    /// The cue of hypothesis `h`.
    pub(super) fn cue(&self, h: usize) -> Cue {
        if h < self.single() {
            self.threshold(h % self.thresholds).0
        } else {
            Cue::HeadwayOrTtc
        }
    }

    /// The start model of hypothesis `h`.
    pub(super) fn model(&self, h: usize) -> StartModel {
        if h >= self.single() {
            let k = h - self.single();
            let (headway, ttc) = self.pairs[k % self.pairs.len()];
            let (rule, time_headway_s) =
                Cue::paired_rule(self.threshold(headway).1, self.threshold(ttc).1);
            let (lead, lag) = gap_combination(k / self.pairs.len());
            return StartModel {
                rule,
                time_headway_s,
                reaction_s: 0.0,
                min_lead_gap_s: lead,
                min_lag_gap_s: lag,
            };
        }
        let (cue, threshold) = self.threshold(h % self.thresholds);
        let (rule, time_headway_s) = cue.rule(threshold);
        let (reaction_s, min_lead_gap_s, min_lag_gap_s) = combination(h / self.thresholds);
        StartModel {
            rule,
            time_headway_s,
            reaction_s,
            min_lead_gap_s,
            min_lag_gap_s,
        }
    }

    /// The start step of every hypothesis in a scene ([`NEVER`] for none), as
    /// [`Grid::for_each_start`] visits them: the list a test checks against
    /// [`StartModel::start_step`].
    #[cfg(test)]
    pub(super) fn starts(&self, scene: &SceneView<'_>) -> Vec<u32> {
        let mut starts = vec![NEVER; self.len()];
        self.for_each_start(scene, |hypotheses, start| starts[hypotheses].fill(start));
        starts
    }

    /// Calls `visit(hypotheses, start)` with every hypothesis once and its start
    /// step in a scene ([`NEVER`] for none): the fast form of
    /// [`StartModel::start_step`] (a test checks the two agree), sharing each
    /// threshold's decision step across the combinations and each pair of gaps'
    /// next acceptable step across the reactions and the two-cue pairs.
    /// `hypotheses` are consecutive hypotheses that start at the same step. A
    /// model that has decided at the scene's first step never starts in it: its
    /// driver would have changed lanes before the system planned (palc-user
    /// refuses such a scene for a simulated user).
    pub(super) fn for_each_start(
        &self,
        scene: &SceneView<'_>,
        mut visit: impl FnMut(Range<usize>, u32),
    ) {
        let n = scene.situations.len();
        // The first step at which each threshold decides (`n` for never).
        let mut decided_at = vec![n as u32; self.thresholds];
        for (cue, first, thresholds) in &self.cues {
            let mut running = f64::NEG_INFINITY;
            let most_urgent: Vec<f64> = (scene.situations.iter())
                .map(|s| {
                    running = running.max(cue.urgency(s, scene.set_speed_mps));
                    running
                })
                .collect();
            for (j, &threshold) in thresholds.iter().enumerate() {
                let key = cue.key(threshold);
                decided_at[first + j] = most_urgent.partition_point(|&u| u < key) as u32;
            }
        }
        let starts_from = |step: u32| (step > 0 && (step as usize) < n).then_some(step);
        let decision: Vec<u32> = (decided_at.iter())
            .map(|&step| starts_from(step).unwrap_or(NEVER))
            .collect();
        // A two-cue driver decides at the earlier of its two cues' decisions.
        let paired: Vec<u32> = (self.pairs.iter())
            .map(|&(h, t)| starts_from(decided_at[h].min(decided_at[t])).unwrap_or(NEVER))
            .collect();
        // The thresholds in runs of the same decision step.
        let mut runs: Vec<(Range<usize>, u32)> = Vec::new();
        for (t, &decided) in decision.iter().enumerate() {
            match runs.last_mut() {
                Some((range, step)) if *step == decided => range.end = t + 1,
                _ => runs.push((t..t + 1, decided)),
            }
        }
        let mut next = vec![NEVER; n + 1];
        for (lead_index, &lead) in LEAD_GAPS_S.iter().enumerate() {
            for (lag_index, &lag) in LAG_GAPS_S.iter().enumerate() {
                let gaps = StartModel {
                    min_lead_gap_s: lead,
                    min_lag_gap_s: lag,
                    ..self.model(0)
                };
                for i in (0..n).rev() {
                    let open = gaps.accepts(&scene.situations[i]) && scene.safe_through[i];
                    next[i] = if open { i as u32 } else { next[i + 1] };
                }
                let start_after = |decided: u32, reaction: usize| {
                    if decided != NEVER {
                        next[(decided as usize).saturating_add(reaction).min(n)]
                    } else {
                        NEVER
                    }
                };
                for (reaction_index, &reaction_s) in REACTIONS_S.iter().enumerate() {
                    let reaction = StartModel { reaction_s, ..gaps }.reaction_steps(scene.dt);
                    let c = combination_index(reaction_index, lead_index, lag_index);
                    let offset = c * self.thresholds;
                    for (thresholds, decided) in &runs {
                        let start = start_after(*decided, reaction);
                        visit(offset + thresholds.start..offset + thresholds.end, start);
                    }
                }
                let g = lead_index * LAG_GAPS_S.len() + lag_index;
                let offset = self.single() + g * self.pairs.len();
                let mut run: Option<(usize, u32)> = None;
                for (p, &decided) in paired.iter().enumerate() {
                    let start = start_after(decided, 0);
                    match run {
                        Some((_, step)) if step == start => {}
                        Some((first, step)) => {
                            visit(offset + first..offset + p, step);
                            run = Some((p, start));
                        }
                        None => run = Some((p, start)),
                    }
                }
                if let Some((first, step)) = run {
                    visit(offset + first..offset + self.pairs.len(), step);
                }
            }
        }
    }
}

/// The accepted lead and lag gaps of gap pair `g` (the lag's the inner index).
fn gap_combination(g: usize) -> (f64, f64) {
    (
        LEAD_GAPS_S[g / LAG_GAPS_S.len()],
        LAG_GAPS_S[g % LAG_GAPS_S.len()],
    )
}

/// The reaction and gaps of combination `c`.
pub(super) fn combination(c: usize) -> (f64, f64, f64) {
    let lag = c % LAG_GAPS_S.len();
    let lead = (c / LAG_GAPS_S.len()) % LEAD_GAPS_S.len();
    let reaction = c / (LAG_GAPS_S.len() * LEAD_GAPS_S.len());
    (REACTIONS_S[reaction], LEAD_GAPS_S[lead], LAG_GAPS_S[lag])
}

fn combination_index(reaction: usize, lead: usize, lag: usize) -> usize {
    (reaction * LEAD_GAPS_S.len() + lead) * LAG_GAPS_S.len() + lag
}

/// A scene as the estimate reads it.
pub(super) struct SceneView<'a> {
    situations: &'a [Situation],
    dt: f64,
    set_speed_mps: f64,
    /// Whether a lane change started at each step keeps the safety layer's
    /// distance throughout (all `true` without the layer).
    safe_through: Vec<bool>,
}

impl<'a> SceneView<'a> {
    /// `safe` per step (`None` without the safety layer), a lane change lasting
    /// `duration_s`.
    pub(super) fn new(
        situations: &'a [Situation],
        dt: f64,
        set_speed_mps: f64,
        safe: Option<&[bool]>,
        duration_s: f64,
    ) -> SceneView<'a> {
        let n = situations.len();
        let steps = (duration_s / dt).ceil().max(0.0) as usize;
        let safe_through = match safe {
            None => vec![true; n],
            Some(safe) => (0..n)
                .map(|i| {
                    safe[i..=i.saturating_add(steps).min(n - 1)]
                        .iter()
                        .all(|&s| s)
                })
                .collect(),
        };
        SceneView {
            situations,
            dt,
            set_speed_mps,
            safe_through,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene in which the headway falls from 2.2 s by 0.011 s per step behind
    /// a slower leader, with the target lane's follower alongside until step 60.
    fn approach() -> Vec<Situation> {
        (0..300)
            .map(|i| {
                let headway = 2.2 - 0.011 * f64::from(i);
                Situation {
                    time_headway_s: headway,
                    preceding_gap_m: headway * 20.0,
                    preceding_speed: Some(18.0),
                    target_lead_gap_m: Some(40.0 - 0.05 * f64::from(i)),
                    target_lag_gap_m: Some(if i < 60 {
                        -1.0
                    } else {
                        0.1 * f64::from(i - 60)
                    }),
                    ego_speed: 20.0,
                    target_lead_speed: Some(18.0),
                    target_lag_speed: Some(18.0),
                }
            })
            .collect()
    }

    #[test]
    fn the_fast_starts_are_the_start_models_own() {
        let seen = approach();
        let view = SceneView::new(&seen, 0.1, 25.0, None, 2.0);
        let grid = Grid::new();
        let starts = grid.starts(&view);
        // Every 97th hypothesis, spread over every cue and combination.
        for h in (0..grid.len()).step_by(97) {
            let model = grid.model(h);
            let reference = match model.start_step(&seen, 0.1, 25.0, |_| true) {
                Ok((_, start)) => start as u32,
                Err(_) => NEVER,
            };
            assert_eq!(starts[h], reference, "{model:?}");
        }
    }
}
