//! The Model Exchange functions (FMI 2.0 ME) of an instance made with fmuType
//! fmi2ModelExchange: the importer's solver sets time and continuous states, reads
//! derivatives and event indicators, and calls the event functions. Each checks the stage mask
//! (Reference-FMUs), the interface, NULL pointers and array lengths; a refusal is an error
//! status plus a log line, never a crash.

use super::guard::{c_slice, c_slice_mut, with_instance, write_out};
use crate::engine::Simulation;
use crate::error::FmuError;
use crate::fmi2_types::*;
use crate::instance::{Instance, Mask, Stage, masks};
use flyloop_core::number::Compact;

/// [`with_instance`] for a Model Exchange function: also refuses a Co-Simulation instance.
pub(crate) fn with_me(
    c: fmi2Component,
    function: &'static str,
    mask: Mask,
    body: impl FnOnce(&mut Instance) -> Result<(), FmuError>,
) -> fmi2Status {
    with_instance(c, function, mask, |instance| {
        instance.check_model_exchange()?;
        body(instance)?;
        Ok(fmi2Status::fmi2OK)
    })
}

/// The body of fmi2EnterEventMode and fmi3EnterEventMode.
pub(crate) fn enter_event_mode(c: fmi2Component, function: &'static str) -> fmi2Status {
    with_me(c, function, masks::ENTER_EVENT_MODE, |instance| {
        instance.stage = Stage::EventMode;
        Ok(())
    })
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
    enter_event_mode(c, "fmi2EnterEventMode")
}

/// The discrete changes of the event at the current time, logged as `function`'s event:
/// whether the continuous states changed, and the next time event (the part of
/// fmi2NewDiscreteStates and fmi3UpdateDiscreteStates that is not C arguments).
pub(crate) fn discrete_update(
    instance: &mut Instance,
    function: &str,
) -> Result<(bool, Option<f64>), FmuError> {
    let (changed, next) = instance.sim.new_discrete_states()?;
    instance.event(&format!(
        "{function}: t = {}, next time event {}",
        Compact(instance.sim.time()),
        next.map_or("none".to_string(), |t| Compact(t).to_string())
    ));
    Ok((changed, next))
}

/// The discrete changes of the event at the current time (turbulence sample, released
/// bristles) and the next time event.
///
/// # Safety
/// `c` must be NULL or a live instance; `eventInfo` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2NewDiscreteStates(
    c: fmi2Component,
    eventInfo: *mut fmi2EventInfo,
) -> fmi2Status {
    let function = "fmi2NewDiscreteStates";
    with_me(c, function, masks::NEW_DISCRETE_STATES, |instance| {
        if eventInfo.is_null() {
            return Err(FmuError::NullArgument("eventInfo"));
        }
        let (changed, next) = discrete_update(instance, function)?;
        let info = fmi2EventInfo {
            newDiscreteStatesNeeded: fmi2False,
            terminateSimulation: fmi2False,
            nominalsOfContinuousStatesChanged: fmi2False,
            valuesOfContinuousStatesChanged: fmi2Boolean::from(changed),
            nextEventTimeDefined: fmi2Boolean::from(next.is_some()),
            nextEventTime: next.unwrap_or(0.0),
        };
        // SAFETY: non-NULL (checked above) and writable per the contract.
        unsafe { write_out(eventInfo, info, "eventInfo") }
    })
}

/// The body of fmi2EnterContinuousTimeMode and fmi3EnterContinuousTimeMode.
pub(crate) fn enter_continuous_time_mode(c: fmi2Component, function: &'static str) -> fmi2Status {
    with_me(c, function, masks::ENTER_CONTINUOUS_TIME_MODE, |instance| {
        instance.stage = Stage::ContinuousTimeMode;
        Ok(())
    })
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
    enter_continuous_time_mode(c, "fmi2EnterContinuousTimeMode")
}

/// The body of fmi2CompletedIntegratorStep and fmi3CompletedIntegratorStep: no step event
/// and no termination (`no` is the version's false); an error (Error stage) once the state is
/// not finite.
///
/// # Safety
/// The two flags must be NULL or writable.
pub(crate) unsafe fn completed_integrator_step<B: Copy>(
    c: fmi2Component,
    function: &'static str,
    enter_event_mode: *mut B,
    terminate_simulation: *mut B,
    no: B,
) -> fmi2Status {
    with_me(c, function, masks::COMPLETED_INTEGRATOR_STEP, |instance| {
        if enter_event_mode.is_null() {
            return Err(FmuError::NullArgument("enterEventMode"));
        }
        if terminate_simulation.is_null() {
            return Err(FmuError::NullArgument("terminateSimulation"));
        }
        instance.sim.completed_integrator_step()?;
        // SAFETY: both non-NULL (checked above) and writable per the contract.
        unsafe {
            write_out(enter_event_mode, no, "enterEventMode")?;
            write_out(terminate_simulation, no, "terminateSimulation")
        }
    })
}

/// # Safety
/// `c` must be NULL or a live instance; the two flags NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
    c: fmi2Component,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
    enterEventMode: *mut fmi2Boolean,
    terminateSimulation: *mut fmi2Boolean,
) -> fmi2Status {
    let function = "fmi2CompletedIntegratorStep";
    // SAFETY: forwarded contract.
    unsafe { completed_integrator_step(c, function, enterEventMode, terminateSimulation, 0) }
}

