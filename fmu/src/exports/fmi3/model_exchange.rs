//! Model Exchange through FMI 3.0, for an instance from fmi3InstantiateModelExchange: the
//! same states, derivatives, event indicators and events as FMI 2.0's Model Exchange.

use super::with_instance3;
use crate::error::FmuError;
use crate::exports::guard::write_out;
use crate::exports::model_exchange::{
    DERIVATIVES, EVENT_INDICATORS, NOMINALS, Reader, STATES, completed_integrator_step,
    discrete_update, enter_continuous_time_mode, read_array, set_continuous_states, set_time,
    with_me,
};
use crate::fmi3_types::*;
use crate::instance::{masks, masks3};

/// # Safety
/// `instance` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(instance: fmi3Instance) -> fmi3Status {
    enter_continuous_time_mode(instance, "fmi3EnterContinuousTimeMode").into()
}

/// The discrete changes of the event at the current time (turbulence sample, released
/// bristles) and the next time event. Every output pointer must be writable.
///
/// # Safety
/// `instance` must be NULL or live; the output pointers NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
    instance: fmi3Instance,
    discreteStatesNeedUpdate: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
    valuesOfContinuousStatesChanged: *mut fmi3Boolean,
    nextEventTimeDefined: *mut fmi3Boolean,
    nextEventTime: *mut fmi3Float64,
) -> fmi3Status {
    let function = "fmi3UpdateDiscreteStates";
    with_me(
        instance,
        function,
        masks3::UPDATE_DISCRETE_STATES,
        |instance| {
            let flags = [
                (discreteStatesNeedUpdate, "discreteStatesNeedUpdate"),
                (terminateSimulation, "terminateSimulation"),
                (
                    nominalsOfContinuousStatesChanged,
                    "nominalsOfContinuousStatesChanged",
                ),
                (
                    valuesOfContinuousStatesChanged,
                    "valuesOfContinuousStatesChanged",
                ),
                (nextEventTimeDefined, "nextEventTimeDefined"),
            ];
            if let Some((_, name)) = flags.iter().find(|(p, _)| p.is_null()) {
                return Err(FmuError::NullArgument(name));
            }
            if nextEventTime.is_null() {
                return Err(FmuError::NullArgument("nextEventTime"));
            }
            let (changed, next) = discrete_update(instance, function)?;
            let values = [false, false, false, changed, next.is_some()];
            // SAFETY: every pointer checked non-NULL above, writable per the contract.
            unsafe {
                for ((pointer, name), value) in flags.into_iter().zip(values) {
                    write_out(pointer, u8::from(value), name)?;
                }
                write_out(nextEventTime, next.unwrap_or(0.0), "nextEventTime")
            }
        },
    )
    .into()
}

/// No step event and no termination; an error once the state is not finite.
///
/// # Safety
/// `instance` must be NULL or live; the two flags NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
    instance: fmi3Instance,
    _noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    enterEventMode: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
) -> fmi3Status {
    let function = "fmi3CompletedIntegratorStep";
    // SAFETY: forwarded contract.
    unsafe {
        completed_integrator_step(instance, function, enterEventMode, terminateSimulation, 0u8)
    }
    .into()
}

/// # Safety
/// `instance` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetTime(instance: fmi3Instance, time: fmi3Float64) -> fmi3Status {
    set_time(instance, "fmi3SetTime", time).into()
}

/// # Safety
/// `instance` must be NULL or live; `continuousStates` NULL or `nContinuousStates` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetContinuousStates(
    instance: fmi3Instance,
    continuousStates: *const fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    let function = "fmi3SetContinuousStates";
    // SAFETY: forwarded contract.
    unsafe { set_continuous_states(instance, function, continuousStates, nContinuousStates) }.into()
}

/// The derivatives of the continuous states: the core's right-hand side, bit for bit.
///
/// # Safety
/// `instance` must be NULL or live; `derivatives` NULL or `nContinuousStates` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(
    instance: fmi3Instance,
    derivatives: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    let reader = Reader {
        function: "fmi3GetContinuousStateDerivatives",
        mask: masks3::GET_DERIVATIVES,
        argument: "derivatives",
        fill: DERIVATIVES,
    };
    // SAFETY: forwarded contract.
    unsafe { read_array(instance, &reader, derivatives, nContinuousStates) }.into()
}

/// The foot heights (m): a sign change is a touch-down or a lift-off.
///
/// # Safety
/// `instance` must be NULL or live; `eventIndicators` NULL or `nEventIndicators` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetEventIndicators(
    instance: fmi3Instance,
    eventIndicators: *mut fmi3Float64,
    nEventIndicators: usize,
) -> fmi3Status {
    let reader = Reader {
        function: "fmi3GetEventIndicators",
        mask: masks::GET_EVENT_INDICATORS,
        argument: "eventIndicators",
        fill: EVENT_INDICATORS,
    };
    // SAFETY: forwarded contract.
    unsafe { read_array(instance, &reader, eventIndicators, nEventIndicators) }.into()
}

/// # Safety
/// `instance` must be NULL or live; `continuousStates` NULL or `nContinuousStates` values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetContinuousStates(
    instance: fmi3Instance,
    continuousStates: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    let reader = Reader {
        function: "fmi3GetContinuousStates",
        mask: masks::GET_CONTINUOUS_STATES,
        argument: "continuousStates",
        fill: STATES,
    };
    // SAFETY: forwarded contract.
    unsafe { read_array(instance, &reader, continuousStates, nContinuousStates) }.into()
}

/// 1 for every state.
///
/// # Safety
/// `instance` must be NULL or live; `nominals` NULL or `nContinuousStates` writable values.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(
    instance: fmi3Instance,
    nominals: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    let reader = Reader {
        function: "fmi3GetNominalsOfContinuousStates",
        mask: masks::GET_NOMINALS,
        argument: "nominals",
        fill: NOMINALS,
    };
    // SAFETY: forwarded contract.
    unsafe { read_array(instance, &reader, nominals, nContinuousStates) }.into()
}

/// How many values a Model Exchange quantity of the model has (0 for a Co-Simulation-only
/// model), written to `out`.
fn count(
    instance: fmi3Instance,
    function: &'static str,
    out: *mut usize,
    of: fn(&crate::table::ModelExchangeTable) -> usize,
) -> fmi3Status {
    with_instance3(instance, function, masks3::ANY, |instance| {
        let n = instance.sim.table().model_exchange.as_ref().map_or(0, of);
        // SAFETY: `out` is NULL (refused) or writable per the caller's contract.
        unsafe { write_out(out, n, "the count") }
    })
}

/// The number of event indicators (0 for a Co-Simulation-only model).
///
/// # Safety
/// `instance` must be NULL or live; `nEventIndicators` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(
    instance: fmi3Instance,
    nEventIndicators: *mut usize,
) -> fmi3Status {
    let function = "fmi3GetNumberOfEventIndicators";
    count(instance, function, nEventIndicators, |me| {
        me.event_indicators
    })
}

/// The number of continuous states (0 for a Co-Simulation-only model).
///
/// # Safety
/// `instance` must be NULL or live; `nContinuousStates` NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(
    instance: fmi3Instance,
    nContinuousStates: *mut usize,
) -> fmi3Status {
    let function = "fmi3GetNumberOfContinuousStates";
    count(instance, function, nContinuousStates, |me| me.states.len())
}
