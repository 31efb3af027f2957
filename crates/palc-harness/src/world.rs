//! The world a lane change is driven in: palc's own traffic, or a simulator
//! outside palc (SUMO, highway-env, a Python object) behind the [`World`] trait.
//!
//! The learning loop keeps one [`palc_traffic::Scene`] per lane change, the
//! *mirror*: at the start the world places the scene at the trigger, and after
//! every step the ego's state is imposed on the world, the world advances one step
//! and reports the other vehicles, and the mirror takes those states
//! ([`Scene::step_observed`]). Everything the loop reads of the traffic (the
//! user's view, the longitudinal guard, the safety monitor, the recorded paths)
//! reads the mirror, and every prediction (plans, re-plans, the user's look one
//! step ahead, the safety layer's check) rolls out a clone of it with palc's own
//! models, the placed vehicles' IDM parameters being known. Without a world the
//! mirror is stepped by palc's own models, as it always was.

use palc_traffic::{EgoState, Observed, Scene};

use crate::HarnessError;

/// A simulator in which the learning loop drives its lane changes.
///
/// The loop calls [`World::place`] at the start of every lane change (and of every
/// closed-loop rehearsal), then [`World::step`] once per step of the plan's
/// horizon. A world is deterministic for the loop's purposes when the same
/// placement and the same ego states give the same reports: a closed-loop plan is
/// rehearsed once without the user, then driven with it.
pub trait World: std::fmt::Debug + Send {
    /// The world's name, for errors.
    fn name(&self) -> &str;

    /// Places `scene` (the ego at the trigger, its preceding vehicle and the
    /// target-lane platoon, each background vehicle with its IDM parameters) in the
    /// world, replacing what it held; the world then steps by `dt` seconds.
    ///
    /// # Errors
    /// Why the world cannot hold the scene, or the simulator's failure.
    fn place(&mut self, scene: &Scene, dt: f64) -> Result<(), WorldError>;

    /// Moves the ego to `ego` (its state at the end of the step), advances the
    /// world one step and reports every background vehicle of the placed scene
    /// (identifiers as in the scene, palc's coordinates: `s` the front bumper,
    /// `l` the centre line, positive to the left of lane 0's centre).
    ///
    /// # Errors
    /// The simulator's failure; the loop ends the run with it.
    fn step(&mut self, ego: &EgoState) -> Result<Vec<Observed>, WorldError>;
}

/// What went wrong in a world outside palc.
#[derive(Debug, thiserror::Error)]
#[error("{message}")]
pub struct WorldError {
    /// What happened, in the world's words.
    pub message: String,
}

impl WorldError {
    /// An error with `message`.
    pub fn new(message: impl Into<String>) -> Self {
        WorldError {
            message: message.into(),
        }
    }
}

/// palc's own traffic as a [`World`]: a clone of the placed scene stepped by
/// [`Scene::step`]. The loop without a world drives the mirror the same way; this
/// type shows (and its tests check) that a world reporting palc's own traffic
/// gives the loop's results bit for bit.
#[derive(Debug, Clone, Default)]
pub struct PalcTraffic {
    scene: Option<Scene>,
    dt: f64,
}

impl World for PalcTraffic {
    fn name(&self) -> &str {
        "palc"
    }

    fn place(&mut self, scene: &Scene, dt: f64) -> Result<(), WorldError> {
        self.scene = Some(scene.clone());
        self.dt = dt;
        Ok(())
    }

    fn step(&mut self, ego: &EgoState) -> Result<Vec<Observed>, WorldError> {
        let scene = (self.scene.as_mut()).ok_or_else(|| WorldError::new("no scene was placed"))?;
        (scene.step(self.dt, *ego)).map_err(|error| WorldError::new(error.to_string()))?;
        Ok(scene.observed())
    }
}

/// What drives the mirror of a lane change: palc's own models, or a world.
#[derive(Debug)]
pub(crate) struct Traffic<'w> {
    world: Option<&'w mut dyn World>,
}

impl<'w> Traffic<'w> {
    /// `world`'s traffic, or palc's own without one.
    pub(crate) fn of(world: Option<&'w mut dyn World>) -> Self {
        Traffic { world }
    }

    /// Starts a lane change from `scene` (the mirror at step 0).
    pub(crate) fn place(&mut self, scene: &Scene, dt: f64) -> Result<(), HarnessError> {
        match &mut self.world {
            None => Ok(()),
            Some(world) => (world.place(scene, dt)).map_err(|error| failed(&**world, error)),
        }
    }

    /// Moves the mirror `scene` one step of `dt`, the ego to `ego`.
    pub(crate) fn advance(
        &mut self,
        scene: &mut Scene,
        dt: f64,
        ego: EgoState,
    ) -> Result<(), HarnessError> {
        match &mut self.world {
            None => Ok(scene.step(dt, ego)?),
            Some(world) => {
                let observed = (world.step(&ego)).map_err(|error| failed(&**world, error))?;
                (scene.step_observed(dt, ego, &observed)).map_err(|source| HarnessError::World {
                    world: world.name().to_owned(),
                    source: Box::new(source),
                })
            }
        }
    }
}

/// The run's error for `error` in `world`.
fn failed(world: &dyn World, error: WorldError) -> HarnessError {
    HarnessError::World {
        world: world.name().to_owned(),
        source: Box::new(error),
    }
}
