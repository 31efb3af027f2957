//! `palc zone ...`: fit the perceived-safe-zone filter on labelled samples and
//! classify points with it.
//!
//! File formats (chosen by the file extension, `.csv` or `.json`):
//! - samples, CSV: a header with the feature set's columns (by default
//!   `ds_p,dl_p,dist_p,ds_a,dl_a,dist_a`, any order) and `y` (1 = not taken
//!   over, 0 = taken over); other columns are ignored.
//!   JSON: `[{"x": [..features..], "y": 0 or 1}, ...]`.
//! - points, CSV: the same feature columns (a `y` column is ignored, so a
//!   samples file can be classified as it is). JSON: `[[..features..], ...]`.
//! - classify output: CSV `class,p_safe` (one row per point, in order), or
//!   JSON `[{"class": 0 or 1, "p_safe": ..}, ...]`; to stdout as CSV without `--out`.
//! - model: JSON written by `ZoneModel`'s serde form (format version, config, statistics).

use std::{
    io::{Cursor, Read, Write},
    path::{Path, PathBuf},
};

use anyhow::{Context, bail};
use clap::{Args, Subcommand, ValueEnum};
use palc_aggregator::{input, output};
use palc_zone_filter::{Discriminant, FeatureSet, Label, Sample, ZoneConfig, ZoneModel};
use serde::Serialize;

use crate::console::{self, warning};
use crate::parse;

/// The perceived safe zone filter (GDA, paper Eqs. 1-8).
#[derive(Debug, Args)]
pub struct ZoneArgs {
    #[command(subcommand)]
    command: ZoneCommand,
}

#[derive(Debug, Subcommand)]
enum ZoneCommand {
    /// Fit a zone model on labelled samples (CSV or JSON) and write it as JSON.
    Fit(FitArgs),
    /// Classify points with a fitted model: class and p(y=1|x) per point.
    Classify(ClassifyArgs),
}

