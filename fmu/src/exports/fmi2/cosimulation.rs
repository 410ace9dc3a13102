//! FMI 2.0 Co-Simulation: fmi2DoStep, the status queries, and the capabilities this FMU
//! declares absent (input interpolation, output derivatives, asynchronous steps, directional
//! derivatives), which answer fmi2Error with the reason.

use crate::error::FmuError;
use crate::exports::guard::{with_instance, write_out};
use crate::fmi2_types::*;
use crate::instance::{Instance, Mask, masks};

/// The one status answer that applies to a synchronous FMU that never discards.
fn status_kind(
    instance: &Instance,
    function: &str,
    kind: fmi2StatusKind,
) -> Result<fmi2Status, FmuError> {
    let why = match kind {
        fmi2DoStepStatus | fmi2PendingStatus => "fmi2DoStep never returns fmi2Pending",
        fmi2LastSuccessfulTime | fmi2Terminated => "fmi2DoStep never returns fmi2Discard",
        other => {
            return Err(FmuError::InvalidArgument(format!(
                "unknown fmi2StatusKind {other}"
            )));
        }
    };
    instance.log(
        fmi2Status::fmi2Discard,
        &format!("{function}: status kind {kind} does not apply: {why}"),
    );
    Ok(fmi2Status::fmi2Discard)
}

/// The body of a function this FMU does not offer: refuses with `why` (after the NULL and
/// stage checks).
fn refuse(c: fmi2Component, function: &'static str, mask: Mask, why: &'static str) -> fmi2Status {
    with_instance(c, function, mask, |_| {
        Err::<(), _>(FmuError::NotSupported(why))
    })
}

exports! {
    /// Advances from `currentCommunicationPoint` (which must be the instance's time) by
    /// `communicationStepSize` (> 0). The time after the step is t0 + n·h on the instance's
    /// grid; a step size within 1e-9 (relative) of the previous one is taken as the previous
    /// one, so the rounding of an importer's time arithmetic does not reach the model.
    /// Refused with fmi2Error, changing nothing: a mismatched communication point, h <= 0 or
    /// not finite, a step past the stop time. A state that turns non-finite gives fmi2Error
    /// and the Error stage.
    fn fmi2DoStep(c: fmi2Component, currentCommunicationPoint: fmi2Real, communicationStepSize: fmi2Real, _noSetFMUStatePriorToCurrentPoint: fmi2Boolean) -> fmi2Status {
        with_instance(c, "fmi2DoStep", masks::DO_STEP, |instance| {
            instance.sim.do_step(currentCommunicationPoint, communicationStepSize)?;
            Ok(fmi2Status::fmi2OK)
        })
    }

    /// Never applicable: fmi2DoStep never returns fmi2Pending.
    fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
        refuse(c, "fmi2CancelStep", masks::CANCEL_STEP, "fmi2DoStep never returns fmi2Pending")
    }

    fn fmi2GetStatus(c: fmi2Component, s: fmi2StatusKind, _value: *mut fmi2Status) -> fmi2Status {
        let function = "fmi2GetStatus";
        with_instance(c, function, masks::GET_STATUS, |instance| status_kind(instance, function, s))
    }

    /// fmi2LastSuccessfulTime gives the instance's time.
    fn fmi2GetRealStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Real) -> fmi2Status {
        let function = "fmi2GetRealStatus";
        with_instance(c, function, masks::GET_STATUS, |instance| {
            if s == fmi2LastSuccessfulTime {
                write_out(value, instance.sim.time(), "value")?;
                return Ok(fmi2Status::fmi2OK);
            }
            status_kind(instance, function, s)
        })
    }

    fn fmi2GetIntegerStatus(c: fmi2Component, s: fmi2StatusKind, _value: *mut fmi2Integer) -> fmi2Status {
        let function = "fmi2GetIntegerStatus";
        with_instance(c, function, masks::GET_STATUS, |instance| status_kind(instance, function, s))
    }

    /// fmi2Terminated gives fmi2False: the models never ask to end the simulation.
    fn fmi2GetBooleanStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Boolean) -> fmi2Status {
        let function = "fmi2GetBooleanStatus";
        with_instance(c, function, masks::GET_STATUS, |instance| {
            if s == fmi2Terminated {
                write_out(value, fmi2False, "value")?;
                return Ok(fmi2Status::fmi2OK);
            }
            status_kind(instance, function, s)
        })
    }

    fn fmi2GetStringStatus(c: fmi2Component, s: fmi2StatusKind, _value: *mut fmi2String) -> fmi2Status {
        let function = "fmi2GetStringStatus";
        with_instance(c, function, masks::GET_STATUS, |instance| status_kind(instance, function, s))
    }

    /// canInterpolateInputs="false".
    fn fmi2SetRealInputDerivatives(c: fmi2Component, _vr: *const fmi2ValueReference, _nvr: usize, _order: *const fmi2Integer, _value: *const fmi2Real) -> fmi2Status {
        let why = "input derivatives (canInterpolateInputs=\"false\"); inputs are held over a step";
        refuse(c, "fmi2SetRealInputDerivatives", masks::SET_REAL_INPUT_DERIVATIVES, why)
    }

    /// maxOutputDerivativeOrder="0".
    fn fmi2GetRealOutputDerivatives(c: fmi2Component, _vr: *const fmi2ValueReference, _nvr: usize, _order: *const fmi2Integer, _value: *mut fmi2Real) -> fmi2Status {
        let why = "output derivatives (maxOutputDerivativeOrder=\"0\")";
        refuse(c, "fmi2GetRealOutputDerivatives", masks::GET_REAL_OUTPUT_DERIVATIVES, why)
    }

    /// providesDirectionalDerivative="false".
    fn fmi2GetDirectionalDerivative(c: fmi2Component, _vUnknown_ref: *const fmi2ValueReference, _nUnknown: usize, _vKnown_ref: *const fmi2ValueReference, _nKnown: usize, _dvKnown: *const fmi2Real, _dvUnknown: *mut fmi2Real) -> fmi2Status {
        let why = "directional derivatives (providesDirectionalDerivative=\"false\")";
        refuse(c, "fmi2GetDirectionalDerivative", masks::DIRECTIONAL_DERIVATIVE, why)
    }
}
