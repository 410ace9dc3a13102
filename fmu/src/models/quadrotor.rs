//! The multirotor behind every multirotor FMU ([`super::Multirotor`] declares one per
//! frame). A communication step of h seconds is one `Quadrotor::step(h)`, which integrates
//! on the model's fixed physics grid (`max_substep`, contact substeps inside each grid
//! interval) and cuts the step at the turbulence's own sample times (`turbulence_dt`), so
//! any h on the grid gives the same bits at the shared times and h does not change the
//! weather.
//!
//! Model Exchange integrates the same right-hand side (`flyloop_core::quadrotor::continuous`):
//! the continuous states of the frame, the four foot heights as event indicators and the
//! turbulence samples as time events.

use crate::error::FmuError;
use crate::model::{FmuModel, Hybrid};
use flyloop_core::CommandError;
use flyloop_core::number::Compact;
use flyloop_core::quadrotor::continuous::{BRISTLES, body_state_outputs};
use flyloop_core::quadrotor::{Frame, Quadrotor, QuadrotorInitial, wind};
use flyloop_core::vehicle::Vehicle;
use flyloop_core::{ParamError, SnapshotError};

/// The name of continuous state `index` of `quad`, for messages.
fn state_name(quad: &Quadrotor, index: usize) -> &'static str {
    let names = body_state_outputs(quad.frame().rotor_count()).chain(BRISTLES.map(|b| b.0));
    names.clone().nth(index).unwrap_or_default()
}

impl FmuModel for Quadrotor {
    fn build(
        frame: &Frame,
        previous: Option<&Self>,
        initial: &QuadrotorInitial,
    ) -> Result<Self, ParamError> {
        let params = previous.map(|q| q.params.clone()).unwrap_or_default();
        Ok(Quadrotor::from_initial(params, initial)?.with_frame(frame.clone()))
    }

    fn internal_steps(&self, _end: f64, h: f64) -> f64 {
        (h / self.params.max_substep).ceil() + wind::segment_count(&self.params, h)
    }

    fn advance(&mut self, _end: f64, h: f64) {
        self.step(h);
    }

    fn is_finite(&self) -> bool {
        Vehicle::is_finite(self)
    }

    fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        Quadrotor::save(self)
    }

    fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        Quadrotor::restore(bytes)
    }

    fn hybrid(&self) -> Option<&dyn Hybrid> {
        Some(self)
    }

    fn hybrid_mut(&mut self) -> Option<&mut dyn Hybrid> {
        Some(self)
    }
}

impl Hybrid for Quadrotor {
    fn states(&self, x: &mut [f64]) {
        x.copy_from_slice(&self.continuous_state());
    }

    fn set_states(&mut self, x: &[f64]) -> Result<(), FmuError> {
        self.set_continuous_state(x).map_err(|e| match e {
            CommandError::NotFinite(e) => {
                let name = state_name(self, e.index);
                FmuError::InvalidArgument(format!(
                    "x[{}] (state `{name}`) is {}, not a finite number; nothing was set",
                    e.index,
                    Compact(e.value)
                ))
            }
            e => FmuError::InvalidArgument(format!("{e}; nothing was set")),
        })
    }

    fn derivatives(&self, dx: &mut [f64]) {
        dx.copy_from_slice(&self.state_derivative());
    }

    fn event_indicators(&self, z: &mut [f64]) {
        z.copy_from_slice(&Quadrotor::event_indicators(self));
    }

    fn time_event_after(&self) -> Option<f64> {
        self.time_to_turbulence_sample()
    }

    fn event_update(&mut self, elapsed: f64) -> bool {
        let before = self.continuous_state();
        Quadrotor::event_update(self, elapsed);
        let after = self.continuous_state();
        before
            .iter()
            .zip(&after)
            .any(|(a, b)| a.to_bits() != b.to_bits())
    }
}
