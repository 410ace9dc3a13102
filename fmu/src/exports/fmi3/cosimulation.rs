//! Co-Simulation through FMI 3.0: fmi3DoStep on the same engine and time grid as fmi2DoStep
//! (so both give the same outputs bit for bit), and the step-mode functions this FMU does not
//! need.

use crate::exports::guard::{no_null, refuse, write_out};
use crate::fmi3_types::*;
use crate::instance::{Interface, masks, masks3};

forward! {
    /// Advances from `currentCommunicationPoint` (the instance's time) by
    /// `communicationStepSize`, exactly as fmi2DoStep does. Never asks for event handling,
    /// never terminates, never returns early; `*lastSuccessfulTime` is the time after the
    /// step. The four output pointers must not be NULL. (A Model Exchange instance is never
    /// in StepComplete, so the mask alone refuses it.)
    fn fmi3DoStep(
        instance: fmi3Instance,
        currentCommunicationPoint: fmi3Float64,
        communicationStepSize: fmi3Float64,
        _noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
        eventHandlingNeeded: *mut fmi3Boolean,
        terminateSimulation: *mut fmi3Boolean,
        earlyReturn: *mut fmi3Boolean,
        lastSuccessfulTime: *mut fmi3Float64,
    ) -> fmi3Status = masks::DO_STEP => |i| {
        let flags = [
            (eventHandlingNeeded, "eventHandlingNeeded"),
            (terminateSimulation, "terminateSimulation"),
            (earlyReturn, "earlyReturn"),
        ];
        no_null(&flags)?;
        no_null(&[(lastSuccessfulTime, "lastSuccessfulTime")])?;
        let result = i.sim.do_step(currentCommunicationPoint, communicationStepSize);
        for (pointer, name) in flags {
            write_out(pointer, fmi3False, name)?;
        }
        write_out(lastSuccessfulTime, i.sim.time(), "lastSuccessfulTime")?;
        result
    };
    /// Not needed: without event mode (hasEventMode="false") fmi3ExitInitializationMode
    /// already enters step mode.
    fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status = masks3::ENTER_STEP_MODE => |i| {
        refuse(match i.interface {
            Interface::ModelExchange => "Co-Simulation functions on a Model Exchange instance",
            Interface::CoSimulation => {
                "event mode is not used (hasEventMode=\"false\"): \
                 fmi3ExitInitializationMode enters step mode"
            }
        })
    };
    /// maxOutputDerivativeOrder="0".
    fn fmi3GetOutputDerivatives(
        instance: fmi3Instance,
        _valueReferences: *const fmi3ValueReference,
        _nValueReferences: usize,
        _orders: *const fmi3Int32,
        _values: *mut fmi3Float64,
        _nValues: usize,
    ) -> fmi3Status = masks3::GET_OUTPUT_DERIVATIVES => |_i| {
        refuse("output derivatives (maxOutputDerivativeOrder=\"0\")")
    };
}
