//! The model-independent part of an FMU instance below the state machine: start values,
//! the experiment, the time grid, variable access by type and causality, communication
//! steps and FMU states. [`Engine`] does it for any [`FmuModel`]; the instance sees it
//! through the object-safe [`Simulation`] so one library serves every model.

use crate::error::FmuError;
use crate::model::{FmuModel, ModelTable, StepRequest, settable_after_initialisation};
use crate::state_record;
use flyloop_core::SnapshotError;
use flyloop_core::number::Compact;
use flyloop_core::params::ValueKind;
use flyloop_core::variables::Causality;
use serde::{Deserialize, Serialize};

/// A communication point matches the instance's time within this fraction of max(1 s, |t|)
/// (an importer that sums its steps drifts by far less over millions of steps).
pub const TIME_TOLERANCE: f64 = 1e-9;

/// A communication step size within this fraction of the previous one continues the grid
/// with the previous size: importers compute h as a difference of grid times, which jitters
/// by a few ulps (0.02 - 0.01 != 0.01), and the model should not see that jitter.
pub const STEP_TOLERANCE: f64 = 1e-9;

/// A single fmi2DoStep may run at most this many internal steps (≈ tens of seconds of CPU).
pub const MAX_INTERNAL_STEPS: f64 = 1e8;

/// The type an fmi2Get*/fmi2Set* or fmi3Get*/fmi3Set* function works with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FmiType {
    Real,
    Integer,
    Boolean,
    String,
    Float64,
    Int32,
    Boolean3,
    /// An FMI 3.0 type no variable has (Float32, Int8, ..., String, Binary), by name.
    Other3(&'static str),
}

impl FmiType {
    fn name(self) -> &'static str {
        match self {
            FmiType::Real => "Real",
            FmiType::Integer => "Integer",
            FmiType::Boolean | FmiType::Boolean3 => "Boolean",
            FmiType::String => "String",
            FmiType::Float64 => "Float64",
            FmiType::Int32 => "Int32",
            FmiType::Other3(name) => name,
        }
    }

    fn is_fmi3(self) -> bool {
        matches!(
            self,
            FmiType::Float64 | FmiType::Int32 | FmiType::Boolean3 | FmiType::Other3(_)
        )
    }

    /// The type of this FMI version that reads a variable of `kind`.
    fn for_kind(self, kind: ValueKind) -> FmiType {
        match (self.is_fmi3(), kind) {
            (false, ValueKind::Real) => FmiType::Real,
            (false, ValueKind::Integer) => FmiType::Integer,
            (false, ValueKind::Boolean) => FmiType::Boolean,
            (true, ValueKind::Real) => FmiType::Float64,
            (true, ValueKind::Integer) => FmiType::Int32,
            (true, ValueKind::Boolean) => FmiType::Boolean3,
        }
    }

    pub(crate) fn matches(self, kind: ValueKind) -> bool {
        self.for_kind(kind) == self
    }

    /// The error for a variable of another type than this function's.
    pub fn mismatch(self, name: &'static str, vr: u32, kind: ValueKind) -> FmuError {
        FmuError::WrongType {
            name,
            vr,
            actual: self.for_kind(kind).name(),
            requested: self.name(),
            api: if self.is_fmi3() { "fmi3" } else { "fmi2" },
        }
    }
}

/// The time grid: t = base + n·h while the step size stays h, so time is never a running
/// sum. A new step size starts a new segment at the current time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Clock {
    base: f64,
    step: f64,
    n: u64,
}

impl Clock {
    pub fn at(time: f64) -> Self {
        Clock {
            base: time,
            step: 0.0,
            n: 0,
        }
    }

    pub fn time(&self) -> f64 {
        if self.n == 0 {
            self.base
        } else {
            self.base + self.n as f64 * self.step
        }
    }

    /// The step size to use for a requested `h`: the grid's own step when `h` is within
    /// [`STEP_TOLERANCE`] of it, else `h`.
    pub fn grid_step(&self, h: f64) -> f64 {
        if self.n > 0 && (h - self.step).abs() <= STEP_TOLERANCE * self.step {
            self.step
        } else {
            h
        }
    }

    /// The clock after one more step of `h`.
    pub fn after(&self, h: f64) -> Clock {
        if self.n > 0 && self.step.to_bits() == h.to_bits() {
            Clock {
                n: self.n + 1,
                ..*self
            }
        } else {
            Clock {
                base: self.time(),
                step: h,
                n: 1,
            }
        }
    }
}

