//! `palc learn`: runs the lesson-learning loop and shows each lane change.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use palc_aggregator::{Experience, output};
use palc_harness::advanced::GapAcceptanceSet;
use palc_harness::driver::DriverEstimate;
use palc_harness::{
    CellChoice, LaneChangeRecord, LearnConfig, LessonEvent, Method, Observer, RunSummary,
    UserConfig, config::UserStyle, run,
};

use crate::console::say;

/// The default config, compiled in so that `palc learn` alone works anywhere.
const DEFAULT_CONFIG: &str = include_str!("../../../../configs/learn.toml");

impl ScenarioArgs {
    /// Where the run's user comes from, for an error found while it runs: the
    /// `--user` file, else the config.
    pub(crate) fn whose_user(&self) -> String {
        match (&self.user, &self.config) {
            (Some(user), _) => format!("with the user of {}", user.display()),
            (None, Some(config)) => format!("with the config {}", config.display()),
            (None, None) => "with the built-in config (configs/learn.toml)".to_owned(),
        }
    }
}

/// The scenario and user of a run: a config and what the command line overrides.
#[derive(Debug, Args)]
pub struct ScenarioArgs {
    /// Run config (TOML); the paper's test bed and the `palc` method by default.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Learning method: `paper` or `palc`.
    #[arg(long)]
    method: Option<String>,
    /// A TOML file holding a `[user]` table (style, `[user.family]`, `[user.spread]`)
    /// that replaces the config's.
    #[arg(long)]
    user: Option<PathBuf>,
    /// Driving style: `aggressive`, `neutral`, `cautious`, or `custom` for the
    /// config's `[user.custom]` table.
    #[arg(long)]
    style: Option<UserStyle>,
    /// Speed case by name, e.g. `collector-high`.
    #[arg(long)]
    speed: Option<String>,
    /// Front-to-front headway on the target lane (m).
    #[arg(long)]
    headway: Option<f64>,
    /// Seed of the scene.
    #[arg(long)]
    seed: Option<u64>,
}

/// Arguments of `palc learn`.
#[derive(Debug, Args)]
pub struct LearnArgs {
    #[command(flatten)]
    scenario: ScenarioArgs,
    /// Start from experience saved in another run.
    #[arg(long)]
    experience: Option<PathBuf>,
    /// Save what was learned.
    #[arg(long)]
    save_experience: Option<PathBuf>,
    /// Write every lane change (trajectories, timings) as JSON.
    #[arg(long)]
    record: Option<PathBuf>,
}

/// Reads a file for a command, naming it in the error.
fn read(path: &Path) -> anyhow::Result<String> {
    Ok(palc_aggregator::input::read_to_string(path)?)
}

/// The learning config of `args`: the config file (or the built-in one) with the
/// user file, method, style and cell of the command line.
pub fn load_config(args: &ScenarioArgs) -> anyhow::Result<LearnConfig> {
    let (text, source) = match &args.config {
        Some(path) => (read(path)?, path.display().to_string()),
        None => (
            DEFAULT_CONFIG.to_owned(),
            "the built-in configs/learn.toml".to_owned(),
        ),
    };
    let mut config = LearnConfig::from_toml_str(&text).with_context(|| format!("in {source}"))?;
    if let Some(name) = &args.method {
        let method = Method::named(name)
            .with_context(|| format!("unknown method `{name}`: expected `paper` or `palc`"))?;
        config = config.with_method(method);
    }
    if let Some(path) = &args.user {
        let user = UserConfig::from_toml_str(&read(path)?, config.planning.takeover_threshold_m)
            .with_context(|| format!("in {}", path.display()))?;
        config = config.with_user(user);
    }
    if let Some(style) = args.style {
        let user = UserConfig {
            style,
            ..config.user.clone()
        };
        config = config.with_user(user);
    }
    let cell = CellChoice {
        speed_case: args
            .speed
            .clone()
            .unwrap_or_else(|| config.cell.speed_case.clone()),
        headway_m: args.headway.unwrap_or(config.cell.headway_m),
        seed: args.seed.unwrap_or(config.cell.seed),
    };
    let config = config.with_cell(cell);
    config.validate().with_context(|| format!("in {source}"))?;
    Ok(config)
}

/// Prints one line per lane change as it happens.
struct Printer;

impl Observer for Printer {
    fn lane_change(&mut self, record: &LaneChangeRecord) {
        match record.takeover {
            Some(t) => say!(
                "lane change {:>2}: takeover at {:5.1} s ({:6.1} m), deviation {:.2} m, perceived safety {:.2}",
                record.index + 1,
                t.time_s,
                t.distance_m,
                t.deviation_m,
                record.perceived_safety_ratio
            ),
            None => say!(
                "lane change {:>2}: no takeover, max deviation {:.2} m",
                record.index + 1,
                record.max_deviation_m
            ),
        }
    }

    fn lesson(&mut self, event: &LessonEvent<'_>) {
        if let LessonEvent::Failed { error, .. } = event {
            say!("               learning step failed, experience unchanged: {error}");
        }
        if let Some(estimate) = event.driver_estimate() {
            say!(
                "               the driver, as palc believes: {}",
                estimate.describe()
            );
        }
        if let Some(set) = event.gap_acceptance() {
            say!(
                "               the starts allow a driver who {}",
                set.describe()
            );
        }
    }

    fn finished(&mut self, summary: &RunSummary) {
        say!(
            "{:?} after {} takeovers in {} lane changes (final max deviation {:.2} m)",
            summary.outcome,
            summary.counted_takeovers(),
            summary.lane_changes,
            summary.final_max_deviation_m
        );
        if summary.learning_failures > 0 {
            say!(
                "{} of the lessons could not be learned from",
                summary.learning_failures
            );
        }
        if let Some(frozen) = summary.frozen {
            say!(
                "after learning, frozen: {} of {} lane changes taken over ({:.0} %), the nominal plan {} ({:.0} %)",
                frozen.takeovers,
                frozen.lane_changes,
                100.0 * frozen.takeover_rate(),
                frozen.ceiling_takeovers,
                100.0 * frozen.ceiling_rate()
            );
        }
    }
}

/// Runs `palc learn`.
pub fn run_learn(args: LearnArgs) -> anyhow::Result<()> {
    for path in [&args.save_experience, &args.record].into_iter().flatten() {
        output::check_writable(path)?;
    }
    let config = load_config(&args.scenario)?;
    let experience = match &args.experience {
        Some(path) => Some(
            Experience::load(path).with_context(|| format!("cannot load {}", path.display()))?,
        ),
        None => None,
    };
    say!("{} ({} method)", config.label(), config.method.name());
    let result = run(&config, experience.as_ref(), &mut Printer)
        .with_context(|| args.scenario.whose_user())?;
    let duration_s = config.planning.standard_alc.lane_change_duration_s;
    if let Some(estimate) = DriverEstimate::from_onsets(&result.experience.onsets, duration_s) {
        say!(
            "after the run, the driver as palc believes: {}",
            estimate.describe()
        );
    }
    if let Some(set) = GapAcceptanceSet::from_onsets(&result.experience.onsets) {
        say!(
            "after the run, the starts allow a driver who {}",
            set.describe()
        );
    }
    if let Some(path) = &args.save_experience {
        result
            .experience
            .save(path)
            .with_context(|| format!("cannot save {}", path.display()))?;
    }
    if let Some(path) = &args.record {
        let mut json = serde_json::to_vec_pretty(&result)?;
        json.push(b'\n');
        output::write(path, &json)?;
    }
    Ok(())
}
