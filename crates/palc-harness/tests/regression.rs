//! One test per fixed bug, named after it.

use palc_aggregator::{AggregatorError, AggregatorOptions};
use palc_harness::{LearnConfig, LessonEvent, Method, Observer, StylePreset, UserConfig, run};
use palc_zone_filter::{FeatureSet, ZoneConfig};

/// The zone's sample counts after each lesson, and the failures.
#[derive(Default)]
struct ZoneGrowth {
    samples: Vec<u64>,
    failures: Vec<String>,
    zone_failures: usize,
}

impl Observer for ZoneGrowth {
    fn lesson(&mut self, event: &LessonEvent<'_>) {
        match event {
            LessonEvent::Learned { outcome, .. } => {
                let zone = outcome.experience.zone.as_ref();
                self.samples.push(zone.map_or(0, |z| {
                    z.safe_statistics().count + z.unsafe_statistics().count
                }));
            }
            LessonEvent::Failed { error, .. } => {
                self.failures.push(error.to_string());
                if matches!(error, AggregatorError::Zone(_)) {
                    self.zone_failures += 1;
                }
            }
        }
    }
}

/// The default scenario with a neutral user, `method` and its options with the zone
/// on in `feature_set`.
fn with_zone(method: Method, options: AggregatorOptions, feature_set: FeatureSet) -> LearnConfig {
    let text = include_str!("../../../configs/learn.toml");
    let mut config = (LearnConfig::from_toml_str(text).unwrap())
        .with_method(method)
        .with_user(UserConfig::preset(StylePreset::Neutral));
    config.aggregator = Some(AggregatorOptions {
        use_zone: true,
        zone: ZoneConfig {
            feature_set,
            ..ZoneConfig::default()
        },
        ..options
    });
    config
}

/// Lesson samples were built with the default (paper) feature set while the zone
/// used its own, so a zone of another set refused every update ("expected 4
/// features, got 6") and never learned; the failures showed only as a record field.
#[test]
fn the_zone_learns_with_a_non_default_feature_set() {
    for feature_set in [FeatureSet::NoDistance, FeatureSet::TimeGap] {
        let config = with_zone(Method::Palc, AggregatorOptions::default(), feature_set);
        let mut growth = ZoneGrowth::default();
        let result = run(&config, None, &mut growth).unwrap();
        assert!(result.summary.takeovers > 0, "{feature_set:?}: no lesson");
        assert!(
            growth.failures.is_empty(),
            "{feature_set:?}: {:?}",
            growth.failures
        );
        assert_eq!(result.summary.learning_failures, 0, "{feature_set:?}");
        // Every lesson adds samples to the zone.
        assert_eq!(
            growth.samples.len(),
            result.summary.takeovers.min(29),
            "{feature_set:?}"
        );
        assert!(growth.samples[0] > 0, "{feature_set:?}");
        assert!(
            growth.samples.windows(2).all(|w| w[1] > w[0]),
            "{feature_set:?}: {:?}",
            growth.samples
        );
        let zone = result.experience.zone.as_ref().expect("a zone was learned");
        assert_eq!(zone.config().feature_set, feature_set);
        assert_eq!(zone.dimension(), feature_set.dimension());
    }
}

/// The paper's method with another feature set: its zone accepts every lesson's
/// samples; what fails, fails in the zone-centre expert, as with the paper's set.
#[test]
fn the_paper_method_zone_accepts_samples_of_any_feature_set() {
    for feature_set in [
        FeatureSet::Paper,
        FeatureSet::NoDistance,
        FeatureSet::TimeGap,
    ] {
        let config = with_zone(Method::Paper, AggregatorOptions::paper(), feature_set);
        let mut growth = ZoneGrowth::default();
        let result = run(&config, None, &mut growth).unwrap();
        assert!(result.summary.takeovers > 0, "{feature_set:?}: no lesson");
        assert_eq!(
            growth.zone_failures, 0,
            "{feature_set:?}: {:?}",
            growth.failures
        );
        assert_eq!(growth.failures.len(), result.summary.learning_failures);
    }
}
