//! The parsers of the inputs that the command line reads itself (zone config, zone
//! model, plan problem, JSON samples and points): every error names the dotted path
//! of the field it is in (e.g. `initial.speed_mps`, `config.ridge`) besides the line
//! and column that `toml` and `serde_json` report.

use std::fmt;
use std::io::Read;

use serde::de::DeserializeOwned;
use serde_path_to_error::{Path, Segment};

/// A parse error with the path of the field it is in; empty for a syntax error or a
/// truncated text, which are in no field.
#[derive(Debug)]
pub struct ParseError {
    /// Dotted path of the field (`a.b[2].c`), or empty.
    pub path: String,
    /// What `toml` or `serde_json` said, with the line and column.
    pub source: Box<dyn std::error::Error + Send + Sync + 'static>,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if !self.path.is_empty() {
            write!(f, "`{}`: ", self.path)?;
        }
        write!(f, "{}", self.source)
    }
}

impl std::error::Error for ParseError {}

fn error<E>(path: &Path, source: E) -> ParseError
where
    E: std::error::Error + Send + Sync + 'static,
{
    let known = path
        .iter()
        .any(|segment| !matches!(segment, Segment::Unknown));
    ParseError {
        path: if known {
            path.to_string()
        } else {
            String::new()
        },
        source: Box::new(source),
    }
}

/// The UTF-8 byte-order mark some editors write at the start of a file.
const BYTE_ORDER_MARK: &[u8] = b"\xEF\xBB\xBF";

/// Parses a TOML document.
pub fn toml<T: DeserializeOwned>(text: &str) -> Result<T, ParseError> {
    let deserializer = toml::de::Deserializer::parse(text).map_err(|source| ParseError {
        path: String::new(),
        source: Box::new(source),
    })?;
    serde_path_to_error::deserialize(deserializer)
        .map_err(|e| error(&e.path().clone(), e.into_inner()))
}

/// Parses one JSON value; anything but whitespace after it is an error. A UTF-8
/// byte-order mark at the start is skipped, as the TOML and CSV readers do.
pub fn json<T: DeserializeOwned>(reader: impl Read) -> Result<T, ParseError> {
    let mut reader = std::io::BufReader::new(reader);
    if let Ok(start) = std::io::BufRead::fill_buf(&mut reader) {
        if start.starts_with(BYTE_ORDER_MARK) {
            std::io::BufRead::consume(&mut reader, BYTE_ORDER_MARK.len());
        }
    }
    let mut deserializer = serde_json::Deserializer::from_reader(reader);
    let value = serde_path_to_error::deserialize(&mut deserializer)
        .map_err(|e| error(&e.path().clone(), e.into_inner()))?;
    deserializer.end().map_err(|source| ParseError {
        path: String::new(),
        source: Box::new(source),
    })?;
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::commands::plan::PlanInput;
    use palc_zone_filter::{ZoneConfig, ZoneModel};

    const PLAN: &str = include_str!("../../../configs/examples/plan-problem.json");
    const ZONE: &str = include_str!("../../../configs/examples/zone.toml");

    #[test]
    fn a_wrong_type_in_a_nested_plan_field_names_its_path_line_and_column() {
        let text = PLAN.replacen("\"v\": 20.1168", "\"v\": \"fast\"", 1);
        assert_ne!(text, PLAN, "the example has no initial speed of 20.1168");
        let error = json::<PlanInput>(text.as_bytes()).unwrap_err();
        assert_eq!(error.path, "problem.initial.v", "{error}");
        let message = error.to_string();
        assert!(
            message.contains("`problem.initial.v`: invalid type") && message.contains("line 19"),
            "{message}"
        );
    }

    #[test]
    fn a_byte_order_mark_before_the_json_is_skipped() {
        let marked = [b"\xEF\xBB\xBF".as_slice(), PLAN.as_bytes()].concat();
        let input = json::<PlanInput>(marked.as_slice()).unwrap();
        let plain = json::<PlanInput>(PLAN.as_bytes()).unwrap();
        assert_eq!(format!("{input:?}"), format!("{plain:?}"));
    }

    #[test]
    fn trailing_text_after_the_json_value_is_refused() {
        let error = json::<PlanInput>(format!("{PLAN} {{}}").as_bytes()).unwrap_err();
        assert!(
            error.path.is_empty() && error.to_string().contains("trailing"),
            "{error}"
        );
    }

    #[test]
    fn a_wrong_type_in_the_zone_config_names_its_path_and_line() {
        let error =
            toml::<ZoneConfig>(&ZONE.replace("ridge = 0.0", "ridge = \"small\"")).unwrap_err();
        assert_eq!(error.path, "ridge", "{error}");
        let message = error.to_string();
        assert!(
            message.contains("`ridge`: ") && message.contains("line 8"),
            "{message}"
        );
    }

    #[test]
    fn a_wrong_type_in_the_zone_model_names_its_path() {
        let samples = crate::commands::zone::samples_from_csv(
            include_str!("../../../configs/examples/zone-samples.csv").as_bytes(),
            palc_zone_filter::FeatureSet::Paper,
        )
        .unwrap();
        let model = ZoneModel::fit(Default::default(), &samples).unwrap();
        let mut value = serde_json::to_value(&model).unwrap();
        value["config"]["ridge"] = serde_json::json!("small");
        let text = serde_json::to_string_pretty(&value).unwrap();
        let error = json::<ZoneModel>(text.as_bytes()).unwrap_err();
        assert_eq!(error.path, "config.ridge", "{error}");
        assert!(error.to_string().contains("line"), "{error}");
    }
}
