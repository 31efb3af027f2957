//! How a method personalizes (paper Section II.C;
//! docs/experiments/0005-the-two-methods.md): what a lesson demonstrates, what an
//! accepted lane change tells, and how experience is carried into a new scene. The
//! loop asks a [`Personalization`] and switches on no flag of its own.
//!
//! Three implementations compose every method and ablation rung
//! ([`for_options`]):
//!
//! | implementation | demonstration | carried into a new scene |
//! | --- | --- | --- |
//! | [`Replay`] (the paper's) | what was driven | weights resampled, same time base |
//! | [`RelativeOnset`] (palc's) | the user's whole lane change, fitted before the takeover | anchored at the user's start predicted in relative space |
//! | [`SceneAveraged`] around either | the mean of the scene's lessons in the gap its lane changes point to | as the inner one |

use std::cell::OnceCell;
use std::fmt;

use palc_aggregator::{AggregatorOptions, Experience, OwnLaneChange, Representation};
use palc_planner::Weights;

use crate::HarnessError;
use crate::carry::{self, Carried, Names};
use crate::onset::{OwnShape, UserLaneChange, onset_at};
use crate::scene_lessons::SceneLessons;
use crate::setup::Setup;

/// The lateral paths of one taken-over lane change, at steps `0..=K` of `dt`,
/// with the user's lane change fitted to them once, when first asked for.
#[derive(Debug, Clone)]
pub struct LessonPaths<'a> {
    /// What was driven: the system up to the takeover, then the user.
    pub driven_l: &'a [f64],
    /// The plan that was taken over.
    pub planned_l: &'a [f64],
    /// The first step the user drove.
    pub takeover_step: usize,
    /// Step (s).
    pub dt: f64,
    /// The target lane's centre (m).
    pub target_l: f64,
    /// The user's own lane change as last seen whole, from the experience.
    own: Option<OwnShape>,
    /// The user's lane change fitted to what it drove after the takeover.
    fitted: OnceCell<Option<UserLaneChange>>,
}

impl<'a> LessonPaths<'a> {
    /// The paths of a lesson taken over at `takeover_step`.
    pub fn new(
        driven_l: &'a [f64],
        planned_l: &'a [f64],
        takeover_step: usize,
        dt: f64,
        target_l: f64,
    ) -> Self {
        LessonPaths {
            driven_l,
            planned_l,
            takeover_step,
            dt,
            target_l,
            own: None,
            fitted: OnceCell::new(),
        }
    }

    /// These paths, with the user's own lane change as an experience last saw it
    /// whole (`Experience::own_lane_change`): fitted beside the lane-change
    /// models when the lesson shows only the end of the user's lane change.
    #[must_use]
    pub fn with_own_lane_change(mut self, own: Option<&OwnLaneChange>) -> Self {
        self.own = own.and_then(OwnShape::stored);
        self.fitted = OnceCell::new();
        self
    }

    /// The user's own lane change fitted to what it drove after the takeover
    /// (`onset::UserLaneChange::fit_lesson`); `None` when too little is left to fit.
    fn fitted(&self) -> Option<UserLaneChange> {
        self.fitted
            .get_or_init(|| {
                UserLaneChange::fit_lesson(
                    self.driven_l,
                    self.takeover_step,
                    self.dt,
                    self.target_l,
                    self.own.as_ref(),
                )
            })
            .clone()
    }

    /// The user's whole lane change, when this lesson showed it from rest in its
    /// lane to its end (the takeover came before the user's own start): its shape,
    /// for the experience to keep. `None` otherwise.
    pub fn own_lane_change_seen(&self) -> Option<OwnLaneChange> {
        let user = self.fitted()?;
        let own = user.own_shape_seen(self.driven_l, self.takeover_step, self.dt)?;
        Some(own.to_stored())
    }

    /// The user's lane change as the model fitted to this lesson, when the lesson
    /// pins the model down (`onset::UserLaneChange::own_shape_fitted`): the
    /// shape for an experience that has not seen one whole. `None` otherwise.
    pub fn own_lane_change_fitted(&self) -> Option<OwnLaneChange> {
        let user = self.fitted()?;
        let own = user.own_shape_fitted(self.driven_l, self.takeover_step, self.dt)?;
        Some(own.to_stored())
    }
}

/// What a lesson teaches.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Demonstration {
    /// The lateral path (m, steps `0..=K`) the expert follows; `None` for what was
    /// driven.
    pub path: Option<Vec<f64>>,
    /// The user's start (s) when the lesson shows where the user starts in this
    /// scene; recorded in the experience once the lesson is learned.
    pub start_s: Option<f64>,
}

