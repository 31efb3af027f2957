//! The study protocol (TOML): the participant, the scenes in order with their
//! stopping rules, whether experience carries between scenes, the pause between
//! them, whether the plan is shown and the live driver's limits. The server
//! ticks once per planning step of the learn config, in real time (10 Hz at its
//! `dt` of 0.1 s).
//!
//! ```toml
//! participant = "P01"
//! carry_experience = true
//! show_plan = true
//! pause_s = 5.0
//!
//! [[scene]]
//! speed_case = "collector-high"
//! headway_m = 40.0
//! seed = 1
//! success_streak = 3
//! max_lane_changes = 12
//! ```

use std::path::{Path, PathBuf};

use palc_harness::live::LiveLimits;
use palc_harness::{CellChoice, LearnConfig};
use serde::{Deserialize, Serialize};

use crate::DriveError;

/// The learn config a protocol's scenes start from unless it names its own.
pub const DEFAULT_LEARN_CONFIG: &str = include_str!("../../../configs/learn.toml");

/// Most scenes a protocol may hold.
pub const MAX_SCENES: usize = 100;

/// Most lane changes a scene may ask for.
pub const MAX_LANE_CHANGES: usize = 100;

/// A study protocol.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Protocol {
    /// The participant's id: letters, digits, `-` and `_`, at most 64.
    pub participant: String,
    /// A learn config (relative to the protocol file) the scenes take their
    /// planning set-up from; `configs/learn.toml`'s by default.
    #[serde(default)]
    pub config: Option<PathBuf>,
    /// Whether what was learned in a scene carries to the next.
    #[serde(default = "yes")]
    pub carry_experience: bool,
    /// Whether the planned lane change is drawn ahead of the ego (off for blind
    /// studies).
    #[serde(default = "yes")]
    pub show_plan: bool,
    /// How the server steps: in real time, a tick per planning step, or, for scripted
    /// participants, once per control message.
    #[serde(default)]
    pub pace: Pace,
    /// The pause between scenes (s), shown to the participant.
    #[serde(default = "default_pause_s")]
    pub pause_s: f64,
    /// The live driver's limits (`[limits]`).
    #[serde(default)]
    pub limits: LiveLimits,
    /// The scenes in order (`[[scene]]`).
    pub scene: Vec<SceneProtocol>,
}

/// How the server steps a lane change.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Pace {
    /// A tick every planning step (`planning.dt`) while the page is connected.
    #[default]
    Realtime,
    /// A tick for every control message, answered with its frame: a scripted
    /// participant drives as fast as it decides, and every run is the same.
    Lockstep,
}

/// One scene of a protocol and its stopping rule.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneProtocol {
    /// The speed case of the test bed.
    pub speed_case: String,
    /// Front-to-front headway on the target lane (m).
    pub headway_m: f64,
    /// The scene's seed.
    pub seed: u64,
    /// Takeover-free lane changes in a row that end the scene (the paper's 3).
    #[serde(default = "default_streak")]
    pub success_streak: usize,
    /// Lane changes after which the scene ends in any case.
    #[serde(default = "default_max_lane_changes")]
    pub max_lane_changes: usize,
}

fn yes() -> bool {
    true
}
fn default_pause_s() -> f64 {
    5.0
}
fn default_streak() -> usize {
    3
}
fn default_max_lane_changes() -> usize {
    12
}

