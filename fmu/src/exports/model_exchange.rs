//! The Model Exchange functions, exported so that the library offers the whole FMI 2.0 API:
//! fmi2Instantiate refuses Model Exchange, so every call here is an illegal call sequence.

use super::guard::with_instance;
use crate::fmi2_types::*;
use crate::instance::masks::MODEL_EXCHANGE;

fn refuse(c: fmi2Component, function: &'static str) -> fmi2Status {
    with_instance(c, function, MODEL_EXCHANGE, |_| Ok(fmi2Status::fmi2OK))
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
    refuse(c, "fmi2EnterEventMode")
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2NewDiscreteStates(
    c: fmi2Component,
    _eventInfo: *mut fmi2EventInfo,
) -> fmi2Status {
    refuse(c, "fmi2NewDiscreteStates")
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
    refuse(c, "fmi2EnterContinuousTimeMode")
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
    c: fmi2Component,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
    _enterEventMode: *mut fmi2Boolean,
    _terminateSimulation: *mut fmi2Boolean,
) -> fmi2Status {
    refuse(c, "fmi2CompletedIntegratorStep")
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, _time: fmi2Real) -> fmi2Status {
    refuse(c, "fmi2SetTime")
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetContinuousStates(
    c: fmi2Component,
    _x: *const fmi2Real,
    _nx: usize,
) -> fmi2Status {
    refuse(c, "fmi2SetContinuousStates")
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDerivatives(
    c: fmi2Component,
    _derivatives: *mut fmi2Real,
    _nx: usize,
) -> fmi2Status {
    refuse(c, "fmi2GetDerivatives")
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetEventIndicators(
    c: fmi2Component,
    _eventIndicators: *mut fmi2Real,
    _ni: usize,
) -> fmi2Status {
    refuse(c, "fmi2GetEventIndicators")
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetContinuousStates(
    c: fmi2Component,
    _x: *mut fmi2Real,
    _nx: usize,
) -> fmi2Status {
    refuse(c, "fmi2GetContinuousStates")
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
    c: fmi2Component,
    _x_nominal: *mut fmi2Real,
    _nx: usize,
) -> fmi2Status {
    refuse(c, "fmi2GetNominalsOfContinuousStates")
}
