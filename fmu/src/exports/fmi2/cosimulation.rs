//! FMI 2.0 Co-Simulation: fmi2DoStep, the status queries, and the capabilities this FMU
//! declares absent (input interpolation, output derivatives, asynchronous steps, directional
//! derivatives), which answer fmi2Error with the reason.

use crate::error::FmuError;
use crate::exports::guard::{refuse, write_out};
use crate::fmi2_types::*;
use crate::instance::{Instance, masks};

/// The body of fmi2Get*Status: `known` is the status kind the function answers, with its
/// value; any other kind does not apply to a synchronous FMU that never discards.
///
/// # Safety
/// `value` must be NULL or writable.
unsafe fn status<T>(
    instance: &Instance,
    function: &str,
    s: fmi2StatusKind,
    value: *mut T,
    known: Option<(fmi2StatusKind, T)>,
) -> Result<fmi2Status, FmuError> {
    let why = match (s, known) {
        (s, Some((kind, known))) if s == kind => {
            // SAFETY: per the contract.
            unsafe { write_out(value, known, "value") }?;
            return Ok(fmi2Status::fmi2OK);
        }
        (fmi2DoStepStatus | fmi2PendingStatus, _) => "fmi2DoStep never returns fmi2Pending",
        (fmi2LastSuccessfulTime | fmi2Terminated, _) => "fmi2DoStep never returns fmi2Discard",
        (other, _) => {
            let message = format!("unknown fmi2StatusKind {other}");
            return Err(FmuError::InvalidArgument(message));
        }
    };
    let message = format!("{function}: status kind {s} does not apply: {why}");
    instance.log(fmi2Status::fmi2Discard, &message);
    Ok(fmi2Status::fmi2Discard)
}

forward! {
    fn fmi2GetStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Status) -> fmi2Status =
        masks::GET_STATUS => |i, f| status(i, f, s, value, None);
    /// fmi2LastSuccessfulTime gives the instance's time.
    fn fmi2GetRealStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Real) -> fmi2Status =
        masks::GET_STATUS => |i, f| {
            status(i, f, s, value, Some((fmi2LastSuccessfulTime, i.sim.time())))
        };
    fn fmi2GetIntegerStatus(
        c: fmi2Component,
        s: fmi2StatusKind,
        value: *mut fmi2Integer,
    ) -> fmi2Status = masks::GET_STATUS => |i, f| status(i, f, s, value, None);
    /// fmi2Terminated gives fmi2False: the models never ask to end the simulation.
    fn fmi2GetBooleanStatus(
        c: fmi2Component,
        s: fmi2StatusKind,
        value: *mut fmi2Boolean,
    ) -> fmi2Status =
        masks::GET_STATUS => |i, f| status(i, f, s, value, Some((fmi2Terminated, fmi2False)));
    fn fmi2GetStringStatus(
        c: fmi2Component,
        s: fmi2StatusKind,
        value: *mut fmi2String,
    ) -> fmi2Status = masks::GET_STATUS => |i, f| status(i, f, s, value, None);
    /// Advances from `currentCommunicationPoint` (which must be the instance's time) by
    /// `communicationStepSize` (> 0). The time after the step is t0 + n·h on the instance's
    /// grid; a step size within 1e-9 (relative) of the previous one is taken as the previous
    /// one, so the rounding of an importer's time arithmetic does not reach the model.
    /// Refused with fmi2Error, changing nothing: a mismatched communication point, h <= 0 or
    /// not finite, a step past the stop time. A state that turns non-finite gives fmi2Error
    /// and the Error stage.
    fn fmi2DoStep(
        c: fmi2Component,
        currentCommunicationPoint: fmi2Real,
        communicationStepSize: fmi2Real,
        _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
    ) -> fmi2Status =
        masks::DO_STEP => |i| i.sim.do_step(currentCommunicationPoint, communicationStepSize);
    /// Never applicable: fmi2DoStep never returns fmi2Pending.
    fn fmi2CancelStep(c: fmi2Component) -> fmi2Status =
        masks::CANCEL_STEP => |_i| refuse("fmi2DoStep never returns fmi2Pending");
    /// canInterpolateInputs="false".
    fn fmi2SetRealInputDerivatives(
        c: fmi2Component,
        _vr: *const fmi2ValueReference,
        _nvr: usize,
        _order: *const fmi2Integer,
        _value: *const fmi2Real,
    ) -> fmi2Status = masks::SET_REAL_INPUT_DERIVATIVES => |_i| {
        refuse("input derivatives (canInterpolateInputs=\"false\"); inputs are held over a step")
    };
    /// maxOutputDerivativeOrder="0".
    fn fmi2GetRealOutputDerivatives(
        c: fmi2Component,
        _vr: *const fmi2ValueReference,
        _nvr: usize,
        _order: *const fmi2Integer,
        _value: *mut fmi2Real,
    ) -> fmi2Status = masks::GET_REAL_OUTPUT_DERIVATIVES => |_i| {
        refuse("output derivatives (maxOutputDerivativeOrder=\"0\")")
    };
    /// providesDirectionalDerivative="false".
    fn fmi2GetDirectionalDerivative(
        c: fmi2Component,
        _vUnknown_ref: *const fmi2ValueReference,
        _nUnknown: usize,
        _vKnown_ref: *const fmi2ValueReference,
        _nKnown: usize,
        _dvKnown: *const fmi2Real,
        _dvUnknown: *mut fmi2Real,
    ) -> fmi2Status = masks::DIRECTIONAL_DERIVATIVE => |_i| {
        refuse("directional derivatives (providesDirectionalDerivative=\"false\")")
    };
}
