//! The dynamic obstacles as tracks: one sample per time step with position and speed, or
//! the reason the vehicle is skipped.

use super::geometry::Point;
use super::params::MAX_COORDINATE_M;
use super::record::SkipReason;
use super::xml::{XmlObstacle, XmlState};

/// A vehicle's track with consecutive time steps and finite numbers.
#[derive(Debug)]
pub(crate) struct Track {
    /// The obstacle id.
    pub id: i64,
    /// The obstacle's `type` (`car`, `truck`, ...).
    pub kind: String,
    /// Length (m).
    pub length: f64,
    /// Width (m).
    pub width: f64,
    /// The first time step; sample `k` is at step `first_step + k`.
    pub first_step: i64,
    /// Positions (m).
    pub position: Vec<Point>,
    /// Speeds (m/s): the state's velocity, or the speed between the neighbouring
    /// positions where the state has none.
    pub speed: Vec<f64>,
}

impl Track {
    /// The number of samples.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    /// The last time step.
    pub fn last_step(&self) -> i64 {
        self.first_step + self.len() as i64 - 1
    }

    /// The sample at time step `step`, if recorded.
    pub fn index_of(&self, step: i64) -> Option<usize> {
        usize::try_from(step - self.first_step)
            .ok()
            .filter(|&k| k < self.len())
    }
}

/// Reads an obstacle into a track; `Err((reason, time step))` when it must be skipped.
pub(crate) fn track(obstacle: &XmlObstacle, dt: f64) -> Result<Track, (SkipReason, Option<i64>)> {
    let rectangle = obstacle
        .shape
        .as_ref()
        .and_then(|s| s.rectangle.as_ref())
        .ok_or((SkipReason::Incomplete, None))?;
    if !rectangle.length.is_finite() || !rectangle.width.is_finite() {
        return Err((SkipReason::NonFinite, None));
    }
    if rectangle.length <= 0.0 || rectangle.width <= 0.0 {
        return Err((SkipReason::Incomplete, None));
    }
    let states: Vec<&XmlState> = obstacle
        .initial_state
        .iter()
        .chain(obstacle.trajectory.iter().flat_map(|t| t.state.iter()))
        .collect();
    let mut first_step = None;
    let mut position = Vec::with_capacity(states.len());
    let mut velocity = Vec::with_capacity(states.len());
    for (k, state) in states.iter().enumerate() {
        let time = state.time.as_ref().and_then(|t| t.exact);
        let step = match time {
            Some(t) if t.is_finite() && t.fract() == 0.0 && t.abs() < 1e15 => t as i64,
            Some(t) if !t.is_finite() => return Err((SkipReason::NonFinite, None)),
            _ => return Err((SkipReason::Incomplete, None)),
        };
        let first = *first_step.get_or_insert(step);
        if step != first + k as i64 {
            return Err((SkipReason::TimeGap, Some(step)));
        }
        let point = state
            .position
            .as_ref()
            .and_then(|p| p.point)
            .ok_or((SkipReason::Incomplete, Some(step)))?;
        let exact = |v: &Option<super::xml::XmlExact>| v.as_ref().and_then(|v| v.exact);
        let v = exact(&state.velocity);
        let others = [exact(&state.orientation), exact(&state.acceleration), v];
        let in_range = |c: f64| c.is_finite() && c.abs() <= MAX_COORDINATE_M;
        if !in_range(point.x)
            || !in_range(point.y)
            || others.iter().flatten().any(|v| !v.is_finite())
        {
            return Err((SkipReason::NonFinite, Some(step)));
        }
        position.push([point.x, point.y]);
        velocity.push(v);
    }
    let Some(first_step) = first_step else {
        return Err((SkipReason::Incomplete, None));
    };
    let n = position.len();
    let speed = (0..n)
        .map(|k| {
            velocity[k].unwrap_or_else(|| {
                let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
                if b > a {
                    super::geometry::dist(position[a], position[b]) / ((b - a) as f64 * dt)
                } else {
                    0.0
                }
            })
        })
        .collect();
    Ok(Track {
        id: obstacle.id,
        kind: obstacle.kind.clone(),
        length: rectangle.length,
        width: rectangle.width,
        first_step,
        position,
        speed,
    })
}