/// The body of fmi2SetTime and fmi3SetTime.
pub(crate) fn set_time(c: fmi2Component, function: &'static str, time: f64) -> fmi2Status {
    with_me(c, function, masks::SET_TIME, |instance| {
        instance.sim.set_time(time)
    })
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    set_time(c, "fmi2SetTime", time)
}

/// The body of fmi2SetContinuousStates and fmi3SetContinuousStates.
///
/// # Safety
/// `x` must be NULL or hold `nx` readable values.
pub(crate) unsafe fn set_continuous_states(
    c: fmi2Component,
    function: &'static str,
    x: *const f64,
    nx: usize,
) -> fmi2Status {
    with_me(c, function, masks::SET_CONTINUOUS_STATES, |instance| {
        // SAFETY: per the function's contract.
        let x = unsafe { c_slice(x, nx, "continuous states") }?;
        instance.sim.set_continuous_states(x)
    })
}

/// # Safety
/// `c` must be NULL or a live instance; `x` NULL or `nx` readable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetContinuousStates(
    c: fmi2Component,
    x: *const fmi2Real,
    nx: usize,
) -> fmi2Status {
    // SAFETY: forwarded contract.
    unsafe { set_continuous_states(c, "fmi2SetContinuousStates", x, nx) }
}

/// A Model Exchange array the importer reads: the call's name, allowed stages, the array
/// argument's name, and what fills it.
pub(crate) struct Reader {
    pub function: &'static str,
    pub mask: Mask,
    pub argument: &'static str,
    pub fill: fn(&dyn Simulation, &mut [f64]) -> Result<(), FmuError>,
}

/// Fills the importer's array `out` of `n` values with `reader.fill`.
///
/// # Safety
/// `out` must be NULL or hold `n` writable values.
pub(crate) unsafe fn read_array(
    c: fmi2Component,
    reader: &Reader,
    out: *mut f64,
    n: usize,
) -> fmi2Status {
    with_me(c, reader.function, reader.mask, |instance| {
        // SAFETY: per the function's contract.
        let out = unsafe { c_slice_mut(out, n, reader.argument) }?;
        (reader.fill)(instance.sim.as_ref(), out)
    })
}

/// The derivatives of the continuous states: the core's right-hand side, bit for bit.
pub(crate) const DERIVATIVES: fn(&dyn Simulation, &mut [f64]) -> Result<(), FmuError> =
    |sim, out| sim.derivatives(out);
/// The foot heights (m): a sign change is a touch-down or a lift-off.
pub(crate) const EVENT_INDICATORS: fn(&dyn Simulation, &mut [f64]) -> Result<(), FmuError> =
    |sim, out| sim.event_indicators(out);
/// The continuous states.
pub(crate) const STATES: fn(&dyn Simulation, &mut [f64]) -> Result<(), FmuError> =
    |sim, out| sim.continuous_states(out);
/// 1 for every state (positions in m, speeds in m/s, quaternion and motors near 1).
pub(crate) const NOMINALS: fn(&dyn Simulation, &mut [f64]) -> Result<(), FmuError> =
    |sim, out| sim.nominals(out);

/// The derivatives of the continuous states: the core's right-hand side, bit for bit.
///
/// # Safety
/// `c` must be NULL or a live instance; `derivatives` NULL or `nx` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDerivatives(
    c: fmi2Component,
    derivatives: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    let reader = Reader {
        function: "fmi2GetDerivatives",
        mask: masks::GET_DERIVATIVES,
        argument: "derivatives",
        fill: DERIVATIVES,
    };
    // SAFETY: forwarded contract.
    unsafe { read_array(c, &reader, derivatives, nx) }
}

/// The foot heights (m): a sign change is a touch-down or a lift-off.
///
/// # Safety
/// `c` must be NULL or a live instance; `eventIndicators` NULL or `ni` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetEventIndicators(
    c: fmi2Component,
    eventIndicators: *mut fmi2Real,
    ni: usize,
) -> fmi2Status {
    let reader = Reader {
        function: "fmi2GetEventIndicators",
        mask: masks::GET_EVENT_INDICATORS,
        argument: "eventIndicators",
        fill: EVENT_INDICATORS,
    };
    // SAFETY: forwarded contract.
    unsafe { read_array(c, &reader, eventIndicators, ni) }
}

/// # Safety
/// `c` must be NULL or a live instance; `x` NULL or `nx` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetContinuousStates(
    c: fmi2Component,
    x: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    let reader = Reader {
        function: "fmi2GetContinuousStates",
        mask: masks::GET_CONTINUOUS_STATES,
        argument: "x",
        fill: STATES,
    };
    // SAFETY: forwarded contract.
    unsafe { read_array(c, &reader, x, nx) }
}

/// 1 for every state (positions in m, speeds in m/s, quaternion and motors near 1).
///
/// # Safety
/// `c` must be NULL or a live instance; `x_nominal` NULL or `nx` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
    c: fmi2Component,
    x_nominal: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    let reader = Reader {
        function: "fmi2GetNominalsOfContinuousStates",
        mask: masks::GET_NOMINALS,
        argument: "x_nominal",
        fill: NOMINALS,
    };
    // SAFETY: forwarded contract.
    unsafe { read_array(c, &reader, x_nominal, nx) }
}
