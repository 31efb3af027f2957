//! An evaluation split over machines: `palc eval --shard i/n` runs a
//! deterministic part of the plan and writes its rows to `shard.json`;
//! `palc eval merge` reads the parts of all `n` shards, checks that they are the
//! parts of one evaluation, and writes the results as if one machine had run it.
//!
//! **Which runs a shard makes.** The runs linked by experience (a transfer or
//! accumulation run and the run it starts from, transitively) form groups that
//! stay on one shard, so no shard needs another's experience. The groups, in order
//! of their first run, go one at a time to the shard with the fewest runs so far
//! (the lowest index on a tie): every shard computes the same assignment from the
//! plan alone, and the shards' sizes differ by at most one group.
//!
//! **What a merge checks.** Every shard file is of this format, this palc version,
//! the same config texts (SHA-256), the same `--quick` and the same number of
//! shards and runs; each shard index appears once and all `n` are there; every row
//! is the plan's run at its index, and every run of the plan is there exactly
//! once. A mismatch is an error naming the file and what differs.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::EvalError;
use crate::plan::{RunPlan, RunSpec};
use crate::results::{RunRow, Status};
use crate::runner::Executor;

/// The shard file's format; a merge refuses other versions.
pub const SHARD_FORMAT_VERSION: u32 = 1;

/// The file a shard writes into its output directory.
pub const SHARD_FILE: &str = "shard.json";

/// Part `index` of `count` (`index` from 0, as Slurm's `SLURM_ARRAY_TASK_ID` and
/// Kubernetes' `JOB_COMPLETION_INDEX` count).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard, `0..count`.
    pub index: usize,
    /// How many shards the evaluation is split into.
    pub count: usize,
}

/// The most shards an evaluation may be split into.
pub const MAX_SHARDS: usize = 100_000;

impl std::str::FromStr for Shard {
    type Err = EvalError;

    /// `i/n`, `0 <= i < n <= MAX_SHARDS`.
    fn from_str(text: &str) -> Result<Shard, EvalError> {
        let invalid = || EvalError::InvalidOption {
            option: "--shard",
            value: format!("{text:?}"),
            bound: format!("i/n with 0 <= i < n <= {MAX_SHARDS} (e.g. 0/4)"),
        };
        let (index, count) = text.split_once('/').ok_or_else(invalid)?;
        let index: usize = index.trim().parse().map_err(|_| invalid())?;
        let count: usize = count.trim().parse().map_err(|_| invalid())?;
        if count == 0 || count > MAX_SHARDS || index >= count {
            return Err(invalid());
        }
        Ok(Shard { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// Which shard each run of `plan` belongs to, by run index.
pub fn assignment(plan: &RunPlan, count: usize) -> Vec<usize> {
    let runs: Vec<&RunSpec> = plan.all().collect();
    // The group of a run is the group of the run it starts from (which comes
    // earlier in the plan), else its own.
    let mut group: Vec<usize> = (0..runs.len()).collect();
    for (i, spec) in runs.iter().enumerate() {
        if let Some(source) = spec.experience_from.filter(|&s| s < i) {
            group[i] = group[source];
        }
    }
    let mut sizes = vec![0usize; runs.len()];
    for &g in &group {
        sizes[g] += 1;
    }
    let mut shard_of_group = vec![usize::MAX; runs.len()];
    let mut load = vec![0usize; count.max(1)];
    for g in 0..runs.len() {
        if sizes[g] == 0 {
            continue;
        }
        let lightest = (0..load.len()).min_by_key(|&s| (load[s], s)).unwrap_or(0);
        shard_of_group[g] = lightest;
        load[lightest] += sizes[g];
    }
    group.iter().map(|&g| shard_of_group[g]).collect()
}

/// An executor that makes only the runs of one shard; the others end at once
/// with a placeholder row that is never written.
pub struct ShardExecutor<'a, E> {
    inner: &'a E,
    member: Vec<bool>,
}

impl<'a, E: Executor> ShardExecutor<'a, E> {
    /// The runs of `shard` in `plan`, made by `inner`.
    pub fn new(inner: &'a E, plan: &RunPlan, shard: Shard) -> Self {
        let member = (assignment(plan, shard.count).into_iter())
            .map(|s| s == shard.index)
            .collect();
        ShardExecutor { inner, member }
    }

    /// Whether run `id` is this shard's.
    pub fn is_member(&self, id: usize) -> bool {
        self.member.get(id).copied().unwrap_or(false)
    }
}

impl<E: Executor> Executor for ShardExecutor<'_, E> {
    type Experience = E::Experience;

    fn run(
        &self,
        spec: &RunSpec,
        experience: Option<&E::Experience>,
    ) -> (RunRow, Option<E::Experience>) {
        if self.is_member(spec.id) {
            return self.inner.run(spec, experience);
        }
        let status = Status::Failed {
            error: "another shard's run".to_owned(),
        };
        let row = RunRow::without_result(spec.clone(), status, self.inner.cap(), 0.0);
        (row, None)
    }

    fn cap(&self) -> usize {
        self.inner.cap()
    }
}

/// What a shard writes: its rows and what a merge checks them against.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardFile {
    /// [`SHARD_FORMAT_VERSION`].
    pub format_version: u32,
    /// palc's version.
    pub palc_version: String,
    /// SHA-256 of the evaluation config and its base config.
    pub config_sha256: String,
    /// Whether the `--quick` subset was run.
    pub quick: bool,
    /// Which shard.
    pub shard: Shard,
    /// Runs in the whole plan.
    pub plan_runs: usize,
    /// Worker threads of this shard.
    pub threads: usize,
    /// Wall time of this shard's runs (s).
    pub wall_s: f64,
    /// This shard's rows, in plan order.
    pub rows: Vec<RunRow>,
}

/// What the evaluation being merged is: the fields every shard must share.
#[derive(Debug, Clone, PartialEq)]
pub struct Expected<'a> {
    /// palc's version.
    pub palc_version: &'a str,
    /// SHA-256 of the configs.
    pub config_sha256: &'a str,
    /// Whether the `--quick` subset.
    pub quick: bool,
}

