//! Creating, configuring, initialising, terminating, resetting and freeing an instance.

use super::guard::{c_slice, guarded, with_instance};
use super::instantiate::{Request, create_instance};
use crate::error::FmuError;
use crate::fmi2_types::*;
use crate::instance::{Instance, Interface, Stage, masks};
use crate::log::{Category, Sink};
use crate::table::Api;
use flyloop_core::number::Compact;
use std::ffi::{CStr, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Returns "default".
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    guarded(fmi2TypesPlatform.as_ptr(), || fmi2TypesPlatform.as_ptr())
}

/// Returns "2.0".
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    guarded(fmi2Version.as_ptr(), || fmi2Version.as_ptr())
}

/// Creates a Co-Simulation or Model Exchange instance of the model whose GUID is `fmuGUID`
/// (Quadrotor: both; Lander2D: Co-Simulation only). Returns NULL, with the reason sent to the
/// logger when there is one, for NULL or logger-less callbacks, a missing instance name, an
/// interface the model does not offer, or an unknown GUID.
///
/// # Safety
/// Pointer arguments must be NULL or valid per the FMI 2.0 standard.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    _fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: NULL or a valid callback struct (the importer's contract).
        let functions = unsafe { functions.as_ref() }.copied()?;
        let sink = Sink::Fmi2 {
            callback: functions.logger?,
            environment: functions.componentEnvironment,
        };
        let interface = match fmuType {
            fmi2CoSimulation => Ok(Interface::CoSimulation),
            fmi2ModelExchange => Ok(Interface::ModelExchange),
            other => Err(format!(
                "fmuType {other} is neither Model Exchange (0) nor Co-Simulation (1)"
            )),
        };
        // SAFETY: NULL or NUL-terminated strings (the contract).
        let (name, guid) = unsafe { (c_str(instanceName), c_str(fmuGUID)) };
        create_instance(&Request {
            function: "fmi2Instantiate",
            api: Api::Fmi2,
            name,
            interface,
            token: guid,
            sink,
            logging_on: loggingOn != fmi2False,
        })
    }));
    match outcome {
        Ok(Some(instance)) => instance.cast(),
        _ => std::ptr::null_mut(),
    }
}

/// A `&CStr` from a C string argument.
///
/// # Safety
/// `s` must be NULL or NUL-terminated and valid for the call.
pub(crate) unsafe fn c_str<'a>(s: *const c_char) -> Option<&'a CStr> {
    // SAFETY: per the function's contract.
    (!s.is_null()).then(|| unsafe { CStr::from_ptr(s) })
}

/// Frees the instance behind `c` (the body of fmi2FreeInstance and fmi3FreeInstance).
pub(crate) fn free_instance(c: fmi2Component, function: &'static str) {
    let status = with_instance(c, function, masks::FREE_INSTANCE, |instance| {
        instance.event(&format!("{function}: freeing the instance"));
        Ok(fmi2Status::fmi2OK)
    });
    // Free only what passed the stage check (FREE_INSTANCE allows every stage an instance
    // can be in); a panic there leaves the instance allocated rather than half dropped.
    if status == fmi2Status::fmi2OK {
        let _ = catch_unwind(AssertUnwindSafe(|| {
            // SAFETY: non-NULL (checked by with_instance) and created by Box::into_raw.
            drop(unsafe { Box::from_raw(c.cast::<Instance>()) });
        }));
    }
}

/// Frees the instance and every FMU state it handed out. NULL is ignored.
///
/// # Safety
/// `c` must be NULL or an instance not freed yet.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    free_instance(c, "fmi2FreeInstance");
}

