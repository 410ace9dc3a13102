//! fmi2Get*/fmi2Set* for Real, Integer, Boolean and String. Every element is handled: a
//! refused one is logged with its reason and the call returns the worst status, while the
//! others still take effect (set) or are filled in (get).

use super::guard::{c_slice, c_slice_mut, with_instance};
use crate::fmi2_types::*;
use crate::instance::{Instance, Mask, Stage, masks};
use crate::simulation::FmiType;

pub(crate) fn initialised(instance: &Instance) -> bool {
    !matches!(
        instance.stage,
        Stage::Instantiated | Stage::InitializationMode
    )
}

/// Reads `vr` into `value` through `to_c`.
///
/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
unsafe fn get_values<T>(
    c: fmi2Component,
    function: &'static str,
    ty: FmiType,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut T,
    to_c: fn(f64) -> T,
) -> fmi2Status {
    with_instance(c, function, masks::GET_VALUE, |instance| {
        // SAFETY: per the function's contract.
        let vrs = unsafe { c_slice(vr, nvr, "vr[]") }?;
        // SAFETY: per the function's contract.
        let values = unsafe { c_slice_mut(value, nvr, "value[]") }?;
        let mut worst = fmi2Status::fmi2OK;
        for (&vr, slot) in vrs.iter().zip(values) {
            match instance.sim.get(vr, ty) {
                Ok(v) => *slot = to_c(v),
                Err(e) => worst = worst.max(instance.report(function, &e)),
            }
        }
        Ok(worst)
    })
}

/// One fmi2Set* function: its name, its allowed stages and its type.
struct Setter {
    function: &'static str,
    mask: Mask,
    ty: FmiType,
}

/// Writes `value` (converted by `from_c`) to `vr`.
///
/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
unsafe fn set_values<T: Copy>(
    c: fmi2Component,
    setter: Setter,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const T,
    from_c: fn(T) -> f64,
) -> fmi2Status {
    let Setter { function, mask, ty } = setter;
    with_instance(c, function, mask, |instance| {
        // SAFETY: per the function's contract.
        let vrs = unsafe { c_slice(vr, nvr, "vr[]") }?;
        // SAFETY: per the function's contract.
        let values = unsafe { c_slice(value, nvr, "value[]") }?;
        let initialised = initialised(instance);
        let mut worst = fmi2Status::fmi2OK;
        for (&vr, &v) in vrs.iter().zip(values) {
            if let Err(e) = instance.sim.set(vr, ty, from_c(v), initialised) {
                worst = worst.max(instance.report(function, &e));
            }
        }
        Ok(worst)
    })
}

fn real_to_c(v: f64) -> fmi2Real {
    v
}

fn integer_to_c(v: f64) -> fmi2Integer {
    // Integer variables hold integers within i32 (their table ranges say so).
    v as fmi2Integer
}

fn boolean_to_c(v: f64) -> fmi2Boolean {
    if v != 0.0 { fmi2True } else { fmi2False }
}

fn boolean_from_c(v: fmi2Boolean) -> f64 {
    if v != fmi2False { 1.0 } else { 0.0 }
}

/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    // SAFETY: forwarded contract.
    unsafe { get_values(c, "fmi2GetReal", FmiType::Real, vr, nvr, value, real_to_c) }
}

/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    // SAFETY: forwarded contract.
    unsafe {
        get_values(
            c,
            "fmi2GetInteger",
            FmiType::Integer,
            vr,
            nvr,
            value,
            integer_to_c,
        )
    }
}

/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    // SAFETY: forwarded contract.
    unsafe {
        get_values(
            c,
            "fmi2GetBoolean",
            FmiType::Boolean,
            vr,
            nvr,
            value,
            boolean_to_c,
        )
    }
}

/// There are no String variables: every value reference is refused (with its real type
/// when it exists).
///
/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    // SAFETY: forwarded contract; no value is ever converted.
    unsafe {
        get_values(c, "fmi2GetString", FmiType::String, vr, nvr, value, |_| {
            std::ptr::null()
        })
    }
}

/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    let setter = Setter {
        function: "fmi2SetReal",
        mask: masks::SET_REAL,
        ty: FmiType::Real,
    };
    // SAFETY: forwarded contract.
    unsafe { set_values(c, setter, vr, nvr, value, real_to_c) }
}

/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    let setter = Setter {
        function: "fmi2SetInteger",
        mask: masks::SET_OTHER,
        ty: FmiType::Integer,
    };
    // SAFETY: forwarded contract.
    unsafe { set_values(c, setter, vr, nvr, value, f64::from) }
}

/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    let setter = Setter {
        function: "fmi2SetBoolean",
        mask: masks::SET_OTHER,
        ty: FmiType::Boolean,
    };
    // SAFETY: forwarded contract.
    unsafe { set_values(c, setter, vr, nvr, value, boolean_from_c) }
}

/// There are no String variables: every value reference is refused.
///
/// # Safety
/// `vr` and `value` must be NULL or hold `nvr` elements.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    let setter = Setter {
        function: "fmi2SetString",
        mask: masks::SET_OTHER,
        ty: FmiType::String,
    };
    // SAFETY: forwarded contract; the strings are never read.
    unsafe { set_values(c, setter, vr, nvr, value, |_| f64::NAN) }
}