/// The rows of the shards in `dirs`, in plan order, and the shards' summed wall
/// time and largest thread count, after every check of the module's overview.
///
/// # Errors
/// [`EvalError::Shard`] naming the file and the mismatch, or the missing and
/// duplicated runs or shards; [`EvalError::Io`] for a file that cannot be read.
pub fn merge_rows(
    dirs: &[PathBuf],
    plan: &RunPlan,
    expected: &Expected<'_>,
) -> Result<(Vec<RunRow>, f64, usize), EvalError> {
    if dirs.is_empty() {
        return Err(shard_error(Path::new("."), "no shard directory given"));
    }
    let specs: Vec<&RunSpec> = plan.all().collect();
    let mut rows: Vec<Option<RunRow>> = vec![None; specs.len()];
    let mut seen: Vec<Option<PathBuf>> = Vec::new();
    let (mut wall_s, mut threads) = (0.0, 1);
    for dir in dirs {
        let path = dir.join(SHARD_FILE);
        let file = read(&path)?;
        check(&file, &path, expected, specs.len())?;
        if seen.is_empty() {
            seen = vec![None; file.shard.count];
        } else if seen.len() != file.shard.count {
            return Err(shard_error(
                &path,
                format!(
                    "it is one of {} shards, another given one of {}",
                    file.shard.count,
                    seen.len()
                ),
            ));
        }
        if let Some(first) = &seen[file.shard.index] {
            return Err(shard_error(
                &path,
                format!(
                    "shard {} is given twice (also {})",
                    file.shard,
                    first.display()
                ),
            ));
        }
        seen[file.shard.index] = Some(path.clone());
        wall_s += file.wall_s;
        threads = threads.max(file.threads);
        for row in file.rows {
            let id = row.spec.id;
            let Some(spec) = specs.get(id) else {
                return Err(shard_error(&path, format!("run {id} is not in the plan")));
            };
            if &row.spec != *spec {
                return Err(shard_error(
                    &path,
                    format!("run {id} is not the plan's run {id} (`{}`)", spec.label()),
                ));
            }
            if rows[id].is_some() {
                return Err(shard_error(&path, format!("run {id} is in two shards")));
            }
            rows[id] = Some(row);
        }
    }
    let missing_shards: Vec<String> = (seen.iter().enumerate())
        .filter(|(_, path)| path.is_none())
        .map(|(i, _)| format!("{i}/{}", seen.len()))
        .collect();
    if !missing_shards.is_empty() {
        return Err(shard_error(
            &dirs[0],
            format!("shards missing: {}", missing_shards.join(", ")),
        ));
    }
    let missing: Vec<usize> = (rows.iter().enumerate())
        .filter(|(_, row)| row.is_none())
        .map(|(i, _)| i)
        .collect();
    if let Some(first) = missing.first() {
        return Err(shard_error(
            &dirs[0],
            format!(
                "{} runs are in no shard (the first: run {first})",
                missing.len()
            ),
        ));
    }
    Ok((rows.into_iter().flatten().collect(), wall_s, threads))
}

