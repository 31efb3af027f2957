//! Errors of the traffic crate: one enum for configs and scenario construction, one for
//! running a scene.

use crate::road::Lane;
use crate::vehicle::VehicleId;

/// A scenario config or a test-bed cell that cannot be turned into a scene.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ConfigError {
    /// The TOML text does not parse or does not match the schema (unknown field, missing
    /// field, wrong type); the message names the field path, the line and the column.
    #[error("invalid scenario config: {}{error}", at_field(path))]
    Toml {
        /// Dotted path of the field where the error is (e.g. `road.lanes`, `platoon.leader_profile[2].time_s`);
        /// empty for a syntax error, which has no field.
        path: String,
        /// The parse error, with its line and column (in the message, so not a `source`
        /// that a report would print twice).
        error: Box<toml::de::Error>,
    },
    /// A number lies outside the range it must lie in (negative length, speed in wrong units).
    #[error("`{field}` = {value:?} is out of range: it must be {bound}")]
    OutOfRange {
        /// Dotted path of the field, as in the config.
        field: String,
        /// The value given.
        value: f64,
        /// The allowed range, in words.
        bound: String,
    },
    /// Two entries of a list have the same name (the first would win).
    #[error("`{field}` = {name:?} is the name of `{first}` already: names must be unique")]
    DuplicateName {
        /// Dotted path of the second field with the name.
        field: String,
        /// The name.
        name: String,
        /// Dotted path of the first field with the name.
        first: String,
    },
    /// A list that must have at least one element is empty.
    #[error("`{field}` is empty: it needs at least one entry")]
    Empty {
        /// Dotted path of the field.
        field: String,
    },
    /// The config describes no scenario, or more than one.
    #[error(
        "a scenario config needs exactly one of the tables [testbed] and [platoon], found {found}"
    )]
    ScenarioKind {
        /// What was found, in words.
        found: &'static str,
    },
    /// A vehicle starts faster than its IDM desired speed v0, which it cannot hold.
    #[error(
        "`{field}` = {speed_mps:?} m/s is above the desired speed v0 = {v0_mps:?} m/s that the IDM can hold"
    )]
    SpeedAboveDesired {
        /// Dotted path of the field that sets the initial speed.
        field: String,
        /// Initial speed (m/s).
        speed_mps: f64,
        /// Desired speed v0 (m/s).
        v0_mps: f64,
    },
    /// The ego is not faster than the background traffic, so it is not impeded and the
    /// scenario is no discretionary lane change (paper, Section III.A).
    #[error(
        "speed case `{case}`: ego speed {ego_mph:?} mph must be above the others' speed {others_mph:?} mph"
    )]
    NotImpeded {
        /// Name of the speed case.
        case: String,
        /// Ego speed (mph).
        ego_mph: f64,
        /// Background speed (mph).
        others_mph: f64,
    },
    /// The IDM cannot hold the background speed at this headway with any positive time gap.
    #[error(
        "`{field}` = {headway_m:?} m cannot be held at {speed_mps:?} m/s: the IDM needs a front-to-front headway above {min_m:?} m"
    )]
    HeadwayCannotHold {
        /// Dotted path of the field.
        field: String,
        /// Headway given (m, front to front).
        headway_m: f64,
        /// Background speed (m/s).
        speed_mps: f64,
        /// Smallest headway that can be held (m).
        min_m: f64,
    },
    /// Two vehicles on the same lane overlap (net gap not positive) at the start.
    #[error(
        "vehicles {back:?} and {front:?} overlap on lane {lane:?} at the start: net gap {gap_m:?} m must be above 0 m"
    )]
    Overlap {
        /// Lane of both vehicles.
        lane: Lane,
        /// The vehicle ahead.
        front: VehicleId,
        /// The vehicle behind.
        back: VehicleId,
        /// Net gap (m).
        gap_m: f64,
    },
    /// A vehicle would start outside the road section.
    #[error(
        "vehicle {id:?} would start at s = {s_m:?} m, outside the road section [0, {length_m:?}] m (`{hint}`)"
    )]
    OutsideSection {
        /// The vehicle.
        id: VehicleId,
        /// Its front position (m).
        s_m: f64,
        /// Section length (m).
        length_m: f64,
        /// The field to change.
        hint: &'static str,
    },
    /// The scripted leader profile is not a valid profile.
    #[error("`platoon.leader_profile`: {reason}")]
    InvalidProfile {
        /// What is wrong.
        reason: &'static str,
    },
    /// A test-bed cell index beyond the grid.
    #[error("test-bed cell {index} does not exist: the grid has {cells} cells")]
    NoSuchCell {
        /// Index asked for.
        index: usize,
        /// Number of cells.
        cells: usize,
    },
    /// A test-bed operation on a config without a `[testbed]` table.
    #[error("the config has no [testbed] table")]
    NotATestbed,
}

/// A scene cannot be advanced or predicted with the given inputs.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SceneError {
    /// The time step is not finite or outside (0, MAX_DT].
    #[error("time step dt = {dt} s is out of range: it must be in (0, {max}] s")]
    InvalidTimeStep {
        /// The time step given (s).
        dt: f64,
        /// Largest time step allowed (s).
        max: f64,
    },
    /// A field of the supplied ego state is out of range.
    #[error("ego state `{field}` = {value:?} is out of range: it must be {bound}")]
    InvalidEgoState {
        /// The field.
        field: &'static str,
        /// The value given.
        value: f64,
        /// The allowed range, in words.
        bound: &'static str,
    },
    /// An ego state was supplied to a scene that has no ego.
    #[error("the scene has no ego vehicle")]
    NoEgo,
    /// A prediction asked for a vehicle role the scene does not have.
    #[error("the scene has no {role} vehicle")]
    MissingVehicle {
        /// `preceding` or `adjacent`.
        role: &'static str,
    },
    /// A simulator outside palc reported a vehicle state that cannot be used.
    #[error("observed vehicle {id}: `{field}` = {value:?} is out of range: it must be {bound}")]
    InvalidObservation {
        /// The vehicle's identifier as reported.
        id: u32,
        /// The field.
        field: &'static str,
        /// The value reported.
        value: f64,
        /// The allowed range, in words.
        bound: &'static str,
    },
    /// A simulator outside palc did not report a background vehicle of the scene
    /// (it left the simulation, or the simulator lost it).
    #[error("vehicle {id} of the scene was not reported by the simulator after the step")]
    MissingObservation {
        /// The vehicle's identifier.
        id: u32,
    },
    /// A prediction horizon longer than allowed.
    #[error("prediction horizon of {steps} steps is too long: at most {max} steps")]
    HorizonTooLong {
        /// Steps asked for.
        steps: usize,
        /// Largest horizon allowed.
        max: usize,
    },
}

/// `` `path`: `` before a message, or nothing for an empty path.
pub(crate) fn at_field(path: &str) -> String {
    if path.is_empty() {
        String::new()
    } else {
        format!("`{path}`: ")
    }
}
