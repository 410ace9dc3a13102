//! The lander behind Lander2D.fmu. The core advances in fixed control periods of `dt`; a
//! communication step to time t runs every whole period whose end lies at or before t on
//! the grid `start_time + k·dt` (k counted by the core, never summed), so the outputs are
//! exactly the core's state after those periods. A communication step shorter than `dt` may
//! run no period at all; the outputs then stay as they are until the grid is reached.

use crate::model::{FmuModel, ModelInfo, ModelTable, StepRequest};
use flyloop_core::lander2d::{Lander2d, Lander2dInitial};
use flyloop_core::variables;
use flyloop_core::{ParamError, SnapshotError};
use std::sync::OnceLock;

/// A period counts as reached when its end is within this fraction of a period of the
/// communication point (absorbs the rounding of t0 + n·h against k·dt).
const GRID_TOLERANCE: f64 = 1e-6;

static INFO: ModelInfo = ModelInfo {
    identifier: "Lander2D",
    description: "flyloop Lander2D: 2D drone with two thrusters over a landing platform \
                  (rapier2d), thrust noise, battery, wind",
    default_experiment: (0.0, 20.0, 0.02),
    // The wind force output is the episode wind plus the input; everything else moves only
    // with a step.
    direct_feedthrough: &[
        ("wind_force_x", &["wind_force_input_x"]),
        ("wind_force_y", &["wind_force_input_y"]),
    ],
};

/// Control periods from the start to `step.end_time` on the fixed grid of `lander`.
fn periods_until(lander: &Lander2d, step: &StepRequest) -> u64 {
    let periods = (step.end_time - step.start_time) / lander.params().dt + GRID_TOLERANCE;
    // `as` saturates: negative → 0, huge → u64::MAX (refused by internal_steps first).
    periods.floor() as u64
}

impl FmuModel for Lander2d {
    type Initial = Lander2dInitial;

    fn table() -> &'static ModelTable {
        static TABLE: OnceLock<ModelTable> = OnceLock::new();
        TABLE.get_or_init(|| ModelTable::new(&INFO, variables::variables::<Lander2d>()))
    }

    fn build(previous: Option<&Self>, initial: &Lander2dInitial) -> Result<Self, ParamError> {
        let params = previous.map(|l| l.params().clone()).unwrap_or_default();
        Lander2d::from_initial(params, initial)
    }

    fn get(&self, initial: &Lander2dInitial, vr: u32) -> Result<f64, ParamError> {
        variables::get(self, initial, vr)
    }

    fn set(
        &mut self,
        initial: &mut Lander2dInitial,
        vr: u32,
        value: f64,
    ) -> Result<(), ParamError> {
        variables::set(self, initial, vr, value)
    }

    fn internal_steps(&self, step: &StepRequest) -> f64 {
        let periods = periods_until(self, step).saturating_sub(self.steps());
        periods as f64 * f64::from(self.params().physics_substeps)
    }

    fn advance(&mut self, step: &StepRequest) {
        let target = periods_until(self, step);
        while self.steps() < target {
            self.step();
        }
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