#[derive(Debug, Args)]
struct FitArgs {
    /// Labelled samples: `.csv` with a header naming the feature columns
    /// (ds_p,dl_p,dist_p,ds_a,dl_a,dist_a by default) and `y` (1 = not taken over,
    /// 0 = taken over), or `.json` as `[{"x": [..], "y": 0 or 1}, ..]`.
    #[arg(long)]
    samples: PathBuf,
    /// Where to write the model (JSON).
    #[arg(long)]
    out: PathBuf,
    /// Zone config (TOML, the fields of `ZoneConfig`), e.g. configs/examples/zone.toml.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Overrides the config's discriminant.
    #[arg(long, value_enum)]
    discriminant: Option<DiscriminantArg>,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum DiscriminantArg {
    /// Shared covariance (the paper's GDA).
    Linear,
    /// Per-class covariance.
    Quadratic,
}

#[derive(Debug, Args)]
struct ClassifyArgs {
    /// A model written by `palc zone fit`.
    #[arg(long)]
    model: PathBuf,
    /// Points to classify: `.csv` with the model's feature columns by name (other
    /// columns ignored) or `.json` as `[[..features..], ..]`.
    #[arg(long)]
    points: PathBuf,
    /// Output, `.csv` (`class,p_safe` per point) or `.json`
    /// (`[{"class": .., "p_safe": ..}]`); CSV on stdout when absent.
    #[arg(long)]
    out: Option<PathBuf>,
}

pub fn run(args: ZoneArgs) -> anyhow::Result<()> {
    match args.command {
        ZoneCommand::Fit(args) => fit(&args),
        ZoneCommand::Classify(args) => classify(&args),
    }
}

fn fit(args: &FitArgs) -> anyhow::Result<()> {
    output::check_writable(&args.out)?;
    let mut config = match &args.config {
        Some(path) => {
            let text = input::read_to_string(path)?;
            let config = parse::toml::<ZoneConfig>(&text)
                .with_context(|| format!("in {}", path.display()))?;
            config
                .validate()
                .with_context(|| format!("in {}", path.display()))?;
            config
        }
        None => ZoneConfig::default(),
    };
    if let Some(discriminant) = args.discriminant {
        config.discriminant = match discriminant {
            DiscriminantArg::Linear => Discriminant::Linear,
            DiscriminantArg::Quadratic => Discriminant::Quadratic,
        };
    }
    let config_name = args.config.as_ref().map_or_else(
        || "the default zone config".to_owned(),
        |p| p.display().to_string(),
    );
    let samples = read_samples(&args.samples, config.feature_set)?;
    // The samples were checked as they were read; what is left for `fit` to refuse
    // is the pair of config and samples (e.g. a covariance the ridge cannot repair).
    let model = ZoneModel::fit(config, &samples)
        .with_context(|| format!("fitting {} with {config_name}", args.samples.display()))?;
    let mut bytes = serde_json::to_vec_pretty(&model)?;
    bytes.push(b'\n');
    output::write(&args.out, &bytes)?;
    let (safe, unsafe_) = (
        model.safe_statistics().count,
        model.unsafe_statistics().count,
    );
    if !model.is_informative() {
        warning!(
            "warning: {safe} safe and {unsafe_} unsafe samples; the model has no boundary until both classes have samples"
        );
    }
    Ok(())
}

fn classify(args: &ClassifyArgs) -> anyhow::Result<()> {
    if let Some(path) = &args.out {
        output::check_writable(path)?;
    }
    let model: ZoneModel = parse::json(open(&args.model)?)
        .with_context(|| format!("in model {}", args.model.display()))?;
    let set = model.config().feature_set;
    let rows = read_points(&args.points, set)?;
    let mut p_safe = vec![0.0; rows.len() / set.dimension()];
    model
        .posteriors_safe_into(&rows, &mut p_safe)
        .with_context(|| format!("classifying {}", args.points.display()))?;
    let results: Vec<Classified> = p_safe
        .into_iter()
        .map(|p| Classified {
            class: if p > 0.5 {
                Label::Safe.y()
            } else {
                Label::Unsafe.y()
            },
            p_safe: p,
        })
        .collect();
    let mut bytes = Vec::new();
    match &args.out {
        Some(path) if is_json(path) => {
            serde_json::to_writer_pretty(&mut bytes, &results)?;
            bytes.push(b'\n');
        }
        _ => write_csv(&mut bytes, &results)?,
    }
    match &args.out {
        Some(path) => Ok(output::write(path, &bytes)?),
        None => console::data(&bytes).context("cannot write the classes to stdout"),
    }
}

/// One classified point. `class` follows Eq. (2): 1 when p(y=1|x) > 1/2.
#[derive(Debug, Serialize, PartialEq)]
struct Classified {
    class: u8,
    p_safe: f64,
}

fn is_json(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// The bytes of an input file, at most `input::MAX_INPUT_BYTES`.
fn open(path: &Path) -> anyhow::Result<Cursor<Vec<u8>>> {
    Ok(Cursor::new(input::read(path)?))
}

fn read_samples(path: &Path, set: FeatureSet) -> anyhow::Result<Vec<Sample>> {
    let reader = open(path)?;
    if is_json(path) {
        parse::json(reader).with_context(|| format!("in {}", path.display()))
    } else {
        samples_from_csv(reader, set).with_context(|| format!("in {}", path.display()))
    }
}

fn read_points(path: &Path, set: FeatureSet) -> anyhow::Result<Vec<f64>> {
    let reader = open(path)?;
    if is_json(path) {
        let points: Vec<Vec<f64>> =
            parse::json(reader).with_context(|| format!("in {}", path.display()))?;
        let d = set.dimension();
        if let Some((i, p)) = points.iter().enumerate().find(|(_, p)| p.len() != d) {
            bail!(
                "in {}: point {i} has {} features, the model's feature set {set:?} has {d}",
                path.display(),
                p.len()
            );
        }
        Ok(points.concat())
    } else {
        Ok(csv_rows(reader, set, false)
            .with_context(|| format!("in {}", path.display()))?
            .into_iter()
            .flat_map(|(x, _)| x)
            .collect())
    }
}

pub(crate) fn samples_from_csv(reader: impl Read, set: FeatureSet) -> anyhow::Result<Vec<Sample>> {
    csv_rows(reader, set, true)?
        .into_iter()
        .map(|(x, y)| Ok(Sample::new(x, y.context("missing label")?)))
        .collect()
}

/// Largest number of data rows read from a samples or points CSV.
///
/// A samples file holds the labelled lane changes of one user (a few hundred at
/// most in the paper's set-up) and a points file what is to be classified; ten
/// million rows are far beyond either, and bound the memory of the rows read (about
/// 100 bytes each, 1 GB at the bound) before a typo or a wrong file can exhaust it.
/// A longer file is refused with [`TooManyRows`], read to its end only to count.
pub const MAX_CSV_ROWS: usize = 10_000_000;

/// A CSV with more data rows than a bound ([`MAX_CSV_ROWS`]); the caller names the file.
#[derive(Debug, PartialEq)]
pub struct TooManyRows {
    /// Data rows in the file (the header not counted).
    pub rows: u64,
    /// The bound.
    pub max: usize,
}

impl std::fmt::Display for TooManyRows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} data rows, more than the {} rows (MAX_CSV_ROWS) that are read; split the file",
            self.rows, self.max
        )
    }
}