/// What fmi2SetupExperiment said.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Experiment {
    pub start: f64,
    pub stop: Option<f64>,
}

impl Default for Experiment {
    fn default() -> Self {
        Experiment {
            start: 0.0,
            stop: None,
        }
    }
}

/// The instance's simulation as the FMI functions drive it.
pub trait Simulation {
    fn table(&self) -> &'static ModelTable;
    /// fmi2SetupExperiment.
    fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Result<(), FmuError>;
    /// Reads `vr` through a function of type `ty`.
    fn get(&self, vr: u32, ty: FmiType) -> Result<f64, FmuError>;
    /// Writes `vr` through a function of type `ty`; `initialised` once past
    /// fmi2ExitInitializationMode.
    fn set(&mut self, vr: u32, ty: FmiType, value: f64, initialised: bool) -> Result<(), FmuError>;
    /// fmi2DoStep.
    fn do_step(&mut self, communication_point: f64, step_size: f64) -> Result<(), FmuError>;
    /// The instance's time, s.
    fn time(&self) -> f64;
    /// Back to the start values (fmi2Reset).
    fn reset(&mut self) -> Result<(), FmuError>;
    /// Everything, with the caller's `stage` code, as FMU state bytes.
    fn save(&self, stage: u8) -> Result<Vec<u8>, FmuError>;
    /// Checks that `bytes` are a state of this model, without applying them; returns the
    /// stage code saved with them.
    fn check_saved(&self, bytes: &[u8]) -> Result<u8, FmuError>;
    /// Applies state bytes; returns the stage code saved with them. Nothing changes on error.
    fn restore(&mut self, bytes: &[u8]) -> Result<u8, FmuError>;

    // Model Exchange (see `crate::exchange`); each is an error for a Co-Simulation-only model.
    /// fmi2SetTime.
    fn set_time(&mut self, time: f64) -> Result<(), FmuError>;
    /// fmi2GetContinuousStates.
    fn continuous_states(&self, x: &mut [f64]) -> Result<(), FmuError>;
    /// fmi2SetContinuousStates; nothing changes when a value is refused.
    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), FmuError>;
    /// fmi2GetDerivatives.
    fn derivatives(&self, dx: &mut [f64]) -> Result<(), FmuError>;
    /// fmi2GetEventIndicators.
    fn event_indicators(&self, z: &mut [f64]) -> Result<(), FmuError>;
    /// fmi2GetNominalsOfContinuousStates.
    fn nominals(&self, nominals: &mut [f64]) -> Result<(), FmuError>;
    /// fmi2NewDiscreteStates: the discrete changes of an event at the current time. Returns
    /// whether the continuous states changed, and the next time event (absolute time).
    fn new_discrete_states(&mut self) -> Result<(bool, Option<f64>), FmuError>;
    /// fmi2CompletedIntegratorStep: an error once the state is no longer finite.
    fn completed_integrator_step(&self) -> Result<(), FmuError>;
}

/// [`Simulation`] for one model type.
#[derive(Debug)]
pub struct Engine<M: FmuModel> {
    model: M,
    initial: M::Initial,
    /// Inputs set before initialisation, applied again whenever start values rebuild the
    /// model (a rebuild would otherwise put them back to the model's defaults).
    early_inputs: Vec<(u32, f64)>,
    experiment: Experiment,
    clock: Clock,
    /// Model Exchange: time of the last event (its discrete changes are done up to here).
    pub(crate) event_time: f64,
}

/// An FMU state: which model it belongs to (readable for any model, so that a state of
/// another model is named as such) around the model-specific part.
#[derive(Serialize, Deserialize)]
struct Record {
    guid: String,
    stage: u8,
    /// postcard of [`Body`].
    body: Vec<u8>,
}

/// The model-specific part of an FMU state.
#[derive(Serialize, Deserialize)]
struct Body<I> {
    initial: I,
    early_inputs: Vec<(u32, f64)>,
    experiment: Experiment,
    clock: Clock,
    event_time: f64,
    /// The model's own snapshot (the core's format, with its own checks).
    model: Vec<u8>,
}

impl<M: FmuModel> Engine<M> {
    /// An instance at its start values.
    pub fn new() -> Result<Self, FmuError> {
        let initial = M::Initial::default();
        Ok(Engine {
            model: M::build(None, &initial)?,
            initial,
            early_inputs: Vec::new(),
            experiment: Experiment::default(),
            clock: Clock::at(0.0),
            event_time: 0.0,
        })
    }

    /// The model (for tests and benchmarks that compare with the core).
    pub fn model(&self) -> &M {
        &self.model
    }