impl Protocol {
    /// Reads and checks the protocol at `path` and the learn config it names.
    ///
    /// # Errors
    /// [`DriveError::Protocol`] naming the field, value and bound; I/O errors.
    pub fn load(path: &Path) -> Result<(Protocol, LearnConfig), DriveError> {
        let text = std::fs::read_to_string(path).map_err(|source| DriveError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let protocol = Self::parse(&text, path)?;
        let config = protocol.learn_config(path)?;
        Ok((protocol, config))
    }

    /// Parses and checks protocol `text`; `path` names it in errors.
    ///
    /// # Errors
    /// [`DriveError::Protocol`].
    pub fn parse(text: &str, path: &Path) -> Result<Protocol, DriveError> {
        let error = |message: String| DriveError::Protocol {
            path: path.to_path_buf(),
            message,
        };
        let protocol: Protocol = toml::from_str(text).map_err(|e| error(e.to_string()))?;
        protocol.validate().map_err(error)?;
        Ok(protocol)
    }

    /// Checks every field against its bound.
    fn validate(&self) -> Result<(), String> {
        let id = &self.participant;
        let id_ok = !id.is_empty()
            && id.len() <= 64
            && id
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_');
        if !id_ok {
            return Err(format!(
                "`participant` is {id:?}, expected 1 to 64 letters, digits, `-` or `_`"
            ));
        }
        if !(self.pause_s.is_finite() && (0.0..=600.0).contains(&self.pause_s)) {
            return Err(format!(
                "`pause_s` is {}, expected 0 to 600 s",
                self.pause_s
            ));
        }
        self.limits.validate("limits").map_err(|e| e.to_string())?;
        if self.scene.is_empty() || self.scene.len() > MAX_SCENES {
            return Err(format!(
                "{} `[[scene]]` tables, expected 1 to {MAX_SCENES}",
                self.scene.len()
            ));
        }
        for (i, scene) in self.scene.iter().enumerate() {
            if !(scene.headway_m.is_finite() && scene.headway_m > 0.0) {
                return Err(format!(
                    "`scene[{i}].headway_m` is {}, expected a finite headway > 0 m",
                    scene.headway_m
                ));
            }
            if scene.success_streak == 0 || scene.success_streak > MAX_LANE_CHANGES {
                return Err(format!(
                    "`scene[{i}].success_streak` is {}, expected 1 to {MAX_LANE_CHANGES}",
                    scene.success_streak
                ));
            }
            if scene.max_lane_changes == 0 || scene.max_lane_changes > MAX_LANE_CHANGES {
                return Err(format!(
                    "`scene[{i}].max_lane_changes` is {}, expected 1 to {MAX_LANE_CHANGES}",
                    scene.max_lane_changes
                ));
            }
        }
        Ok(())
    }

    /// The learn config of the protocol at `path` (its own or the default).
    fn learn_config(&self, path: &Path) -> Result<LearnConfig, DriveError> {
        let error = |message: String| DriveError::Protocol {
            path: path.to_path_buf(),
            message,
        };
        let text = match &self.config {
            None => DEFAULT_LEARN_CONFIG.to_owned(),
            Some(config) => {
                let full = path.parent().unwrap_or(Path::new(".")).join(config);
                std::fs::read_to_string(&full)
                    .map_err(|e| error(format!("`config` {}: {e}", full.display())))?
            }
        };
        let config =
            LearnConfig::from_toml_str(&text).map_err(|e| error(format!("`config`: {e}")))?;
        // Every scene's cell must exist in that config's test bed.
        for i in 0..self.scene.len() {
            let scene = self.scene_config(&config, i);
            (scene.validate().and_then(|()| scene.cell().map(|_| ())))
                .map_err(|e| error(format!("`scene[{i}]`: {e}")))?;
        }
        Ok(config)
    }

    /// The learn config of scene `index`: `base` with the scene's cell and
    /// stopping rule.
    pub fn scene_config(&self, base: &LearnConfig, index: usize) -> LearnConfig {
        let scene = &self.scene[index];
        let mut config = base.clone().with_cell(CellChoice {
            speed_case: scene.speed_case.clone(),
            headway_m: scene.headway_m,
            seed: scene.seed,
        });
        config.stopping.success_streak = scene.success_streak;
        config.stopping.max_takeovers = scene.max_lane_changes;
        config.stopping.max_lane_changes = scene.max_lane_changes;
        config
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
participant = "P01"
[[scene]]
speed_case = "collector-high"
headway_m = 40.0
seed = 1
"#;

    fn error(text: &str) -> String {
        let path = Path::new("study.toml");
        match Protocol::parse(text, path) {
            Ok(_) => String::new(),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn a_good_protocol_takes_the_defaults() {
        let protocol = Protocol::parse(GOOD, Path::new("study.toml")).unwrap();
        assert_eq!(protocol.pace, Pace::Realtime);
        assert!(protocol.show_plan && protocol.carry_experience);
        assert_eq!(protocol.scene[0].success_streak, 3);
        let config = protocol.learn_config(Path::new("study.toml")).unwrap();
        let scene = protocol.scene_config(&config, 0);
        assert_eq!(scene.stopping.max_lane_changes, 12);
    }

    #[test]
    fn every_bad_field_is_named_with_its_value_and_bound() {
        let cases = [
            (GOOD.replace("P01", "P 01"), "`participant`"),
            (format!("pause_s = -1.0\n{GOOD}"), "`pause_s` is -1"),
            (GOOD.replace("40.0", "-4.0"), "`scene[0].headway_m` is -4"),
            (
                format!("{GOOD}max_lane_changes = 0\n"),
                "`scene[0].max_lane_changes` is 0",
            ),
            (format!("colour = 1\n{GOOD}"), "unknown field `colour`"),
            (
                "participant = \"P01\"\nscene = []\n".to_owned(),
                "0 `[[scene]]` tables",
            ),
            (
                format!("{GOOD}[limits]\nmax_lateral_speed_mps = 40.0\n")
                    .replace("[[scene]]", "")
                    .replace("speed_case", "[[scene]]\nspeed_case"),
                "limits.max_lateral_speed_mps",
            ),
        ];
        for (text, expected) in cases {
            let message = error(&text);
            assert!(
                message.contains(expected),
                "{expected:?} not in {message:?}"
            );
            assert!(message.contains("study.toml"), "{message}");
        }
    }

    #[test]
    fn a_scene_outside_the_test_bed_is_refused_naming_it() {
        let text = GOOD.replace("collector-high", "motorway");
        let protocol = Protocol::parse(&text, Path::new("study.toml")).unwrap();
        let message = protocol
            .learn_config(Path::new("study.toml"))
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("`scene[0]`") && message.contains("motorway"),
            "{message}"
        );
    }
}
