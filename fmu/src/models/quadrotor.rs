//! The quadrotor behind Quadrotor.fmu: a communication step of h seconds is one
//! `Quadrotor::step(h)`, which cuts the step at the turbulence's own sample times
//! (`turbulence_dt`) and integrates each piece in ceil(piece / max_substep) equal RK4
//! substeps under the wind of the piece's start, so h does not change the weather.

use crate::model::{FmuModel, ModelInfo, ModelTable, StepRequest};
use flyloop_core::quadrotor::{Quadrotor, QuadrotorInitial, wind};
use flyloop_core::variables;
use flyloop_core::{ParamError, SnapshotError};
use std::sync::OnceLock;

const WIND_INPUTS: &[&str] = &["wind_input_x", "wind_input_y", "wind_input_z"];

static INFO: ModelInfo = ModelInfo {
    identifier: "Quadrotor",
    description: "flyloop quadrotor: 3D rigid body (ENU world, FLU body), four lagged motors, \
                  quadratic drag, Ornstein-Uhlenbeck wind; RK4",
    default_experiment: (0.0, 10.0, 0.01),
    // Acceleration includes drag, which reacts to the wind input at once; the wind output
    // is the episode wind plus the input. Everything else moves only with a step.
    direct_feedthrough: &[
        ("ax", WIND_INPUTS),
        ("ay", WIND_INPUTS),
        ("az", WIND_INPUTS),
        ("wind_x", &["wind_input_x"]),
        ("wind_y", &["wind_input_y"]),
        ("wind_z", &["wind_input_z"]),
    ],
};

impl FmuModel for Quadrotor {
    type Initial = QuadrotorInitial;

    fn table() -> &'static ModelTable {
        static TABLE: OnceLock<ModelTable> = OnceLock::new();
        TABLE.get_or_init(|| ModelTable::new(&INFO, variables::variables::<Quadrotor>()))
    }

    fn build(previous: Option<&Self>, initial: &QuadrotorInitial) -> Result<Self, ParamError> {
        let params = previous.map(|q| q.params.clone()).unwrap_or_default();
        Quadrotor::from_initial(params, initial)
    }

    fn get(&self, initial: &QuadrotorInitial, vr: u32) -> Result<f64, ParamError> {
        variables::get(self, initial, vr)
    }

    fn set(
        &mut self,
        initial: &mut QuadrotorInitial,
        vr: u32,
        value: f64,
    ) -> Result<(), ParamError> {
        variables::set(self, initial, vr, value)
    }

    fn internal_steps(&self, step: &StepRequest) -> f64 {
        (step.step_size / self.params.max_substep).ceil()
            + wind::segment_count(&self.params, step.step_size)
    }

    fn advance(&mut self, step: &StepRequest) {
        self.step(step.step_size);
    }

    fn is_finite(&self) -> bool {
        let b = &self.body;
        b.position
            .iter()
            .chain(b.velocity.iter())
            .chain(b.body_rates.iter())
            .chain(b.attitude.coords.iter())
            .chain(b.motors.iter())
            .all(|v| v.is_finite())
    }

    fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        Quadrotor::save(self)
    }

    fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        Quadrotor::restore(bytes)
    }
}