/// How a method turns lessons into demonstrations and carries what it learned.
pub trait Personalization: fmt::Debug + Send {
    /// The demonstration of a taken-over lane change.
    fn demonstrate(&mut self, lesson: &LessonPaths<'_>) -> Demonstration;

    /// A lane change the user accepted (no takeover), its driven lateral path at
    /// steps of `dt`; by default it tells nothing.
    fn accepted(&mut self, _driven_l: &[f64], _dt: f64, _target_l: f64) {}

    /// The experience a run starts from in `setup`: `previous` carried into it
    /// (with the user's path to rehearse there, if any), or a fresh one holding
    /// the standard ALC's weights. By default the weights keep their time base.
    ///
    /// # Errors
    /// Resampling errors of the aggregator.
    fn carry(
        &self,
        names: Names<'_>,
        standard_weights: &Weights,
        setup: &Setup,
        previous: Option<&Experience>,
    ) -> Result<Carried, HarnessError> {
        carry::starting_experience(names, standard_weights, setup, previous, false)
    }

    /// Records the user's start `start_s` seen in a lesson of `setup` in the
    /// experience: merged into this scene's onset, which becomes the anchor of
    /// the weights.
    fn observe_start(&self, experience: &mut Experience, setup: &Setup, start_s: f64) {
        record_onset(experience, setup, start_s);
    }

    /// Records in the experience what `lesson` showed of the user's lane change
    /// as a whole; by default nothing (the paper's method keeps no shape).
    fn observe_lane_change(&self, _experience: &mut Experience, _lesson: &LessonPaths<'_>) {}
}

/// The implementations a method's options compose: [`Replay`] or
/// [`RelativeOnset`] by `representation`, inside [`SceneAveraged`] with
/// `average_lessons`.
pub fn for_options(options: &AggregatorOptions) -> Box<dyn Personalization> {
    match (options.representation, options.average_lessons) {
        (Representation::TimeIndexed, false) => Box::new(Replay),
        (Representation::TimeIndexed, true) => Box::new(SceneAveraged::new(Replay)),
        (Representation::RelativeOnset, false) => Box::new(RelativeOnset),
        (Representation::RelativeOnset, true) => Box::new(SceneAveraged::new(RelativeOnset)),
    }
}

/// The paper's personalization: the expert follows what was driven, and the
/// weights carry with their time base.
#[derive(Debug, Clone, Copy, Default)]
pub struct Replay;

impl Personalization for Replay {
    fn demonstrate(&mut self, lesson: &LessonPaths<'_>) -> Demonstration {
        Demonstration {
            path: None,
            start_s: lesson.fitted().map(|user| user.start_s),
        }
    }
}

/// palc's personalization in relative space
/// (docs/experiments/0046-carrying-rehearsal-and-bounds.md; measured in
/// docs/experiments/0047-relative-onset-measured.md): the expert follows the
/// user's whole lane change (before the takeover, the model fitted to what the
/// user drove after it), and the weights carry anchored at the start predicted in
/// the new scene.
#[derive(Debug, Clone, Copy, Default)]
pub struct RelativeOnset;

impl Personalization for RelativeOnset {
    fn demonstrate(&mut self, lesson: &LessonPaths<'_>) -> Demonstration {
        match lesson.fitted() {
            Some(user) => Demonstration {
                path: Some(user.path(lesson.driven_l, lesson.takeover_step, lesson.dt)),
                start_s: Some(user.start_s),
            },
            None => Demonstration::default(),
        }
    }

    fn carry(
        &self,
        names: Names<'_>,
        standard_weights: &Weights,
        setup: &Setup,
        previous: Option<&Experience>,
    ) -> Result<Carried, HarnessError> {
        carry::starting_experience(names, standard_weights, setup, previous, true)
    }

    /// Keeps the user's own lane change when the lesson showed it whole, or,
    /// when the experience has none, the model that fitted a lesson exactly: later
    /// lessons that see only its end place its start by it
    /// (docs/experiments/0077-the-users-own-shape.md,
    /// docs/experiments/0079-a-reaction-and-a-shape-pinned-down.md).
    fn observe_lane_change(&self, experience: &mut Experience, lesson: &LessonPaths<'_>) {
        if let Some(own) = lesson.own_lane_change_seen() {
            experience.own_lane_change = Some(own);
        } else if experience.own_lane_change.is_none() {
            experience.own_lane_change = lesson.own_lane_change_fitted();
        }
    }
}

/// The mean of the scene's lessons (`average_lessons`;
/// docs/experiments/0050-users-with-spread-averaging-and-window.md,
/// docs/experiments/0063-the-gap-the-lane-changes-point-to.md): the expert of a
/// lesson follows the mean of the inner demonstrations that started in the gap the
/// scene's lane changes point to; a lesson into another gap keeps the plan and
/// shows no start.
#[derive(Debug, Clone, Default)]
pub struct SceneAveraged<P> {
    inner: P,
    lessons: SceneLessons,
}

impl<P> SceneAveraged<P> {
    /// Averages the demonstrations of `inner`.
    pub fn new(inner: P) -> Self {
        SceneAveraged {
            inner,
            lessons: SceneLessons::default(),
        }
    }
}

impl<P: Personalization> Personalization for SceneAveraged<P> {
    fn demonstrate(&mut self, lesson: &LessonPaths<'_>) -> Demonstration {
        let inner = self.inner.demonstrate(lesson);
        let Some(user) = lesson.fitted() else {
            return inner;
        };
        let path = (inner.path).unwrap_or_else(|| lesson.driven_l.to_vec());
        let mean = self.lessons.add(user, path, lesson.dt);
        Demonstration {
            path: Some(mean.path.unwrap_or_else(|| lesson.planned_l.to_vec())),
            start_s: inner.start_s.filter(|_| mean.includes_lesson),
        }
    }

    /// Counts the lane change's start: it tells which gap the user takes.
    fn accepted(&mut self, driven_l: &[f64], dt: f64, target_l: f64) {
        if let Some(driven) = UserLaneChange::fit(driven_l, 0, dt, target_l) {
            self.lessons.accept(driven.start_s);
        }
        self.inner.accepted(driven_l, dt, target_l);
    }

    fn carry(
        &self,
        names: Names<'_>,
        standard_weights: &Weights,
        setup: &Setup,
        previous: Option<&Experience>,
    ) -> Result<Carried, HarnessError> {
        self.inner.carry(names, standard_weights, setup, previous)
    }

    fn observe_start(&self, experience: &mut Experience, setup: &Setup, start_s: f64) {
        self.inner.observe_start(experience, setup, start_s);
    }

    fn observe_lane_change(&self, experience: &mut Experience, lesson: &LessonPaths<'_>) {
        self.inner.observe_lane_change(experience, lesson);
    }
}

/// Merges the start `start_s` seen in `setup` into this scene's onset (the last
/// of `experience.onsets` when it is this scene's), which becomes the anchor of
/// the weights; the onsets of earlier scenes tell which waits were for the
/// leader's gap.
fn record_onset(experience: &mut Experience, setup: &Setup, start_s: f64) {
    let onsets = &mut experience.onsets;
    let this_scene = if onsets.last().is_some_and(|o| o.scenario == setup.label) {
        onsets.pop()
    } else {
        None
    };
    let Some(observed) = onset_at(setup, start_s, onsets) else {
        onsets.extend(this_scene);
        return;
    };
    let merged = match this_scene {
        Some(last) => last.merged(&observed),
        None => observed,
    };
    experience.anchor_s = Some(merged.time_s);
    onsets.push(merged);
}

#[cfg(test)]
mod tests {
    use super::*;
    use palc_user::quintic;

    const DT: f64 = 0.1;
    const TARGET_L: f64 = 3.5;

    /// A quintic lane change from `start_s` over `duration_s`, at steps `0..=k`.
    fn lane_change(start_s: f64, duration_s: f64, k: usize) -> Vec<f64> {
        (0..=k)
            .map(|i| {
                let t = (i as f64 * DT - start_s) / duration_s;
                TARGET_L * quintic(t.clamp(0.0, 1.0))
            })
            .collect()
    }

    fn paths<'a>(driven: &'a [f64], planned: &'a [f64], takeover_step: usize) -> LessonPaths<'a> {
        LessonPaths::new(driven, planned, takeover_step, DT, TARGET_L)
    }

    #[test]
    fn replay_demonstrates_what_was_driven_and_sees_the_start() {
        let driven = lane_change(3.0, 2.0, 80);
        let planned = lane_change(5.0, 3.0, 80);
        let demonstration = Replay.demonstrate(&paths(&driven, &planned, 32));
        assert_eq!(demonstration.path, None);
        let start = demonstration.start_s.expect("a lane change to fit");
        assert!((start - 3.0).abs() < 0.15, "{start}");
    }

    #[test]
    fn relative_onset_demonstrates_the_whole_fitted_lane_change() {
        // The system drove its own plan until step 35, then the user drove its quintic.
        let user = lane_change(3.0, 2.0, 80);
        let planned = lane_change(5.0, 3.0, 80);
        let takeover = 35;
        let driven: Vec<f64> = (0..=80)
            .map(|i| if i < takeover { planned[i] } else { user[i] })
            .collect();
        let demonstration = RelativeOnset.demonstrate(&paths(&driven, &planned, takeover));
        let path = demonstration.path.expect("a fitted path");
        assert_eq!(path.len(), driven.len());
        // After the takeover it is what the user drove; before, close to the user's own.
        assert_eq!(path[takeover..], driven[takeover..]);
        let worst = (path.iter().zip(&user))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.1, "{worst}");
    }

    #[test]
    fn palcs_personalization_keeps_the_users_own_lane_change_when_a_lesson_shows_it_whole() {
        let weights = Weights::from_columns(vec![[1.0; palc_planner::FEATURE_COUNT]; 81]);
        let fresh = Experience::new("user", "scene", "palc", weights, DT).unwrap();
        let user = lane_change(5.0, 2.0, 80);
        let planned = lane_change(3.0, 3.0, 80);
        // Taken over at 4 s, before the user's start at 5 s: it kept its lane,
        // then drove its whole lane change.
        let takeover = 40;
        let driven: Vec<f64> = (0..=80)
            .map(|i| if i < takeover { planned[i] } else { user[i] })
            .collect();
        let whole = paths(&driven, &planned, takeover);
        let own = whole.own_lane_change_seen().expect("seen from rest");
        assert!(own.validate().is_ok());
        let mut palc = fresh.clone();
        SceneAveraged::new(RelativeOnset).observe_lane_change(&mut palc, &whole);
        assert_eq!(palc.own_lane_change, Some(own));
        // The paper's method keeps no shape.
        let mut paper = fresh.clone();
        Replay.observe_lane_change(&mut paper, &whole);
        assert_eq!(paper, fresh);
        // Taken over after the user's start, nothing is seen whole.
        let late = paths(&user, &planned, 55);
        assert_eq!(late.own_lane_change_seen(), None);
        let mut kept = palc.clone();
        RelativeOnset.observe_lane_change(&mut kept, &late);
        assert_eq!(kept, palc);
        // Taken over just after the user's start, the quintic explains what it
        // drove: the fitted model is kept by an experience without a shape, and
        // never replaces one seen whole.
        let early = (0..=80).find(|&i| user[i] > 0.1).unwrap();
        let pinned = paths(&user, &planned, early);
        assert_eq!(pinned.own_lane_change_seen(), None);
        let fitted = pinned.own_lane_change_fitted().expect("pinned down");
        let mut without = fresh.clone();
        RelativeOnset.observe_lane_change(&mut without, &pinned);
        assert_eq!(without.own_lane_change, Some(fitted));
        let mut with_whole = palc.clone();
        RelativeOnset.observe_lane_change(&mut with_whole, &pinned);
        assert_eq!(with_whole, palc);
    }

    #[test]
    fn nothing_to_fit_is_no_demonstration_and_no_start() {
        let flat = vec![0.0; 41];
        for personalization in [
            &mut Replay as &mut dyn Personalization,
            &mut RelativeOnset,
            &mut SceneAveraged::new(RelativeOnset),
        ] {
            let demonstration = personalization.demonstrate(&paths(&flat, &flat, 10));
            assert_eq!(
                demonstration,
                Demonstration::default(),
                "{personalization:?}"
            );
        }
    }

    #[test]
    fn scene_averaging_follows_the_gap_the_accepted_lane_changes_point_to() {
        let planned = lane_change(6.0, 3.0, 120);
        let mut averaged = SceneAveraged::new(Replay);
        // Three lane changes the user accepted start at 3 s.
        for _ in 0..3 {
            averaged.accepted(&lane_change(3.0, 2.0, 120), DT, TARGET_L);
        }
        // A lesson into another gap (8 s) keeps the plan and shows no start.
        let late = lane_change(8.0, 2.0, 120);
        let demonstration = averaged.demonstrate(&paths(&late, &planned, 70));
        assert_eq!(demonstration.path.as_deref(), Some(&planned[..]));
        assert_eq!(demonstration.start_s, None);
        // A lesson into the 3 s gap is followed, with its start.
        let early = lane_change(3.0, 2.0, 120);
        let demonstration = averaged.demonstrate(&paths(&early, &planned, 20));
        let path = demonstration.path.expect("the mean of the gap's lessons");
        assert!((path.iter().zip(&early)).all(|(a, b)| (a - b).abs() < 1e-12));
        assert!(demonstration.start_s.is_some());
    }

    #[test]
    fn the_methods_options_compose_their_implementations() {
        let paper = format!("{:?}", for_options(&AggregatorOptions::paper()));
        assert_eq!(paper, "Replay");
        let palc = format!("{:?}", for_options(&AggregatorOptions::default()));
        assert!(
            palc.starts_with("SceneAveraged { inner: RelativeOnset"),
            "{palc}"
        );
    }
}
