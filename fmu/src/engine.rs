//! The model-independent part of an FMU instance below the state machine, for any
//! [`FmuModel`]; the instance sees it through the object-safe [`Simulation`] so one library
//! serves every model. Model Exchange keeps the time of the last event so that the model's
//! discrete changes happen at events only, never inside the solver's trial steps.

use crate::api::Api;
use crate::error::FmuError;
use crate::model::{Access, FmuModel, Hybrid, Table};
use crate::table::ModelTable;
use flyloop_core::number::Compact;
use flyloop_core::variables::{Causality, Variability};
use flyloop_core::{SnapshotError, snapshot};
use serde::{Deserialize, Serialize};

/// A communication point matches the instance's time within this fraction of max(1 s, |t|)
/// (an importer that sums its steps drifts by far less over millions of steps).
pub const TIME_TOLERANCE: f64 = 1e-9;

/// A communication step size within this fraction of the previous one continues the grid
/// with the previous size: importers compute h as a difference of grid times, which jitters
/// by a few ulps (0.02 - 0.01 != 0.01), and the model should not see that jitter.
pub const STEP_TOLERANCE: f64 = 1e-9;

/// At most this many internal steps in one fmi2DoStep (≈ tens of seconds of CPU).
pub const MAX_INTERNAL_STEPS: f64 = 1e8;

/// The time grid: t = base + n·h while the step size stays h, so time is never a running
/// sum. A new step size starts a new segment at the current time.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
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

    /// The grid's own step when `h` is within [`STEP_TOLERANCE`] of it, else `h`.
    pub fn grid_step(&self, h: f64) -> f64 {
        if self.n > 0 && (h - self.step).abs() <= STEP_TOLERANCE * self.step {
            self.step
        } else {
            h
        }
    }

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

/// The instance's simulation as the FMI functions drive it; a method named after an FMI
/// function (`do_step`, `set_time`...) is that function's work, `index` is a position in the
/// table, `stage` the instance's stage code saved in FMU states. The hybrid views and the
/// event update are an error for a Co-Simulation-only model.
pub trait Simulation: std::fmt::Debug {
    fn table(&self) -> &'static ModelTable;
    fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> Result<(), FmuError>;
    fn get(&self, index: usize) -> f64;
    fn set(&mut self, index: usize, value: f64, initialised: bool) -> Result<(), FmuError>;
    fn do_step(&mut self, communication_point: f64, step_size: f64) -> Result<(), FmuError>;
    fn time(&self) -> f64;
    fn reset(&mut self) -> Result<(), FmuError>;
    fn save(&self, stage: u8) -> Result<Vec<u8>, FmuError>;
    /// The stage code of state bytes of this model, without applying them.
    fn check_saved(&self, bytes: &[u8]) -> Result<u8, FmuError>;
    /// Applies state bytes and returns their stage code; nothing changes on error.
    fn restore(&mut self, bytes: &[u8]) -> Result<u8, FmuError>;
    fn set_time(&mut self, time: f64) -> Result<(), FmuError>;
    /// The model's hybrid view, after checking that the importer's array `name` of length
    /// `len` has one entry per continuous state (`ni`: per event indicator).
    fn hybrid(&self, len: usize, name: &str) -> Result<&dyn Hybrid, FmuError>;
    fn hybrid_mut(&mut self, len: usize, name: &str) -> Result<&mut dyn Hybrid, FmuError>;
    /// Whether the continuous states changed, and the next time event (absolute time).
    fn new_discrete_states(&mut self) -> Result<(bool, Option<f64>), FmuError>;
    fn completed_integrator_step(&self) -> Result<(), FmuError>;
}

#[derive(Debug)]
pub struct Engine<M: FmuModel> {
    /// The FMU's table: which FMU of the model this is.
    table: &'static Table<M>,
    model: M,
    book: Book<M::Initial>,
}

/// What an instance holds besides the model (all of it goes into FMU states).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct Book<I> {
    initial: I,
    /// Inputs set before initialisation, applied again whenever start values rebuild the
    /// model (a rebuild would otherwise put them back to the model's defaults).
    early_inputs: Vec<(u32, f64)>,
    /// The experiment's start and stop time.
    start: f64,
    stop: Option<f64>,
    clock: Clock,
    /// Model Exchange: time of the last event (its discrete changes are done up to here).
    event_time: f64,
}

fn co_simulation_only() -> FmuError {
    FmuError::NotSupported("Model Exchange: this model is Co-Simulation only")
}

/// An FMU state (fmi2GetFMUstate, fmi2SerializeFMUstate) in the core's snapshot envelope
/// (tag, length, checksum) under [`STATE_TAG`]: its model's GUID (readable for any model, so
/// that a state of another model is named as such) around the model-specific part.
#[derive(Serialize, Deserialize)]
struct Record {
    guid: String,
    stage: u8,
    /// postcard of [`Body`].
    body: Vec<u8>,
}

