//! An FMU instance (what an `fmi2Component` points to) and the FMI 2.0 state machine of
//! Co-Simulation and Model Exchange: the stage it is in and, per function, the stages it may
//! be called in (the masks of modelica/Reference-FMUs' fmi2Functions.c).

use crate::api::Api;
use crate::engine::Simulation;
use crate::error::FmuError;
use crate::fmi2_types::fmi2Status;
use crate::log::{Logger, category_of};
use std::collections::HashMap;

/// The stages of an instance: EventMode and ContinuousTimeMode for Model Exchange, the Step*
/// stages for Co-Simulation, the others for both. `Fatal` is entered after a caught panic:
/// only fmi2FreeInstance is allowed then.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u16)]
pub enum Stage {
    Instantiated = 1 << 1,
    InitializationMode = 1 << 2,
    StepComplete = 1 << 3,
    StepInProgress = 1 << 4,
    StepFailed = 1 << 5,
    StepCanceled = 1 << 6,
    Terminated = 1 << 7,
    Error = 1 << 8,
    Fatal = 1 << 9,
    EventMode = 1 << 10,
    ContinuousTimeMode = 1 << 11,
}

impl Stage {
    const ALL: [Stage; 11] = [
        Stage::Instantiated,
        Stage::InitializationMode,
        Stage::StepComplete,
        Stage::StepInProgress,
        Stage::StepFailed,
        Stage::StepCanceled,
        Stage::Terminated,
        Stage::Error,
        Stage::Fatal,
        Stage::EventMode,
        Stage::ContinuousTimeMode,
    ];

    /// The stage's code in FMU state bytes.
    pub fn code(self) -> u8 {
        (self as u16).trailing_zeros() as u8
    }

    pub fn from_code(code: u8) -> Option<Stage> {
        Stage::ALL.into_iter().find(|s| s.code() == code)
    }

