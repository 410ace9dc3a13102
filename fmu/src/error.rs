//! Why an FMI call was refused. Every variant becomes a status for the caller and a log
//! message that says what to do about it.

use flyloop_core::number::Compact;
use flyloop_core::{ParamError, SnapshotError};

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FmuError {
    #[error(
        "Illegal call sequence: the instance is in stage {stage}; \
         this function is allowed only in {allowed}"
    )]
    IllegalCall { stage: String, allowed: String },
    #[error("argument `{0}` is NULL")]
    NullArgument(&'static str),
    #[error("{0}")]
    InvalidArgument(String),
    #[error("unknown value reference {0} (see modelDescription.xml)")]
    UnknownValueReference(u32),
    #[error(
        "variable `{name}` (value reference {vr}) is of type {actual}, not {requested}: \
         use {api}Get{actual}/{api}Set{actual}"
    )]
    WrongType {
        name: &'static str,
        vr: u32,
        actual: &'static str,
        requested: &'static str,
        /// "fmi2" or "fmi3": the function prefix of the caller's FMI version.
        api: &'static str,
    },
    /// The variable exists but cannot be set now (an output, or a fixed parameter after
    /// initialisation).
    #[error("variable `{name}` cannot be set: {reason}")]
    NotSettable {
        name: &'static str,
        reason: &'static str,
    },
    /// The model refused a value (out of range, NaN, wrong kind, a broken relation).
    #[error("value refused: {0}")]
    Refused(#[from] ParamError),
    /// An FMU state that does not decode or does not fit this model.
    #[error("FMU state refused: {0}")]
    State(#[from] SnapshotError),
    /// An fmi2FMUstate pointer this instance did not hand out, or has freed already.
    #[error(
        "the FMU state is not a live state of this instance \
         (freed already, or from another instance)"
    )]
    UnknownState,
    #[error(
        "currentCommunicationPoint {g} does not match the instance's time \
         {e} (tolerance {t}); steps must follow each other, \
         or restore an FMU state first",
        g = Compact(*.given),
        e = Compact(*.expected),
        t = Compact(*.tolerance)
    )]
    CommunicationPoint {
        given: f64,
        expected: f64,
        tolerance: f64,
    },
    #[error(
        "communicationStepSize must be a positive finite number, got {}",
        Compact(*.0)
    )]
    StepSize(f64),
    #[error(
        "the step would end at {e}, after the stop time {s} set in \
         fmi2SetupExperiment",
        e = Compact(*.end),
        s = Compact(*.stop)
    )]
    PastStopTime { end: f64, stop: f64 },
    #[error(
        "the step would take {s} internal steps (limit {l}); \
         use smaller communication steps",
        s = Compact(*.steps),
        l = Compact(*.limit)
    )]
    TooManySteps { steps: f64, limit: f64 },
    #[error(
        "the model state became non-finite at t = {t}; the instance is in the \
         Error stage (reset it or set an FMU state to go on)",
        t = Compact(*.time)
    )]
    Diverged { time: f64 },
    /// A capability this FMU does not declare (Model Exchange, input interpolation, ...).
    #[error("not supported: {0}")]
    NotSupported(&'static str),
}
