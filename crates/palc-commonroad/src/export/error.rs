//! The one error type of the export: what is wrong with the data handed in, or
//! what the XML serializer refused.

/// Why a scenario or solution cannot be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// A number is NaN or infinite.
    #[error("{owner}: `{field}` at step {step} is {value}, not a finite number")]
    NotFinite {
        /// What the number belongs to, e.g. `obstacle 101` or `ego trajectory`.
        owner: String,
        /// The field, e.g. `x` or `velocity`.
        field: &'static str,
        /// The index of the state (0 for a value that has no steps).
        step: usize,
        /// The value found.
        value: f64,
    },
    /// A length, width or step is zero or negative.
    #[error("{owner}: `{field}` is {value}, expected a positive number")]
    NotPositive {
        /// What the number belongs to.
        owner: String,
        /// The field.
        field: &'static str,
        /// The value found.
        value: f64,
    },
    /// A trajectory or obstacle has no state.
    #[error("{owner} has no state")]
    Empty {
        /// What is empty.
        owner: String,
    },
    /// Time steps do not rise by one from state to state.
    #[error("{owner}: state {step} has time step {found}, expected {expected}")]
    TimeSteps {
        /// What the states belong to.
        owner: String,
        /// The index of the state.
        step: usize,
        /// The time step found.
        found: u32,
        /// The time step expected (the previous one plus one).
        expected: u32,
    },
    /// Two elements of the scenario share an ID (CommonRoad IDs are unique over
    /// lanelets, obstacles and planning problems).
    #[error("ID {id} is used twice (lanelets take 1 and 2)")]
    DuplicateId {
        /// The ID.
        id: u32,
    },
    /// The road's extent in x is empty.
    #[error("the road runs from x = {x_start} to x = {x_end}: it must end after it starts")]
    EmptyRoad {
        /// Where the road starts (m).
        x_start: f64,
        /// Where the road ends (m).
        x_end: f64,
    },
    /// The goal's time interval ends before it starts.
    #[error("the goal's time interval [{start}, {end}] ends before it starts")]
    GoalInterval {
        /// First time step of the goal.
        start: u32,
        /// Last time step of the goal.
        end: u32,
    },
    /// A scenario ID CommonRoad cannot carry in a solution's benchmark ID.
    #[error("scenario ID `{id}` is empty or holds `:` or white space")]
    ScenarioId {
        /// The ID given.
        id: String,
    },
    /// The XML serializer refused the document.
    #[error("cannot serialize the XML: {0}")]
    Xml(#[from] quick_xml::SeError),
    /// The XML declaration could not be written.
    #[error("cannot write the XML declaration: {0}")]
    Declaration(#[from] std::io::Error),
}
