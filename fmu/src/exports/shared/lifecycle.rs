//! Configuring, initialising, terminating, resetting and freeing an instance.

use crate::error::FmuError;
use crate::exports::guard::{c_slice, c_str, with_instance};
use crate::fmi2_types::*;
use crate::instance::{Instance, Interface, Stage, masks};
use crate::log::Category;
use flyloop_core::number::Compact;
use std::ffi::CStr;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Frees the instance behind `c` (the body of fmi2FreeInstance and fmi3FreeInstance).
pub(crate) fn free_instance(c: fmi2Component, function: &'static str) {
    let status: fmi2Status = with_instance(c, function, masks::FREE_INSTANCE, |instance| {
        instance.event(&format!("{function}: freeing the instance"));
        Ok(())
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

/// The body of fmi2SetDebugLogging and fmi3SetDebugLogging.
///
/// # Safety
/// `categories` must be NULL or point to `n` C strings.
pub(crate) unsafe fn set_debug_logging(
    instance: &mut Instance,
    function: &str,
    on: impl Into<i32>,
    n: usize,
    categories: *const fmi2String,
) -> Result<fmi2Status, FmuError> {
    let on = on.into() != 0;
    // SAFETY: per the function's contract.
    let names = unsafe { c_slice(categories, n, "categories[]") }?;
    if names.is_empty() {
        instance.logging = [on; 4];
        return Ok(fmi2Status::fmi2OK);
    }
    let mut worst = fmi2Status::fmi2OK;
    for &name in names {
        // SAFETY: each entry is NULL or a C string (the contract).
        let name = unsafe { c_str(name) }.map(CStr::to_string_lossy);
        let error = match name.as_deref().map(|n| (n, Category::from_name(n))) {
            Some((_, Some(category))) => {
                instance.logging[category as usize] = on;
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

/// The body of fmi2ExitInitializationMode and fmi3ExitInitializationMode: Co-Simulation
/// goes to step mode, Model Exchange to event mode.
pub(crate) fn exit_initialization_mode(
    instance: &mut Instance,
    function: &str,
) -> Result<(), FmuError> {
    let stage = match instance.interface {
        Interface::CoSimulation => Stage::StepComplete,
        Interface::ModelExchange => Stage::EventMode,
    };
    instance.enter(
        stage,
        &format!("{function}: t = {}", Compact(instance.sim.time())),
    )
}

/// The body of fmi2Terminate and fmi3Terminate.
pub(crate) fn terminate(instance: &mut Instance, function: &str) -> Result<(), FmuError> {
    instance.enter(
        Stage::Terminated,
        &format!("{function}: t = {}", Compact(instance.sim.time())),
    )
}

/// The body of fmi2Reset and fmi3Reset: back to the state right after instantiation.
pub(crate) fn reset(instance: &mut Instance, function: &str) -> Result<(), FmuError> {
    instance.sim.reset()?;
    instance.enter(
        Stage::Instantiated,
        &format!("{function}: back to the start values"),
    )
}
