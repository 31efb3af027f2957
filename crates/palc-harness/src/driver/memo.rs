//! The posteriors computed last, kept so that the next estimate extends one
//! instead of starting from the prior.
//!
//! A drive carries its experience into a new scene after every lane change, and
//! each carry estimates the driver from every scene seen so far: the scenes of
//! the carry before and one more. Recomputed from the prior, a drive of `n` lane
//! changes reads `n²/2` scenes over the grid's 2.7 million models; extended, `n`. The
//! posterior is a sum over scenes in their order, so an extended one is bit for
//! bit the one recomputed (a test checks it).
//!
//! The memo holds [`capacity`] posteriors (68 MB each, with their weights), the most recently used
//! last; an entry serves an estimate whose scenes begin with the entry's, and,
//! when a scene carries the safety layer's verdicts (which depend on the lane
//! change's duration), whose duration is the entry's.

use std::sync::{Arc, Mutex, OnceLock, PoisonError};

use palc_aggregator::Onset;

/// The posterior over the grid after some scenes, as [`super::DriverEstimate`] accumulates it.
#[derive(Debug, Clone)]
pub(super) struct Accumulated {
    /// Unnormalized log posterior per hypothesis.
    pub log_posterior: Vec<f64>,
    /// Per hypothesis, the largest distance (s) between a scene's observed start and its own.
    pub worst: Vec<f64>,
    /// Per hypothesis, the scenes whose observed start lies more than the
    /// misfit's distance from its own.
    pub far_scenes: Vec<u16>,
    /// Scenes read.
    pub scenes: usize,
}

/// A posterior with what every estimate from it reads: computed once, when
/// the posterior is, and shared by every estimate that finds it kept.
#[derive(Debug)]
pub(super) struct Posterior {
    pub accumulated: Accumulated,
    /// The posterior weight of each hypothesis, the largest 1: every mass an
    /// estimate reports is a sum of these.
    pub weights: Vec<f64>,
    /// The smallest, over hypotheses, of the largest distance (s) between a
    /// scene's observed start and the hypothesis's.
    pub closest_s: f64,
    /// The fewest, over hypotheses, of the scenes whose observed start lies
    /// far from the hypothesis's.
    pub fewest_far: u16,
}

/// One posterior and what it was computed from.
struct Entry {
    /// The onsets read, in order.
    onsets: Vec<Onset>,
    /// The lane change's duration, when a scene's safety verdicts made it matter.
    duration_bits: Option<u64>,
    posterior: Arc<Posterior>,
}

/// Posteriors kept: two per core, so that every thread of an evaluation (one
/// drive each, as the runner schedules them) finds the one it extends.
fn capacity() -> usize {
    let cores = std::thread::available_parallelism().map_or(2, usize::from);
    2 * cores.clamp(2, 32)
}

fn memo() -> &'static Mutex<Vec<Entry>> {
    static MEMO: OnceLock<Mutex<Vec<Entry>>> = OnceLock::new();
    MEMO.get_or_init(|| Mutex::new(Vec::new()))
}

/// Whether the duration of the lane change matters for `onsets`: when a scene
/// carries the safety layer's verdicts.
fn duration_matters(onsets: &[&Onset]) -> bool {
    (onsets.iter()).any(|o| {
        o.scene
            .as_ref()
            .is_some_and(|s| s.steps.iter().any(|x| x.safe.is_some()))
    })
}

/// The posterior kept for the longest beginning of `onsets` (all with their
/// scene) and a lane change of `duration_s`, with how many onsets it read.
pub(super) fn longest_beginning(
    onsets: &[&Onset],
    duration_s: f64,
) -> Option<(Arc<Posterior>, usize)> {
    let entries = memo().lock().unwrap_or_else(PoisonError::into_inner);
    (entries.iter().rev())
        .filter(|e| e.onsets.len() <= onsets.len())
        .filter(|e| {
            e.duration_bits
                .is_none_or(|bits| bits == duration_s.to_bits())
        })
        .filter(|e| e.onsets.iter().zip(onsets).all(|(a, b)| a == *b))
        .max_by_key(|e| e.onsets.len())
        .map(|e| (Arc::clone(&e.posterior), e.onsets.len()))
}

/// Keeps the posterior of `onsets` (all with their scene) and a lane change of
/// `duration_s`, dropping the least recently kept beyond [`capacity`].
pub(super) fn keep(onsets: &[&Onset], duration_s: f64, posterior: Arc<Posterior>) {
    let entry = Entry {
        onsets: onsets.iter().map(|&o| o.clone()).collect(),
        duration_bits: duration_matters(onsets).then(|| duration_s.to_bits()),
        posterior,
    };
    let mut entries = memo().lock().unwrap_or_else(PoisonError::into_inner);
    entries.retain(|e| e.onsets != entry.onsets || e.duration_bits != entry.duration_bits);
    entries.push(entry);
    let excess = entries.len().saturating_sub(capacity());
    entries.drain(..excess);
}