impl std::error::Error for TooManyRows {}

/// Reads the feature columns of `set` (by name) and, if `with_label`, the `y` column.
pub(crate) fn csv_rows(
    reader: impl Read,
    set: FeatureSet,
    with_label: bool,
) -> anyhow::Result<Vec<(Vec<f64>, Option<Label>)>> {
    csv_rows_at_most(reader, set, with_label, MAX_CSV_ROWS)
}

/// [`csv_rows`] with the bound on the number of rows as a parameter.
fn csv_rows_at_most(
    reader: impl Read,
    set: FeatureSet,
    with_label: bool,
    max_rows: usize,
) -> anyhow::Result<Vec<(Vec<f64>, Option<Label>)>> {
    let mut csv = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(reader);
    let headers = csv
        .headers()
        .context("cannot read the header line")?
        .clone();
    let column = |name: &str| -> anyhow::Result<usize> {
        let mut found = headers.iter().enumerate().filter(|(_, h)| *h == name);
        let (j, _) = found.next().with_context(|| {
            format!(
                "line 1: no column `{name}` in the header; the feature set {set:?} needs {:?}",
                set.names()
            )
        })?;
        if let Some((k, _)) = found.next() {
            bail!(
                "line 1: the column `{name}` appears twice in the header (columns {} and {}); keep one",
                j + 1,
                k + 1
            );
        }
        Ok(j)
    };
    let feature_columns = set
        .names()
        .iter()
        .map(|n| column(n))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let label_column = if with_label { Some(column("y")?) } else { None };
    let mut rows = Vec::new();
    let mut records = csv.records();
    while let Some(record) = records.next() {
        if rows.len() == max_rows {
            // Count the rest without keeping it (or failing on it) for the message.
            let rest = records.count() as u64;
            return Err(TooManyRows {
                rows: max_rows as u64 + 1 + rest,
                max: max_rows,
            }
            .into());
        }
        let record = record.context("cannot read a CSV record")?;
        // csv counts lines from 1, the header being line 1.
        let line = record.position().map_or(0, |p| p.line());
        let field = |j: usize| record.get(j).unwrap_or("");
        let x = feature_columns
            .iter()
            .zip(set.names())
            .map(|(&j, name)| match field(j).parse::<f64>() {
                Ok(x) if x.is_finite() => Ok(x),
                _ => bail!(
                    "line {line}: column `{name}` value `{}` is not a finite number",
                    field(j)
                ),
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let y = match label_column {
            Some(j) => Some(match field(j) {
                "0" => Label::Unsafe,
                "1" => Label::Safe,
                other => bail!("line {line}: column `y` value `{other}` must be 0 or 1"),
            }),
            None => None,
        };
        rows.push((x, y));
    }
    Ok(rows)
}

fn write_csv(writer: impl Write, results: &[Classified]) -> anyhow::Result<()> {
    let mut csv = csv::Writer::from_writer(writer);
    for result in results {
        csv.serialize(result)?;
    }
    csv.flush()?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const EXAMPLE_SAMPLES: &str = include_str!("../../../../configs/examples/zone-samples.csv");
    const EXAMPLE_POINTS: &str = include_str!("../../../../configs/examples/zone-points.csv");
    const EXAMPLE_CONFIG: &str = include_str!("../../../../configs/examples/zone.toml");

    #[test]
    fn a_csv_longer_than_the_bound_is_refused_naming_the_bound_and_the_count() {
        for (example, with_label) in [(EXAMPLE_SAMPLES, true), (EXAMPLE_POINTS, false)] {
            let rows = example
                .lines()
                .skip(1)
                .filter(|l| !l.trim().is_empty())
                .count();
            assert!(rows > 3, "the example has {rows} rows");
            let error =
                csv_rows_at_most(example.as_bytes(), FeatureSet::Paper, with_label, 3).unwrap_err();
            assert_eq!(
                error.downcast_ref::<TooManyRows>(),
                Some(&TooManyRows {
                    rows: rows as u64,
                    max: 3
                })
            );
            let message = error.to_string();
            assert!(
                message.contains(&format!("{rows} data rows")) && message.contains("3 rows"),
                "{message}"
            );
            // At the bound, the file is read.
            let read =
                csv_rows_at_most(example.as_bytes(), FeatureSet::Paper, with_label, rows).unwrap();
            assert_eq!(read.len(), rows);
        }
    }

    #[test]
    fn the_example_files_fit_and_classify() {
        let config: ZoneConfig = toml::from_str(EXAMPLE_CONFIG).unwrap();
        let samples = samples_from_csv(EXAMPLE_SAMPLES.as_bytes(), config.feature_set).unwrap();
        let model = ZoneModel::fit(config, &samples).unwrap();
        assert!(model.is_informative());
        let correct = samples
            .iter()
            .filter(|s| model.classify(&s.x).unwrap() == s.y)
            .count();
        assert!(
            correct * 10 >= samples.len() * 9,
            "{correct} of {}",
            samples.len()
        );
        let rows: Vec<f64> = csv_rows(EXAMPLE_POINTS.as_bytes(), config.feature_set, false)
            .unwrap()
            .into_iter()
            .flat_map(|(x, _)| x)
            .collect();
        let mut p = vec![0.0; rows.len() / 6];
        model.posteriors_safe_into(&rows, &mut p).unwrap();
        assert!(p.iter().all(|p| (0.0..=1.0).contains(p)));
        assert!(p.iter().any(|&p| p > 0.5) && p.iter().any(|&p| p < 0.5));
    }

    #[test]
    fn a_bad_label_names_its_line() {
        let text = "ds_p,dl_p,dist_p,ds_a,dl_a,dist_a,y\n1,2,3,4,5,6,1\n1,2,3,4,5,6,2\n";
        let err = samples_from_csv(text.as_bytes(), FeatureSet::Paper).unwrap_err();
        assert!(err.to_string().contains("line 3"), "{err}");
    }

    #[test]
    fn a_missing_column_is_named() {
        let text = "ds_p,dl_p,ds_a,dl_a,y\n1,2,3,4,1\n";
        let err = samples_from_csv(text.as_bytes(), FeatureSet::Paper).unwrap_err();
        assert!(err.to_string().contains("`dist_p`"), "{err}");
    }
}