    pub(crate) fn model_mut(&mut self) -> &mut M {
        &mut self.model
    }

    /// Model Exchange moves time by fmi2SetTime, not by steps.
    pub(crate) fn set_clock(&mut self, time: f64) {
        self.clock = Clock::at(time);
    }

    /// Rebuilds the model from the start values, keeping the inputs set so far.
    fn rebuild(&mut self) -> Result<(), FmuError> {
        let mut model = M::build(Some(&self.model), &self.initial)?;
        for &(vr, value) in &self.early_inputs {
            model.set(&mut self.initial, vr, value)?;
        }
        self.model = model;
        Ok(())
    }

    /// Decodes FMU state bytes completely: stage code, bookkeeping and a restored model.
    fn decode(bytes: &[u8]) -> Result<(u8, Body<M::Initial>, M), FmuError> {
        let record: Record = state_record::decode(bytes)?;
        let table = M::table();
        if record.guid != table.guid {
            return Err(FmuError::InvalidArgument(format!(
                "the FMU state belongs to a model with GUID {}, not to {} {}",
                record.guid, table.info.identifier, table.guid
            )));
        }
        let body: Body<M::Initial> = postcard::from_bytes(&record.body)
            .map_err(|e| FmuError::State(SnapshotError::Decode(e.to_string())))?;
        let model = M::restore(&body.model)?;
        Ok((record.stage, body, model))
    }
}

