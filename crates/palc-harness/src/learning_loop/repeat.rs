//! Computations repeated from their inputs instead of done again: a closed-loop
//! drive and a lesson that could not be learned.
//!
//! A closed-loop drive ([`ClosedLoop::drive_in`](crate::closed_loop::ClosedLoop::drive_in) without a world) is a function
//! of its inputs alone: the scenario, the experience, the options, the first plan
//! and whether the safety layer fell back; every re-plan builds a fresh planner.
//! When a lesson teaches nothing (the `paper` method's lessons mostly fail, see
//! `LessonEvent::Failed`), the next lane change drives the same plan with the same
//! experience, and its thirty-odd re-plans would give the same trajectory again.
//! [`LastDrive`] keeps the last drive with its inputs and hands it back when they
//! are equal; the scenario's own closed-loop driver changes only through
//! `ClosedLoop::plan_at_speeds`, which forgets the kept drive.
//!
//! Learning from a lesson ([`learn_from_lesson`]) is likewise a function of the
//! experience, the lesson, the problem template and the options (the planner
//! solves each problem cold). A deterministic user who takes over the same plan
//! gives the same lesson again; [`LastFailure`] keeps the error of the last
//! lesson that failed, with its inputs, and hands it back for equal ones.
//!
//! [`learn_from_lesson`]: palc_aggregator::learn_from_lesson

use palc_aggregator::{AggregatorError, AggregatorOptions, Experience, Lesson};
use palc_planner::{Plan, Problem};

use crate::record::ClosedLoopStats;

/// The last closed-loop drive of a run and what it was driven from.
#[derive(Debug, Default)]
pub(super) struct LastDrive {
    kept: Option<Box<Kept>>,
}

#[derive(Debug)]
struct Kept {
    experience: Experience,
    options: AggregatorOptions,
    first: Plan,
    fell_back: bool,
    driven: (Plan, ClosedLoopStats),
}

impl LastDrive {
    /// The kept drive, when it was driven from these inputs.
    pub(super) fn get(
        &self,
        experience: &Experience,
        options: &AggregatorOptions,
        first: &Plan,
        fell_back: bool,
    ) -> Option<(Plan, ClosedLoopStats)> {
        let kept = self.kept.as_deref()?;
        let same = kept.fell_back == fell_back
            && kept.first == *first
            && kept.experience == *experience
            && kept.options == *options;
        same.then(|| kept.driven.clone())
    }

    /// Keeps `driven`, the drive from these inputs.
    pub(super) fn keep(
        &mut self,
        experience: &Experience,
        options: &AggregatorOptions,
        first: &Plan,
        fell_back: bool,
        driven: &(Plan, ClosedLoopStats),
    ) {
        self.kept = Some(Box::new(Kept {
            experience: experience.clone(),
            options: options.clone(),
            first: first.clone(),
            fell_back,
            driven: driven.clone(),
        }));
    }

    /// Forgets the kept drive (the closed-loop driver changed).
    pub(super) fn forget(&mut self) {
        self.kept = None;
    }
}

/// The last lesson of a run that could not be learned, with what it was
/// learned from.
#[derive(Debug, Default)]
pub(super) struct LastFailure {
    kept: Option<Box<Failure>>,
}

#[derive(Debug)]
struct Failure {
    experience: Experience,
    lesson: Lesson,
    template: Problem,
    options: AggregatorOptions,
    error: AggregatorError,
}

impl LastFailure {
    /// The kept error, when the failed lesson was learned from these inputs.
    pub(super) fn get(
        &self,
        experience: &Experience,
        lesson: &Lesson,
        template: &Problem,
        options: &AggregatorOptions,
    ) -> Option<&AggregatorError> {
        let kept = self.kept.as_deref()?;
        let same = kept.lesson == *lesson
            && kept.experience == *experience
            && kept.template == *template
            && kept.options == *options;
        same.then_some(&kept.error)
    }

    /// Keeps `error`, the failure of learning from these inputs, and returns it.
    pub(super) fn keep(
        &mut self,
        experience: &Experience,
        lesson: &Lesson,
        template: &Problem,
        options: &AggregatorOptions,
        error: AggregatorError,
    ) -> &AggregatorError {
        let kept = self.kept.insert(Box::new(Failure {
            experience: experience.clone(),
            lesson: lesson.clone(),
            template: template.clone(),
            options: options.clone(),
            error,
        }));
        &kept.error
    }
}
