//! The lander behind Lander2D.fmu. A communication step to time t leaves the core in its
//! state at t (`Lander2d::advance_to`): whole rapier steps on the fixed physics grid
//! `start_time + k·physics_step` (thrust noise and battery drain once per grid step), and a
//! shortened rapier step when t falls inside a grid step; so every communication step size
//! that is a multiple of `physics_step` gives the same bits at the shared times.

use crate::model::{FmuModel, Table};
use crate::table::ModelInfo;
use flyloop_core::lander2d::{Lander2d, Lander2dInitial};
use flyloop_core::variables::Rows;
use flyloop_core::{ParamError, SnapshotError};
use std::borrow::Cow;

/// Lander2D.fmu's table: the core's variables as they are.
pub(super) fn table() -> Table<Lander2d> {
    Table::new(info(), (), Rows::of(&()), Vec::new(), None)
}

fn info() -> ModelInfo {
    ModelInfo {
        identifier: "Lander2D",
        description: Cow::Borrowed(
            "flyloop Lander2D: 2D drone with two thrusters over a landing platform \
                  (rapier2d), thrust noise, battery, wind",
        ),
        default_experiment: (0.0, 20.0, 0.02),
        // The wind force output is the episode wind plus the input; everything else moves only
        // with a step.
        direct_feedthrough: &[
            ("wind_force_x", &["wind_force_input_x"]),
            ("wind_force_y", &["wind_force_input_y"]),
        ],
        state_free_outputs: &[],
        // Two commands read better by name (left, right) than as an array.
        arrays: Vec::new(),
        event_indicators: &[],
        descriptions: Vec::new(),
    }
}

impl FmuModel for Lander2d {
    fn build(
        _: &(),
        previous: Option<&Self>,
        initial: &Lander2dInitial,
    ) -> Result<Self, ParamError> {
        let params = previous.map(|l| l.params().clone()).unwrap_or_default();
        Lander2d::from_initial(params, initial)
    }

    fn internal_steps(&self, end: f64, _h: f64) -> f64 {
        // Physics steps to go: whole grid steps, one more cut per control period end, and
        // at most two pieces of a grid step.
        let p = self.params();
        let ahead = (end - self.time()).max(0.0);
        (ahead / p.physics_step).ceil() + (ahead / p.dt).ceil() + 2.0
    }

    fn advance(&mut self, end: f64, _h: f64) {
        self.advance_to(end);
    }

    fn is_finite(&self) -> bool {
        let d = self.drone();
        [
            d.x,
            d.y,
            d.angle,
            d.vx,
            d.vy,
            d.angular_velocity,
            self.platform_x(),
        ]
        .iter()
        .all(|v| v.is_finite())
    }

    fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        Lander2d::save(self)
    }

    fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        Lander2d::restore(bytes)
    }
}