impl<M: FmuModel> Simulation for Engine<M> {
    fn table(&self) -> &'static ModelTable {
        M::table()
    }

    fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Result<(), FmuError> {
        if !start.is_finite() {
            return Err(FmuError::InvalidArgument(format!(
                "startTime must be finite, got {}",
                Compact(start)
            )));
        }
        if let Some(stop) = stop {
            if stop.is_nan() || stop < start {
                return Err(FmuError::InvalidArgument(format!(
                    "stopTime {} must not be before startTime {}",
                    Compact(stop),
                    Compact(start)
                )));
            }
        }
        self.experiment = Experiment { start, stop };
        self.clock = Clock::at(start);
        self.event_time = start;
        Ok(())
    }

    fn get(&self, vr: u32, ty: FmiType) -> Result<f64, FmuError> {
        let variable = M::table()
            .variable(vr)
            .ok_or(FmuError::UnknownValueReference(vr))?;
        if !ty.matches(variable.kind) {
            return Err(ty.mismatch(variable.name, vr, variable.kind));
        }
        Ok(self.model.get(&self.initial, vr)?)
    }

    fn set(&mut self, vr: u32, ty: FmiType, value: f64, initialised: bool) -> Result<(), FmuError> {
        let variable = M::table()
            .variable(vr)
            .ok_or(FmuError::UnknownValueReference(vr))?;
        if !ty.matches(variable.kind) {
            return Err(ty.mismatch(variable.name, vr, variable.kind));
        }
        let name = variable.name;
        match variable.causality {
            Causality::Output => {
                return Err(FmuError::NotSettable {
                    name,
                    reason: "it is an output",
                });
            }
            Causality::Parameter
                if initialised
                    && !settable_after_initialisation(variable.causality, variable.variability) =>
            {
                return Err(FmuError::NotSettable {
                    name,
                    reason: "it is a fixed parameter; set it before initialization mode ends",
                });
            }
            _ => {}
        }
        self.model.set(&mut self.initial, vr, value)?;
        if !initialised {
            if variable.causality == Causality::Input {
                self.early_inputs.retain(|&(v, _)| v != vr);
                self.early_inputs.push((vr, value));
            } else {
                self.rebuild()?;
            }
        }
        Ok(())
    }

    fn do_step(&mut self, communication_point: f64, step_size: f64) -> Result<(), FmuError> {
        if !(step_size > 0.0 && step_size.is_finite()) {
            return Err(FmuError::StepSize(step_size));
        }
        let now = self.clock.time();
        let tolerance = TIME_TOLERANCE * now.abs().max(1.0);
        let offset = (communication_point - now).abs();
        if offset.is_nan() || offset > tolerance {
            return Err(FmuError::CommunicationPoint {
                given: communication_point,
                expected: now,
                tolerance,
            });
        }
        let step_size = self.clock.grid_step(step_size);
        let next = self.clock.after(step_size);
        let end = next.time();
        if let Some(stop) = self.experiment.stop {
            if end > stop + TIME_TOLERANCE * stop.abs().max(1.0) {
                return Err(FmuError::PastStopTime { end, stop });
            }
        }
        let request = StepRequest {
            start_time: self.experiment.start,
            end_time: end,
            step_size,
        };
        let steps = self.model.internal_steps(&request);
        if steps.is_nan() || steps > MAX_INTERNAL_STEPS {
            return Err(FmuError::TooManySteps {
                steps,
                limit: MAX_INTERNAL_STEPS,
            });
        }
        self.model.advance(&request);
        self.clock = next;
        if !self.model.is_finite() {
            return Err(FmuError::Diverged { time: end });
        }
        Ok(())
    }

    fn time(&self) -> f64 {
        self.clock.time()
    }

    fn reset(&mut self) -> Result<(), FmuError> {
        *self = Engine::new()?;
        Ok(())
    }

    fn save(&self, stage: u8) -> Result<Vec<u8>, FmuError> {
        let body = Body {
            initial: self.initial.clone(),
            early_inputs: self.early_inputs.clone(),
            experiment: self.experiment,
            clock: self.clock,
            event_time: self.event_time,
            model: self.model.save()?,
        };
        let record = Record {
            guid: M::table().guid.clone(),
            stage,
            body: postcard::to_stdvec(&body)
                .map_err(|e| FmuError::State(SnapshotError::Encode(e.to_string())))?,
        };
        Ok(state_record::encode(&record)?)
    }

    fn check_saved(&self, bytes: &[u8]) -> Result<u8, FmuError> {
        Self::decode(bytes).map(|(stage, _, _)| stage)
    }

    fn restore(&mut self, bytes: &[u8]) -> Result<u8, FmuError> {
        let (stage, body, model) = Self::decode(bytes)?;
        *self = Engine {
            model,
            initial: body.initial,
            early_inputs: body.early_inputs,
            experiment: body.experiment,
            clock: body.clock,
            event_time: body.event_time,
        };
        Ok(stage)
    }

    fn set_time(&mut self, time: f64) -> Result<(), FmuError> {
        crate::exchange::set_time(self, time)
    }

    fn continuous_states(&self, x: &mut [f64]) -> Result<(), FmuError> {
        crate::exchange::hybrid(self, x.len(), "nx")?.states(x);
        Ok(())
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), FmuError> {
        crate::exchange::hybrid(self, x.len(), "nx")?;
        crate::exchange::hybrid_mut(self)?.set_states(x)
    }

    fn derivatives(&self, dx: &mut [f64]) -> Result<(), FmuError> {
        crate::exchange::hybrid(self, dx.len(), "nx")?.derivatives(dx);
        Ok(())
    }

    fn event_indicators(&self, z: &mut [f64]) -> Result<(), FmuError> {
        crate::exchange::event_indicators(self, z)
    }

    fn nominals(&self, nominals: &mut [f64]) -> Result<(), FmuError> {
        crate::exchange::hybrid(self, nominals.len(), "nx")?;
        nominals.fill(1.0);
        Ok(())
    }

    fn new_discrete_states(&mut self) -> Result<(bool, Option<f64>), FmuError> {
        crate::exchange::new_discrete_states(self)
    }

    fn completed_integrator_step(&self) -> Result<(), FmuError> {
        if self.model.is_finite() {
            Ok(())
        } else {
            Err(FmuError::Diverged {
                time: self.clock.time(),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clock_is_t0_plus_n_h_and_restarts_on_a_new_step_size() {
        let mut clock = Clock::at(0.5);
        for _ in 0..1000 {
            clock = clock.after(0.001);
        }
        assert_eq!(clock.time(), 0.5 + 1000.0 * 0.001);
        // Summing drifts; the grid does not.
        let summed = (0..1000).fold(0.5, |t, _| t + 0.001);
        assert_ne!(summed, clock.time());
        let t = clock.time();
        clock = clock.after(0.25);
        assert_eq!(clock.time(), t + 0.25);
        clock = clock.after(0.25);
        assert_eq!(clock.time(), t + 2.0 * 0.25);
    }

    #[test]
    fn step_sizes_that_differ_by_rounding_continue_the_grid() {
        let clock = Clock::at(0.0).after(0.01);
        // What an importer computes for its second step.
        let jittered = 0.03 - 0.02;
        assert_ne!(jittered, 0.01);
        assert_eq!(clock.grid_step(jittered), 0.01);
        assert_eq!(
            clock.grid_step(0.0100001),
            0.0100001,
            "a real change is kept"
        );
        assert_eq!(Clock::at(0.0).grid_step(jittered), jittered, "no grid yet");
    }
}
