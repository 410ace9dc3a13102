//! Creating, configuring, initialising, terminating, resetting and freeing an instance.

use super::guard::{c_slice, guarded, with_instance};
use crate::error::FmuError;
use crate::fmi2_types::*;
use crate::instance::{Instance, Interface, Stage, masks};
use crate::log::{self, Category, Logger};
use crate::models;
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
        let logger = functions.logger?;
        let env = functions.componentEnvironment;
        // SAFETY: NULL or a NUL-terminated string.
        let name = unsafe { c_str(instanceName) };
        let fail = |message: &str| {
            let shown = name.map(CStr::to_owned).unwrap_or_default();
            // SAFETY: logger and environment come together from the importer's callbacks.
            unsafe {
                log::send(
                    logger,
                    env,
                    &shown,
                    fmi2Status::fmi2Error,
                    Category::Error,
                    &format!("fmi2Instantiate: {message}"),
                );
            }
            None
        };
        let Some(name) = name.filter(|n| !n.is_empty()) else {
            return fail("instanceName is NULL or empty");
        };
        let interface = match fmuType {
            fmi2CoSimulation => Interface::CoSimulation,
            fmi2ModelExchange => Interface::ModelExchange,
            other => {
                return fail(&format!(
                    "fmuType {other} is neither Model Exchange (0) nor Co-Simulation (1)"
                ));
            }
        };
        // SAFETY: NULL or a NUL-terminated string.
        let Some(guid) = (unsafe { c_str(fmuGUID) }) else {
            return fail("fmuGUID is NULL");
        };
        let guid = guid.to_string_lossy();
        let Some(sim) = models::simulation_for(&guid) else {
            let known: Vec<String> = models::tables()
                .iter()
                .map(|t| format!("{} {}", t.info.identifier, t.guid))
                .collect();
            return fail(&format!(
                "GUID {guid} is not one of this library's models ({}); the \
                 modelDescription.xml and the binary do not belong together",
                known.join(", ")
            ));
        };
        let sim = match sim {
            Ok(sim) => sim,
            Err(e) => return fail(&format!("the model does not start: {e}")),
        };
        if interface == Interface::ModelExchange && sim.table().model_exchange.is_none() {
            return fail(&format!(
                "{} is Co-Simulation only (its physics engine steps internally); \
                 instantiate it with fmuType fmi2CoSimulation",
                sim.table().info.identifier
            ));
        }
        let instance = Instance::new(
            interface,
            Logger::new(logger, env, name.to_owned()),
            loggingOn != fmi2False,
            sim,
        );
        instance.event(&format!(
            "fmi2Instantiate: {} {:?} instance ({guid}) created",
            instance.sim.table().info.identifier,
            instance.interface
        ));
        Some(Box::into_raw(Box::new(instance)))
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
unsafe fn c_str<'a>(s: fmi2String) -> Option<&'a CStr> {
    // SAFETY: per the function's contract.
    (!s.is_null()).then(|| unsafe { CStr::from_ptr(s) })
}

/// Frees the instance and every FMU state it handed out. NULL is ignored.
///
/// # Safety
/// `c` must be NULL or an instance not freed yet.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    let status = with_instance(c, "fmi2FreeInstance", masks::FREE_INSTANCE, |instance| {
        instance.event("fmi2FreeInstance: freeing the instance");
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
    with_instance(
        c,
        "fmi2SetDebugLogging",
        masks::SET_DEBUG_LOGGING,
        |instance| {
            let on = loggingOn != fmi2False;
            // SAFETY: per the function's contract.
            let names = unsafe { c_slice(categories, nCategories, "categories[]") }?;
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
                worst = worst.max(instance.report("fmi2SetDebugLogging", &error));
            }
            Ok(worst)
        },
    )
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
    with_instance(
        c,
        "fmi2SetupExperiment",
        masks::SETUP_EXPERIMENT,
        |instance| {
            let stop = (stopTimeDefined != fmi2False).then_some(stopTime);
            instance.sim.setup_experiment(startTime, stop)?;
            instance.event(&format!(
                "fmi2SetupExperiment: start {}, stop {}",
                Compact(startTime),
                stop.map_or("undefined".to_string(), |s| Compact(s).to_string())
            ));
            Ok(fmi2Status::fmi2OK)
        },
    )
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

/// # Safety
/// `c` must be NULL or a live instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    let function = "fmi2ExitInitializationMode";
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
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    with_instance(c, "fmi2Terminate", masks::TERMINATE, |instance| {
        instance.stage = Stage::Terminated;
        instance.event(&format!(
            "fmi2Terminate: t = {}",
            Compact(instance.sim.time())
        ));
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
    with_instance(c, "fmi2Reset", masks::RESET, |instance| {
        instance.sim.reset()?;
        instance.stage = Stage::Instantiated;
        instance.event("fmi2Reset: back to the start values");
        Ok(fmi2Status::fmi2OK)
    })
}