/// The most bytes read from one shard's file (2 GiB). A shard holds its runs
/// with every lane change, about 9 kB a run: a quarter of the full reproduction
/// (11,400 runs) is 100 MB, past the 64 MiB every other input is held to
/// (`palc_aggregator::input::MAX_INPUT_BYTES`). 2 GiB is about 230,000 runs a
/// shard, which the merge still holds in memory.
pub const MAX_SHARD_BYTES: u64 = 2 * 1024 * 1024 * 1024;

fn read(path: &Path) -> Result<ShardFile, EvalError> {
    let bytes =
        palc_aggregator::input::read_bounded(path, MAX_SHARD_BYTES).map_err(|e| EvalError::Io {
            action: "read",
            path: path.to_owned(),
            source: e.into_io(),
        })?;
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
    serde_json::from_slice(bytes).map_err(|e| shard_error(path, format!("not a shard file: {e}")))
}

/// The fields every shard shares with the evaluation being merged.
fn check(
    file: &ShardFile,
    path: &Path,
    expected: &Expected<'_>,
    plan_runs: usize,
) -> Result<(), EvalError> {
    let differs = |what: &str, found: &dyn std::fmt::Display, wanted: &dyn std::fmt::Display| {
        shard_error(
            path,
            format!("its {what} is {found}, the evaluation being merged has {wanted}"),
        )
    };
    if file.format_version != SHARD_FORMAT_VERSION {
        return Err(differs(
            "format version",
            &file.format_version,
            &SHARD_FORMAT_VERSION,
        ));
    }
    if file.palc_version != expected.palc_version {
        return Err(differs(
            "palc version",
            &file.palc_version,
            &expected.palc_version,
        ));
    }
    if file.config_sha256 != expected.config_sha256 {
        return Err(differs(
            "config SHA-256",
            &file.config_sha256,
            &expected.config_sha256,
        ));
    }
    if file.quick != expected.quick {
        let name = |quick: bool| {
            if quick {
                "--quick"
            } else {
                "the full evaluation"
            }
        };
        return Err(differs(
            "selection",
            &name(file.quick),
            &name(expected.quick),
        ));
    }
    if file.plan_runs != plan_runs {
        return Err(differs("number of runs", &file.plan_runs, &plan_runs));
    }
    if file.shard.count == 0 || file.shard.index >= file.shard.count {
        return Err(shard_error(
            path,
            format!("shard {} does not exist", file.shard),
        ));
    }
    Ok(())
}

fn shard_error(path: &Path, reason: impl Into<String>) -> EvalError {
    EvalError::Shard {
        path: path.to_owned(),
        reason: reason.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan;

    fn plan() -> RunPlan {
        let mut selection = plan::tests::selection();
        selection.grid.speed_cases = plan::tests::testbed().speed_cases.to_vec();
        selection.transfer.accumulation_users = vec!["deterministic".into()];
        plan::expand(&selection, &plan::tests::testbed()).unwrap()
    }

    #[test]
    fn shard_names_parse_and_bad_ones_name_the_bound() {
        assert_eq!(
            "2/4".parse::<Shard>().unwrap(),
            Shard { index: 2, count: 4 }
        );
        for bad in ["4/4", "0/0", "x/2", "1", "-1/2", "1/100001"] {
            let error = bad.parse::<Shard>().unwrap_err().to_string();
            assert!(
                error.contains("--shard") && error.contains("0 <= i < n"),
                "{error}"
            );
        }
    }

    #[test]
    fn every_run_is_on_one_shard_with_the_runs_it_learns_from_and_shards_are_balanced() {
        let plan = plan();
        let runs: Vec<&RunSpec> = plan.all().collect();
        assert!(runs.iter().any(|s| s.experience_from.is_some()));
        for count in [1, 2, 3, 4, 7] {
            let shards = assignment(&plan, count);
            assert_eq!(shards.len(), runs.len());
            assert!(shards.iter().all(|&s| s < count));
            for (i, spec) in runs.iter().enumerate() {
                if let Some(source) = spec.experience_from {
                    assert_eq!(shards[i], shards[source], "run {i} and its source {source}");
                }
            }
            let sizes: Vec<usize> = (0..count)
                .map(|s| shards.iter().filter(|&&x| x == s).count())
                .collect();
            // The largest group: a run and every run that learns from it, transitively.
            let mut root: Vec<usize> = (0..runs.len()).collect();
            for (i, spec) in runs.iter().enumerate() {
                if let Some(source) = spec.experience_from {
                    root[i] = root[source];
                }
            }
            let largest_group = (0..runs.len())
                .map(|g| root.iter().filter(|&&r| r == g).count())
                .max()
                .unwrap();
            assert!(
                sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= largest_group,
                "{count} shards: {sizes:?}"
            );
        }
    }
}