    pub fn belongs_to(self, interface: Interface) -> bool {
        let model_exchange = matches!(self, Stage::EventMode | Stage::ContinuousTimeMode);
        let co_simulation = matches!(
            self,
            Stage::StepComplete | Stage::StepInProgress | Stage::StepFailed | Stage::StepCanceled
        );
        match interface {
            Interface::CoSimulation => !model_exchange,
            Interface::ModelExchange => !co_simulation,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interface {
    CoSimulation,
    ModelExchange,
}

/// The stages a function may be called in, and whether it is a Model Exchange function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Mask {
    bits: u16,
    /// For the "Illegal call sequence" message.
    pub names: &'static str,
    /// Refused on a Co-Simulation instance (Model Exchange shares InitializationMode and
    /// Terminated with Co-Simulation, so the stage alone does not tell).
    model_exchange: bool,
}

impl Mask {
    pub fn allows(self, stage: Stage) -> bool {
        self.bits & stage as u16 != 0
    }

    const fn model_exchange(self) -> Mask {
        Mask {
            model_exchange: true,
            ..self
        }
    }
}

macro_rules! mask {
    ($first:ident $(| $rest:ident)*) => {
        Mask {
            bits: Stage::$first as u16 $(| Stage::$rest as u16)*,
            names: concat!(stringify!($first) $(, ", ", stringify!($rest))*),
            model_exchange: false,
        }
    };
}

/// A table of masks, one a line (rustfmt leaves it as a table).
macro_rules! masks {
    ($($(#[doc = $doc:literal])* $name:ident = $mask:expr;)*) => {$(
        $(#[doc = $doc])*
        pub const $name: Mask = $mask;
    )*};
}

/// Per-function masks, as in Reference-FMUs' fmi2Functions.c.
pub mod masks {
    use super::{Mask, Stage};

    masks! {
        SET_DEBUG_LOGGING = mask!(Instantiated | InitializationMode | EventMode | ContinuousTimeMode
            | StepComplete | StepInProgress | StepFailed | StepCanceled | Terminated | Error);
        FREE_INSTANCE = mask!(Instantiated | InitializationMode | EventMode | ContinuousTimeMode
            | StepComplete | StepFailed | StepCanceled | Terminated | Error | Fatal);
        SETUP_EXPERIMENT = mask!(Instantiated);
        ENTER_INITIALIZATION_MODE = mask!(Instantiated);
        EXIT_INITIALIZATION_MODE = mask!(InitializationMode);
        TERMINATE = mask!(EventMode | ContinuousTimeMode | StepComplete | StepFailed);
        RESET = mask!(Instantiated | InitializationMode | EventMode | ContinuousTimeMode
            | StepComplete | StepFailed | StepCanceled | Terminated | Error);
        GET_VALUE = mask!(InitializationMode | EventMode | ContinuousTimeMode | StepComplete
            | StepFailed | StepCanceled | Terminated | Error);
        SET_REAL = mask!(Instantiated | InitializationMode | EventMode | ContinuousTimeMode
            | StepComplete);
        SET_OTHER = mask!(Instantiated | InitializationMode | EventMode | StepComplete);
        FMU_STATE = RESET;
        DIRECTIONAL_DERIVATIVE = GET_VALUE;
        SET_REAL_INPUT_DERIVATIVES = mask!(Instantiated | InitializationMode | StepComplete);
        GET_REAL_OUTPUT_DERIVATIVES = mask!(StepComplete | StepFailed | StepCanceled | Terminated
            | Error);
        DO_STEP = mask!(StepComplete);
        CANCEL_STEP = mask!(StepInProgress);
        GET_STATUS = mask!(StepComplete | StepInProgress | StepFailed | Terminated);
        // Model Exchange.
        ENTER_EVENT_MODE = mask!(EventMode | ContinuousTimeMode).model_exchange();
        NEW_DISCRETE_STATES = mask!(EventMode).model_exchange();
        ENTER_CONTINUOUS_TIME_MODE = mask!(EventMode).model_exchange();
        COMPLETED_INTEGRATOR_STEP = mask!(ContinuousTimeMode).model_exchange();
        SET_TIME = mask!(EventMode | ContinuousTimeMode).model_exchange();
        SET_CONTINUOUS_STATES = mask!(ContinuousTimeMode).model_exchange();
        GET_EVENT_INDICATORS = mask!(InitializationMode | EventMode | ContinuousTimeMode
            | Terminated | Error).model_exchange();
        GET_CONTINUOUS_STATES = GET_EVENT_INDICATORS;
        GET_DERIVATIVES = mask!(EventMode | ContinuousTimeMode | Terminated | Error)
            .model_exchange();
        GET_NOMINALS = mask!(Instantiated | EventMode | ContinuousTimeMode | Terminated | Error)
            .model_exchange();
    }
}

/// Per-function masks of FMI 3.0 (Reference-FMUs' fmi3Functions.c), in the stages of
/// [`Stage`]: FMI 3.0's StepMode is `StepComplete`. Functions with the same mask as in FMI
/// 2.0 use [`masks`].
pub mod masks3 {
    use super::{Mask, Stage};

    masks! {
        /// FMI 3.0 allows reading in every stage but the step in progress.
        GET_VALUE = mask!(Instantiated | InitializationMode | EventMode | ContinuousTimeMode
            | StepComplete | StepFailed | StepCanceled | Terminated | Error);
        ENTER_STEP_MODE = mask!(InitializationMode | EventMode);
        GET_OUTPUT_DERIVATIVES = mask!(StepComplete | StepFailed | Terminated);
        UPDATE_DISCRETE_STATES = mask!(EventMode).model_exchange();
        /// FMI 3.0 allows derivatives in initialization mode too: the event indicators' stages.
        GET_DERIVATIVES = super::masks::GET_EVENT_INDICATORS;
        /// Functions that ask nothing of the stage (counts, unsupported capabilities): every
        /// stage but Fatal, as for fmi2SetDebugLogging.
        ANY = super::masks::SET_DEBUG_LOGGING;
    }
}

/// A saved FMU state: the bytes of [`Simulation::save`]. Boxed; the box's address is the
/// `fmi2FMUstate` the importer holds.
#[derive(Debug)]
pub struct SavedState {
    pub bytes: Vec<u8>,
}

#[derive(Debug)]
pub struct Instance {
    pub api: Api,
    pub interface: Interface,
    pub logger: Logger,
    /// Whether each category (by its position in [`crate::log::CATEGORIES`]) is logged.
    pub logging: [bool; 4],
    pub stage: Stage,
    pub sim: Box<dyn Simulation>,
    /// FMU states handed out and not yet freed, by address. A pointer that is not here is
    /// refused instead of dereferenced (double free, foreign pointer).
    pub(crate) states: HashMap<usize, Box<SavedState>>,
}

impl Instance {
    /// Whether the instance is past initialization mode (fixed parameters are fixed now).
    pub fn initialised(&self) -> bool {
        !matches!(self.stage, Stage::Instantiated | Stage::InitializationMode)
    }

    pub fn log(&self, status: fmi2Status, message: &str) {
        if self.logging[category_of(status)] {
            self.logger.log(status, message);
        }
    }

    pub fn event(&self, message: &str) {
        self.log(fmi2Status::fmi2OK, message);
    }

    /// Moves to `stage` and logs `message` as an event.
    pub fn enter(&mut self, stage: Stage, message: &str) -> Result<(), FmuError> {
        self.stage = stage;
        self.event(message);
        Ok(())
    }

    /// Logs why `function` failed.
    pub fn report(&mut self, function: &str, error: &FmuError) -> fmi2Status {
        // A diverged model can no longer step (only get, reset, set state, free).
        if matches!(error, FmuError::Diverged { .. }) {
            self.stage = Stage::Error;
        }
        self.log(fmi2Status::fmi2Error, &format!("{function}: {error}"));
        fmi2Status::fmi2Error
    }

    pub fn check_stage(&self, mask: Mask) -> Result<(), FmuError> {
        if !mask.allows(self.stage) {
            return Err(FmuError::IllegalCall {
                stage: self.api.stage_name(&format!("{:?}", self.stage)),
                allowed: self.api.stage_name(mask.names),
            });
        }
        if mask.model_exchange && self.interface == Interface::CoSimulation {
            return Err(FmuError::NotSupported(match self.api {
                Api::Fmi2 => {
                    "Model Exchange functions on a Co-Simulation instance (instantiate with \
                     fmuType fmi2ModelExchange)"
                }
                Api::Fmi3 => {
                    "Model Exchange functions on a Co-Simulation instance (instantiate with \
                     fmi3InstantiateModelExchange)"
                }
            }));
        }
        Ok(())
    }

    /// The stage saved as `code`, if an instance of this interface can be in it.
    pub fn stage_from_code(&self, code: u8) -> Result<Stage, FmuError> {
        let stage = Stage::from_code(code).ok_or_else(|| {
            FmuError::InvalidArgument(format!("the FMU state holds an unknown stage code {code}"))
        })?;
        if !stage.belongs_to(self.interface) {
            return Err(FmuError::InvalidArgument(format!(
                "the FMU state was saved in stage {stage:?}, which a {:?} instance never is in",
                self.interface
            )));
        }
        Ok(stage)
    }

    /// Keeps `bytes` as a new state (`existing` 0) or in the live state at `existing`;
    /// returns the state's address for the importer.
    pub fn keep_state(
        &mut self,
        existing: usize,
        bytes: Vec<u8>,
    ) -> Result<*mut SavedState, FmuError> {
        if existing != 0 {
            let state = self
                .states
                .get_mut(&existing)
                .ok_or(FmuError::UnknownState)?;
            state.bytes = bytes;
            return Ok(&mut **state);
        }
        let mut boxed = Box::new(SavedState { bytes });
        let address: *mut SavedState = &mut *boxed;
        self.states.insert(address as usize, boxed);
        Ok(address)
    }

    pub fn state(&self, address: usize) -> Result<&SavedState, FmuError> {
        self.states
            .get(&address)
            .map(|b| &**b)
            .ok_or(FmuError::UnknownState)
    }

    pub fn release_state(&mut self, address: usize) -> Result<(), FmuError> {
        self.states
            .remove(&address)
            .map(drop)
            .ok_or(FmuError::UnknownState)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stage_codes_round_trip_and_masks_name_their_stages() {
        for stage in Stage::ALL {
            assert_eq!(Stage::from_code(stage.code()), Some(stage));
        }
        assert_eq!(Stage::from_code(0), None);
        assert_eq!(Stage::from_code(200), None);
        assert!(masks::DO_STEP.allows(Stage::StepComplete));
        assert!(!masks::DO_STEP.allows(Stage::Instantiated));
        assert!(masks::FREE_INSTANCE.allows(Stage::Fatal));
        assert!(!masks::RESET.allows(Stage::Fatal));
        assert_eq!(
            masks::TERMINATE.names,
            "EventMode, ContinuousTimeMode, StepComplete, StepFailed"
        );
        assert!(Stage::EventMode.belongs_to(Interface::ModelExchange));
        assert!(!Stage::EventMode.belongs_to(Interface::CoSimulation));
        assert!(!Stage::StepComplete.belongs_to(Interface::ModelExchange));
        assert!(Stage::Terminated.belongs_to(Interface::ModelExchange));
    }
}
