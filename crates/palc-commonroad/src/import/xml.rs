//! The CommonRoad 2020a XML as serde types, read by quick-xml's deserializer.
//!
//! Only what the importer needs is declared: the root's attributes, lanelets (bounds,
//! successors, predecessors, adjacency) and dynamic obstacles (shape, initial state,
//! trajectory). Every other element (traffic signs, intersections, static obstacles,
//! planning problems) is skipped by the root's catch-all variant, and unknown children of
//! the declared elements are ignored because no type denies unknown fields. The version
//! is checked on the root element before the document is deserialized, so a 2018b file
//! gets a message about its version rather than about its structure.

use quick_xml::Reader;
use quick_xml::events::Event;
use serde::Deserialize;

use super::error::ImportError;

/// The `commonRoad` root element.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlRoot {
    #[serde(rename = "@commonRoadVersion")]
    pub version: String,
    #[serde(rename = "@benchmarkID", default)]
    pub benchmark_id: String,
    #[serde(rename = "@timeStepSize")]
    pub time_step_size: f64,
    #[serde(rename = "$value", default)]
    pub children: Vec<XmlChild>,
}

/// A child of the root: the two kinds the importer reads and everything else.
#[derive(Debug, Deserialize)]
pub(crate) enum XmlChild {
    #[serde(rename = "lanelet")]
    Lanelet(XmlLanelet),
    #[serde(rename = "dynamicObstacle")]
    DynamicObstacle(XmlObstacle),
    #[serde(other)]
    Other,
}

/// A `lanelet` element.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlLanelet {
    #[serde(rename = "@id")]
    pub id: i64,
    #[serde(rename = "leftBound")]
    pub left: XmlBound,
    #[serde(rename = "rightBound")]
    pub right: XmlBound,
    #[serde(default)]
    pub predecessor: Vec<XmlRef>,
    #[serde(default)]
    pub successor: Vec<XmlRef>,
    #[serde(rename = "adjacentLeft")]
    pub adjacent_left: Option<XmlAdjacent>,
    #[serde(rename = "adjacentRight")]
    pub adjacent_right: Option<XmlAdjacent>,
}

/// A lanelet's bound: its points (the line marking is ignored).
#[derive(Debug, Deserialize)]
pub(crate) struct XmlBound {
    #[serde(default)]
    pub point: Vec<XmlPoint>,
}

/// A point `<x>..</x><y>..</y>`.
#[derive(Debug, Clone, Copy, Deserialize)]
pub(crate) struct XmlPoint {
    pub x: f64,
    pub y: f64,
}

/// A `successor` or `predecessor` reference.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlRef {
    #[serde(rename = "@ref")]
    pub id: i64,
}

/// An `adjacentLeft` or `adjacentRight` reference with its driving direction.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlAdjacent {
    #[serde(rename = "@ref")]
    pub id: i64,
    #[serde(rename = "@drivingDir")]
    pub driving_dir: String,
}

/// A `dynamicObstacle` element.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlObstacle {
    #[serde(rename = "@id")]
    pub id: i64,
    #[serde(rename = "type", default)]
    pub kind: String,
    pub shape: Option<XmlShape>,
    #[serde(rename = "initialState")]
    pub initial_state: Option<XmlState>,
    pub trajectory: Option<XmlTrajectory>,
}

/// An obstacle's shape; only a rectangle gives a length and width.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlShape {
    pub rectangle: Option<XmlRectangle>,
}

/// A `rectangle` shape.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlRectangle {
    pub length: f64,
    pub width: f64,
}

/// A `trajectory`: its states.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlTrajectory {
    #[serde(default)]
    pub state: Vec<XmlState>,
}

/// A state; the importer needs the position and the time, the rest may be absent.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlState {
    pub position: Option<XmlPosition>,
    pub orientation: Option<XmlExact>,
    pub time: Option<XmlExact>,
    pub velocity: Option<XmlExact>,
    pub acceleration: Option<XmlExact>,
}

/// A state's position; only an exact point is used.
#[derive(Debug, Deserialize)]
pub(crate) struct XmlPosition {
    pub point: Option<XmlPoint>,
}

/// A value given as `<exact>..</exact>` (intervals are not read).
#[derive(Debug, Deserialize)]
pub(crate) struct XmlExact {
    pub exact: Option<f64>,
}

/// Line and column (from 1) of a byte offset in `text`.
pub(crate) fn line_column(text: &str, offset: u64) -> (usize, usize) {
    let offset = usize::try_from(offset)
        .unwrap_or(usize::MAX)
        .min(text.len());
    let before = text.as_bytes().get(..offset).unwrap_or_default();
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let column = before.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
    (line, column)
}

/// Reads the root element's `commonRoadVersion` (a scan of the first start tag, so a
/// document of another version is not deserialized with this version's types).
pub(crate) fn check_root(text: &str, source: &str) -> Result<(), ImportError> {
    let mut reader = Reader::from_str(text);
    loop {
        let event = reader.read_event().map_err(|e| {
            let (line, column) = line_column(text, reader.error_position());
            ImportError::Xml {
                source_name: source.to_owned(),
                line,
                column,
                message: e.to_string(),
            }
        })?;
        match event {
            Event::Start(start) | Event::Empty(start) => {
                let name = String::from_utf8_lossy(start.name().as_ref()).into_owned();
                if name != "commonRoad" {
                    return Err(ImportError::NotCommonRoad {
                        source_name: source.to_owned(),
                        root: name,
                    });
                }
                let version = start
                    .attributes()
                    .flatten()
                    .find(|a| a.key.as_ref() == b"commonRoadVersion")
                    .map(|a| String::from_utf8_lossy(&a.value).into_owned());
                return match version.as_deref() {
                    Some(super::SUPPORTED_VERSION) => Ok(()),
                    other => Err(ImportError::UnsupportedVersion {
                        source_name: source.to_owned(),
                        version: other.unwrap_or("(none)").to_owned(),
                    }),
                };
            }
            Event::Eof => {
                return Err(ImportError::NotCommonRoad {
                    source_name: source.to_owned(),
                    root: "(no element)".to_owned(),
                });
            }
            _ => {}
        }
    }
}

/// Deserializes a scenario whose root [`check_root`] accepted.
pub(crate) fn parse(text: &str, source: &str) -> Result<XmlRoot, ImportError> {
    let mut de = quick_xml::de::Deserializer::from_str(text);
    XmlRoot::deserialize(&mut de).map_err(|e| {
        let reader = de.get_ref().get_ref();
        let position = match e {
            quick_xml::DeError::InvalidXml(_) => reader.error_position(),
            _ => reader.buffer_position(),
        };
        let (line, column) = line_column(text, position);
        ImportError::Xml {
            source_name: source.to_owned(),
            line,
            column,
            message: e.to_string(),
        }
    })
}