/// The body of fmi2SetDebugLogging and fmi3SetDebugLogging.
///
/// # Safety
/// `categories` must be NULL or point to `n` C strings.
pub(crate) unsafe fn set_debug_logging(
    c: fmi2Component,
    function: &'static str,
    on: bool,
    n: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    with_instance(c, function, masks::SET_DEBUG_LOGGING, |instance| {
        // SAFETY: per the function's contract.
        let names = unsafe { c_slice(categories, n, "categories[]") }?;
        if names.is_empty() {
            instance.filter.set_all(on);
            return Ok(fmi2Status::fmi2OK);
        }
        let mut worst = fmi2Status::fmi2OK;
        for &name in names {
            // SAFETY: each entry is NULL or a C string (the contract).
            let name = unsafe { c_str(name) }.map(CStr::to_string_lossy);
            let error = match name.as_deref().map(|n| (n, Category::from_name(n))) {
                Some((_, Some(category))) => {
                    instance.filter.set(category, on);
                    continue;
                }
                Some((n, None)) => FmuError::InvalidArgument(format!(
                    "unknown log category `{n}` (known: logEvents, logStatusWarning, \
                     logStatusError, logStatusFatal)"
                )),
                None => FmuError::NullArgument("categories[i]"),
            };
            worst = worst.max(instance.report(function, &error));
        }
        Ok(worst)
    })
}

/// Switches log categories: those named in `categories`, or all of them when
/// `nCategories` is 0. An unknown category name is an error (the others still switch).
///
/// # Safety
/// `categories` must be NULL or point to `nCategories` C strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    let on = loggingOn != fmi2False;
    // SAFETY: forwarded contract.
    unsafe { set_debug_logging(c, "fmi2SetDebugLogging", on, nCategories, categories) }
}

/// The experiment (fmi2SetupExperiment; fmi3EnterInitializationMode's arguments).
pub(crate) fn setup_experiment(
    instance: &mut Instance,
    function: &str,
    start: f64,
    stop: Option<f64>,
) -> Result<(), FmuError> {
    instance.sim.setup_experiment(start, stop)?;
    instance.event(&format!(
        "{function}: start {}, stop {}",
        Compact(start),
        stop.map_or("undefined".to_string(), |s| Compact(s).to_string())
    ));
    Ok(())
}

/// Sets the start time (and the stop time, if defined). The tolerance is not used: both
/// models step on fixed grids.
///
/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    _toleranceDefined: fmi2Boolean,
    _tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    let function = "fmi2SetupExperiment";
    with_instance(c, function, masks::SETUP_EXPERIMENT, |instance| {
        let stop = (stopTimeDefined != fmi2False).then_some(stopTime);
        setup_experiment(instance, function, startTime, stop)?;
        Ok(fmi2Status::fmi2OK)
    })
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    let function = "fmi2EnterInitializationMode";
    with_instance(c, function, masks::ENTER_INITIALIZATION_MODE, |instance| {
        instance.stage = Stage::InitializationMode;
        instance.event(function);
        Ok(fmi2Status::fmi2OK)
    })
}

/// The body of fmi2ExitInitializationMode and fmi3ExitInitializationMode: Co-Simulation
/// goes to step mode, Model Exchange to event mode.
pub(crate) fn exit_initialization_mode(c: fmi2Component, function: &'static str) -> fmi2Status {
    with_instance(c, function, masks::EXIT_INITIALIZATION_MODE, |instance| {
        instance.stage = match instance.interface {
            Interface::CoSimulation => Stage::StepComplete,
            Interface::ModelExchange => Stage::EventMode,
        };
        instance.event(&format!("{function}: t = {}", Compact(instance.sim.time())));
        Ok(fmi2Status::fmi2OK)
    })
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    exit_initialization_mode(c, "fmi2ExitInitializationMode")
}

/// The body of fmi2Terminate and fmi3Terminate.
pub(crate) fn terminate(c: fmi2Component, function: &'static str) -> fmi2Status {
    with_instance(c, function, masks::TERMINATE, |instance| {
        instance.stage = Stage::Terminated;
        instance.event(&format!("{function}: t = {}", Compact(instance.sim.time())));
        Ok(fmi2Status::fmi2OK)
    })
}

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    terminate(c, "fmi2Terminate")
}

/// The body of fmi2Reset and fmi3Reset: back to the state right after instantiation.
pub(crate) fn reset(c: fmi2Component, function: &'static str) -> fmi2Status {
    with_instance(c, function, masks::RESET, |instance| {
        instance.sim.reset()?;
        instance.stage = Stage::Instantiated;
        instance.event(&format!("{function}: back to the start values"));
        Ok(fmi2Status::fmi2OK)
    })
}

/// Back to the state right after fmi2Instantiate: start values, no experiment. FMU states
/// handed out stay valid.
///
/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    reset(c, "fmi2Reset")
}
