//! The ablation ladder (`[ablation]`): from `paper` to `palc`, one change at a time.
//!
//! The printed method personalizes nobody; `palc` personalizes every user of the
//! grid. The ladder shows which change does what: each rung is the rung before it
//! with one change (the label rule, or some of the aggregator's options), and
//! each rung runs every grid cell of its users from scratch and again with the
//! experience of the same cell's other scene (`[transfer] source`), so that the
//! report gives each change's effect on learning and on transfer.
//!
//! ```toml
//! [ablation]
//! users = ["deterministic"]
//!
//! [[ablation.rungs]]
//! name = "paper"
//! change = "the printed method"
//! method = "paper"              # the first rung starts from a method
//!
//! [[ablation.rungs]]
//! name = "palc labels"
//! change = "accepted and driven positions safe, rejected ones unsafe"
//! method = "palc"               # a later rung's method changes the label rule only
//!
//! [[ablation.rungs]]
//! name = "lesson expert"
//! change = "the expert re-plans the executed lane change"
//! aggregator = { expert = { kind = "lesson" } }   # replaces whole options
//! ```
//!
//! Each key of a rung's `aggregator` table replaces that option
//! (`palc_aggregator::AggregatorOptions`) of the rung before it as a whole; the
//! base config's own `[aggregator]` table does not apply to ablation runs.

use palc_aggregator::AggregatorOptions;
use palc_harness::Method;
use serde::{Deserialize, Serialize};

use crate::EvalError;

/// The `[ablation]` table.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AblationConfig {
    /// User kinds the ladder runs for; none by default (no ablation runs).
    #[serde(default)]
    pub users: Vec<String>,
    /// The rungs, in order, each one change from the rung before it.
    #[serde(default)]
    pub rungs: Vec<RungConfig>,
}

/// One rung as written in the config.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RungConfig {
    /// Name in runs and reports; unique in the ladder.
    pub name: String,
    /// The change from the rung before, in words, for the report.
    pub change: String,
    /// On the first rung, the method it starts from (label rule and options);
    /// on a later one, the label rule when it changes.
    #[serde(default)]
    pub method: Option<Method>,
    /// Aggregator options replaced, each key a field of
    /// `palc_aggregator::AggregatorOptions`.
    #[serde(default)]
    pub aggregator: toml::Table,
}

/// A rung with everything it runs with.
#[derive(Debug, Clone, PartialEq)]
pub struct Rung {
    /// Name.
    pub name: String,
    /// The change from the rung before.
    pub change: String,
    /// Whose label rule the lessons are labelled by.
    pub labels: Method,
    /// The aggregator's options.
    pub options: AggregatorOptions,
}

impl Rung {
    /// Whether this rung runs exactly a method's set-up: its label rule and
    /// that method's own options.
    pub fn is_method(&self, method: Method) -> bool {
        self.labels == method && self.options == method.aggregator_options()
    }
}

/// Longest name or change text (characters).
const MAX_TEXT: usize = 200;

impl AblationConfig {
    /// The rungs with their label rule and full options, each checked; an error
    /// names the rung's field.
    pub fn resolve(&self) -> Result<Vec<Rung>, EvalError> {
        let mut rungs: Vec<Rung> = Vec::with_capacity(self.rungs.len());
        for (i, rung) in self.rungs.iter().enumerate() {
            let field = |name: &str| format!("ablation.rungs[{i}].{name}");
            for (name, text) in [("name", &rung.name), ("change", &rung.change)] {
                if text.trim().is_empty() || text.chars().count() > MAX_TEXT {
                    return Err(EvalError::invalid(
                        field(name),
                        format_args!("{text:?}"),
                        format!("a non-empty text of at most {MAX_TEXT} characters"),
                    ));
                }
            }
            if rungs.iter().any(|r| r.name == rung.name) {
                return Err(EvalError::invalid(
                    field("name"),
                    format_args!("`{}`", rung.name),
                    "a name not used by an earlier rung",
                ));
            }
            let (labels, options) = match (rungs.last(), rung.method) {
                (None, None) => {
                    return Err(EvalError::invalid(
                        field("method"),
                        "missing",
                        "the method the first rung starts from (`paper` or `palc`)",
                    ));
                }
                (None, Some(method)) => (method, method.aggregator_options()),
                (Some(before), method) => (method.unwrap_or(before.labels), before.options.clone()),
            };
            let options = replaced(&options, &rung.aggregator)
                .map_err(|reason| EvalError::invalid(field("aggregator"), reason, BOUND))?;
            options.validate().map_err(|source| {
                EvalError::invalid(field("aggregator"), source, "a valid combination")
            })?;
            rungs.push(Rung {
                name: rung.name.clone(),
                change: rung.change.clone(),
                labels,
                options,
            });
        }
        Ok(rungs)
    }
}