/// The model-specific part of an FMU state: the book, then the model's own snapshot.
type Body<I> = (Book<I>, Vec<u8>);

const STATE_TAG: &[u8; 8] = b"FLYFMI01";
const STATE_NAME: &str = "flyloop FMU state";

impl<M: FmuModel> Engine<M> {
    /// A fresh simulation of the FMU with `table`, built from the default start values,
    /// boxed as an instance holds it.
    pub fn start(table: &'static Table<M>) -> Result<Box<dyn Simulation>, FmuError> {
        let book = Book::<M::Initial>::default();
        let model = M::build(&table.shape, None, &book.initial)?;
        Ok(Box::new(Engine { table, model, book }))
    }

    /// Rebuilds the model from the start values, keeping the inputs set so far.
    fn rebuild(&mut self) -> Result<(), FmuError> {
        let book = &mut self.book;
        let rows = &self.table.rows;
        let mut model = M::build(&self.table.shape, Some(&self.model), &book.initial)?;
        for &(vr, value) in &book.early_inputs {
            rows.set(&mut model, &mut book.initial, vr, value)?;
        }
        self.model = model;
        Ok(())
    }

    /// Fails unless the model has Model Exchange and the importer's array `name` of length
    /// `len` has one entry per continuous state (`ni`: per event indicator).
    fn check_len(&self, len: usize, name: &str) -> Result<(), FmuError> {
        let table = &self.table.table;
        let me = table
            .model_exchange
            .as_ref()
            .ok_or_else(co_simulation_only)?;
        let (expected, what) = match name {
            "ni" => (me.event_indicators, "event indicators"),
            _ => (me.states.len(), "continuous states"),
        };
        if len != expected {
            return Err(FmuError::InvalidArgument(format!(
                "{name} = {len}, but {} has {expected} {what}",
                table.info.identifier,
            )));
        }
        Ok(())
    }

    /// The stage code, book and model snapshot of state bytes of this model.
    fn decode(&self, bytes: &[u8]) -> Result<(u8, Body<M::Initial>), FmuError> {
        let record: Record = snapshot::decode(STATE_TAG, STATE_NAME, bytes)?;
        let table = &self.table.table;
        if record.guid != table.token(Api::Fmi2) {
            return Err(FmuError::InvalidArgument(format!(
                "the FMU state belongs to a model with GUID {}, not to {} {}",
                record.guid,
                table.info.identifier,
                table.token(Api::Fmi2)
            )));
        }
        let body = postcard::from_bytes(&record.body)
            .map_err(|e| FmuError::State(SnapshotError::Decode(e.to_string())))?;
        Ok((record.stage, body))
    }

    /// The model in a state's snapshot, which must have this FMU's shape (its GUID said so;
    /// this checks what the model holds).
    fn restore_model(&self, bytes: &[u8]) -> Result<M, FmuError> {
        let model = M::restore(bytes)?;
        if *model.shape() != self.table.shape {
            return Err(FmuError::InvalidArgument(format!(
                "the FMU state holds a model of another shape than {}'s ({:?})",
                self.table.table.info.identifier,
                model.shape()
            )));
        }
        Ok(model)
    }
}

