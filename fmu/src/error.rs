//! Why an FMI call was refused. Every variant becomes a status for the caller and a log
//! message that says what to do about it.

use crate::fmi2_types::fmi2Status;
use crate::instance::Stage;
use flyloop_core::{ParamError, SnapshotError};
use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub enum FmuError {
    /// The function is not allowed in the instance's current stage.
    IllegalCall { stage: Stage, allowed: &'static str },
    /// A required pointer argument is NULL.
    NullArgument(&'static str),
    /// An argument with a value the function cannot use.
    InvalidArgument(String),
    /// No variable has this value reference.
    UnknownValueReference(u32),
    /// The variable exists but has another type than the function's.
    WrongType {
        name: &'static str,
        vr: u32,
        actual: &'static str,
        requested: &'static str,
    },
    /// The variable exists but cannot be set now (an output, or a fixed parameter after
    /// initialisation).
    NotSettable {
        name: &'static str,
        reason: &'static str,
    },
    /// The model refused a value (out of range, NaN, wrong kind, a broken relation).
    Refused(ParamError),
    /// An FMU state that does not decode or does not fit this model.
    State(SnapshotError),
    /// An fmi2FMUstate pointer this instance did not hand out, or has freed already.
    UnknownState,
    /// `fmi2DoStep`'s currentCommunicationPoint is not the instance's time.
    CommunicationPoint {
        given: f64,
        expected: f64,
        tolerance: f64,
    },
    /// `fmi2DoStep`'s communicationStepSize is not a positive finite number.
    StepSize(f64),
    /// The step would end after the stop time given in fmi2SetupExperiment.
    PastStopTime { end: f64, stop: f64 },
    /// The step would take more internal steps than a call should run.
    TooManySteps { steps: f64, limit: f64 },
    /// The dynamics produced a non-finite state; the instance stops in the Error stage.
    Diverged { time: f64 },
    /// A capability this FMU does not declare (Model Exchange, input interpolation, ...).
    NotSupported(&'static str),
}

impl FmuError {
    /// The status the caller gets.
    pub fn status(&self) -> fmi2Status {
        fmi2Status::fmi2Error
    }

    /// Whether the instance can no longer step (only get, reset, set state, free).
    pub fn enters_error_stage(&self) -> bool {
        matches!(self, FmuError::Diverged { .. })
    }
}

impl fmt::Display for FmuError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FmuError::IllegalCall { stage, allowed } => write!(
                f,
                "Illegal call sequence: the instance is in stage {stage:?}; \
                 this function is allowed only in {allowed}"
            ),
            FmuError::NullArgument(name) => write!(f, "argument `{name}` is NULL"),
            FmuError::InvalidArgument(message) => write!(f, "{message}"),
            FmuError::UnknownValueReference(vr) => {
                write!(f, "unknown value reference {vr} (see modelDescription.xml)")
            }
            FmuError::WrongType {
                name,
                vr,
                actual,
                requested,
            } => write!(
                f,
                "variable `{name}` (value reference {vr}) is of type {actual}, not {requested}: \
                 use fmi2Get{actual}/fmi2Set{actual}"
            ),
            FmuError::NotSettable { name, reason } => {
                write!(f, "variable `{name}` cannot be set: {reason}")
            }
            FmuError::Refused(e) => write!(f, "value refused: {e}"),
            FmuError::State(e) => write!(f, "FMU state refused: {e}"),
            FmuError::UnknownState => write!(
                f,
                "the FMU state is not a live state of this instance \
                 (freed already, or from another instance)"
            ),
            FmuError::CommunicationPoint {
                given,
                expected,
                tolerance,
            } => write!(
                f,
                "currentCommunicationPoint {given} does not match the instance's time \
                 {expected} (tolerance {tolerance:e}); steps must follow each other, \
                 or restore an FMU state first"
            ),
            FmuError::StepSize(h) => write!(
                f,
                "communicationStepSize must be a positive finite number, got {h}"
            ),
            FmuError::PastStopTime { end, stop } => write!(
                f,
                "the step would end at {end}, after the stop time {stop} set in \
                 fmi2SetupExperiment"
            ),
            FmuError::TooManySteps { steps, limit } => write!(
                f,
                "the step would take {steps} internal steps (limit {limit}); \
                 use smaller communication steps"
            ),
            FmuError::Diverged { time } => write!(
                f,
                "the model state became non-finite at t = {time}; the instance is in the \
                 Error stage (fmi2Reset or fmi2SetFMUstate to go on)"
            ),
            FmuError::NotSupported(what) => write!(f, "not supported: {what}"),
        }
    }
}

impl std::error::Error for FmuError {}

impl From<ParamError> for FmuError {
    fn from(e: ParamError) -> Self {
        match e {
            ParamError::UnknownValueReference(vr) => FmuError::UnknownValueReference(vr),
            other => FmuError::Refused(other),
        }
    }
}

impl From<SnapshotError> for FmuError {
    fn from(e: SnapshotError) -> Self {
        FmuError::State(e)
    }
}