const BOUND: &str = "fields of palc_aggregator::AggregatorOptions, each a whole option";

/// `options` with each key of `changes` replacing that option.
fn replaced(
    options: &AggregatorOptions,
    changes: &toml::Table,
) -> Result<AggregatorOptions, String> {
    let mut table = toml::Table::try_from(options).map_err(|e| e.to_string())?;
    for (key, value) in changes {
        if !table.contains_key(key) {
            return Err(format!("unknown option `{key}`"));
        }
        table.insert(key.clone(), value.clone());
    }
    AggregatorOptions::deserialize(toml::Value::Table(table)).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use palc_aggregator::{CorrectionRule, ExpertKind, Representation};

    fn ladder(text: &str) -> Result<Vec<Rung>, EvalError> {
        let config: AblationConfig = toml::from_str(text).unwrap();
        config.resolve()
    }

    #[test]
    fn each_rung_changes_the_one_before_and_a_full_ladder_ends_at_palc() {
        let rungs = ladder(
            r#"
            users = ["deterministic"]
            [[rungs]]
            name = "paper"
            change = "the printed method"
            method = "paper"
            [[rungs]]
            name = "labels"
            change = "palc's label rule"
            method = "palc"
            [[rungs]]
            name = "expert"
            change = "lesson expert"
            aggregator = { expert = { kind = "lesson" } }
            [[rungs]]
            name = "rest"
            change = "the rest of palc"
            aggregator = { learnable_rows = ["w1", "w2"], correction = { rule = "target" }, use_zone = false, representation = "relative-onset", average_lessons = true, follow_user_speed = true }
            "#,
        )
        .unwrap();
        assert!(rungs[0].is_method(Method::Paper));
        assert_eq!(rungs[1].labels, Method::Palc);
        assert_eq!(rungs[1].options, AggregatorOptions::paper());
        assert!(matches!(rungs[2].options.expert, ExpertKind::Lesson(_)));
        assert!(matches!(
            rungs[2].options.correction,
            CorrectionRule::Apprenticeship(_)
        ));
        assert_eq!(rungs[2].options.representation, Representation::TimeIndexed);
        assert!(rungs[3].is_method(Method::Palc), "{:?}", rungs[3]);
    }

    #[test]
    fn a_bad_rung_is_named_with_its_field() {
        let cases = [
            (
                "[[rungs]]\nname = \"a\"\nchange = \"b\"\n",
                "ablation.rungs[0].method",
            ),
            (
                "[[rungs]]\nname = \"a\"\nchange = \"b\"\nmethod = \"paper\"\naggregator = { expert = { kind = \"oracle\" } }\n",
                "ablation.rungs[0].aggregator",
            ),
            (
                "[[rungs]]\nname = \"a\"\nchange = \"b\"\nmethod = \"paper\"\naggregator = { zone_size = 3 }\n",
                "zone_size",
            ),
            (
                "[[rungs]]\nname = \"a\"\nchange = \"b\"\nmethod = \"palc\"\naggregator = { expert = { kind = \"zone_centre\" } }\n",
                "use_zone",
            ),
            (
                "[[rungs]]\nname = \"a\"\nchange = \"b\"\nmethod = \"palc\"\n[[rungs]]\nname = \"a\"\nchange = \"c\"\n",
                "ablation.rungs[1].name",
            ),
            (
                "[[rungs]]\nname = \" \"\nchange = \"b\"\nmethod = \"palc\"\n",
                "ablation.rungs[0].name",
            ),
        ];
        for (text, expected) in cases {
            let error = ladder(text).unwrap_err().to_string();
            assert!(error.contains(expected), "{text}: {error}");
        }
    }
}