impl<M: FmuModel> Simulation for Engine<M> {
    fn table(&self) -> &'static ModelTable {
        &self.table.table
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
        (self.book.start, self.book.stop) = (start, stop);
        self.book.clock = Clock::at(start);
        self.book.event_time = start;
        Ok(())
    }

    fn get(&self, index: usize) -> f64 {
        let Table { rows, access, .. } = self.table;
        match access[index] {
            Access::Core(row) => rows.get_at(row, &self.model, &self.book.initial),
            Access::Local { read, at } => read(&self.model, at),
        }
    }

    fn set(&mut self, index: usize, value: f64, initialised: bool) -> Result<(), FmuError> {
        let Table {
            table,
            rows,
            access,
            ..
        } = self.table;
        let variable = &table.variables[index];
        let (name, vr) = (variable.name, variable.value_reference);
        match variable.causality {
            Causality::Output => {
                return Err(FmuError::NotSettable {
                    name,
                    reason: "it is an output",
                });
            }
            Causality::Parameter if initialised && variable.variability != Variability::Tunable => {
                return Err(FmuError::NotSettable {
                    name,
                    reason: "it is a fixed parameter; set it before initialization mode ends",
                });
            }
            _ => {}
        }
        let Access::Core(row) = access[index] else {
            return Err(FmuError::UnknownValueReference(vr));
        };
        rows.set_at(row, &mut self.model, &mut self.book.initial, value)?;
        if !initialised {
            if variable.causality == Causality::Input {
                self.book.early_inputs.retain(|&(v, _)| v != vr);
                self.book.early_inputs.push((vr, value));
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
        let now = self.time();
        let tolerance = TIME_TOLERANCE * now.abs().max(1.0);
        let offset = (communication_point - now).abs();
        if offset.is_nan() || offset > tolerance {
            return Err(FmuError::CommunicationPoint {
                given: communication_point,
                expected: now,
                tolerance,
            });
        }
        let step_size = self.book.clock.grid_step(step_size);
        let next = self.book.clock.after(step_size);
        let end = next.time();
        if let Some(stop) = self.book.stop {
            if end > stop + TIME_TOLERANCE * stop.abs().max(1.0) {
                return Err(FmuError::PastStopTime { end, stop });
            }
        }
        let since_start = end - self.book.start;
        let steps = self.model.internal_steps(since_start, step_size);
        if steps.is_nan() || steps > MAX_INTERNAL_STEPS {
            return Err(FmuError::TooManySteps {
                steps,
                limit: MAX_INTERNAL_STEPS,
            });
        }
        self.model.advance(since_start, step_size);
        self.book.clock = next;
        if !self.model.is_finite() {
            return Err(FmuError::Diverged { time: end });
        }
        Ok(())
    }

    fn time(&self) -> f64 {
        self.book.clock.time()
    }

    fn reset(&mut self) -> Result<(), FmuError> {
        let book = Book::<M::Initial>::default();
        self.model = M::build(&self.table.shape, None, &book.initial)?;
        self.book = book;
        Ok(())
    }

    fn save(&self, stage: u8) -> Result<Vec<u8>, FmuError> {
        let body: Body<M::Initial> = (self.book.clone(), self.model.save()?);
        let record = Record {
            guid: self.table.table.token(Api::Fmi2).to_string(),
            stage,
            body: postcard::to_stdvec(&body)
                .map_err(|e| FmuError::State(SnapshotError::Encode(e.to_string())))?,
        };
        Ok(snapshot::encode(STATE_TAG, &record)?)
    }

    fn check_saved(&self, bytes: &[u8]) -> Result<u8, FmuError> {
        let (stage, (_, model)) = self.decode(bytes)?;
        self.restore_model(&model)?;
        Ok(stage)
    }

    fn restore(&mut self, bytes: &[u8]) -> Result<u8, FmuError> {
        let (stage, (book, model)) = self.decode(bytes)?;
        let model = self.restore_model(&model)?;
        (self.model, self.book) = (model, book);
        Ok(stage)
    }

    /// A finite time not before the last event (a solver may go back within a step it
    /// rejects, never past an event it has handled).
    fn set_time(&mut self, time: f64) -> Result<(), FmuError> {
        let last = self.book.event_time;
        if !time.is_finite() || time < last - TIME_TOLERANCE * last.abs().max(1.0) {
            return Err(FmuError::InvalidArgument(format!(
                "time {} is not a finite time at or after the last event ({})",
                Compact(time),
                Compact(last)
            )));
        }
        self.book.clock = Clock::at(time);
        Ok(())
    }

    fn hybrid(&self, len: usize, name: &str) -> Result<&dyn Hybrid, FmuError> {
        self.check_len(len, name)?;
        self.model.hybrid().ok_or_else(co_simulation_only)
    }

    fn hybrid_mut(&mut self, len: usize, name: &str) -> Result<&mut dyn Hybrid, FmuError> {
        self.check_len(len, name)?;
        self.model.hybrid_mut().ok_or_else(co_simulation_only)
    }

    fn new_discrete_states(&mut self) -> Result<(bool, Option<f64>), FmuError> {
        let now = self.time();
        let elapsed = (now - self.book.event_time).max(0.0);
        let hybrid = self.model.hybrid_mut().ok_or_else(co_simulation_only)?;
        let changed = hybrid.event_update(elapsed);
        let next = hybrid.time_event_after().map(|dt| now + dt);
        self.book.event_time = now;
        Ok((changed, next))
    }

    fn completed_integrator_step(&self) -> Result<(), FmuError> {
        if self.model.is_finite() {
            Ok(())
        } else {
            Err(FmuError::Diverged { time: self.time() })
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

    #[test]
    fn states_are_in_the_envelope_under_the_fmu_tag_and_no_other() {
        let value = (7u8, -0.0f64, String::from("Quadrotor"), vec![1u8, 2, 3]);
        let bytes = snapshot::encode(STATE_TAG, &value).unwrap();
        assert_eq!(&bytes[..8], STATE_TAG);
        let back: (u8, f64, String, Vec<u8>) =
            snapshot::decode(STATE_TAG, STATE_NAME, &bytes).unwrap();
        assert_eq!(back.1.to_bits(), (-0.0f64).to_bits());
        // A core snapshot (another tag) is not an FMU state.
        let foreign = snapshot::encode(b"FLYQUA01", &value).unwrap();
        assert_eq!(
            snapshot::decode::<(u8, f64, String, Vec<u8>)>(STATE_TAG, STATE_NAME, &foreign),
            Err(SnapshotError::WrongFormat {
                expected: STATE_NAME
            })
        );
    }
}
