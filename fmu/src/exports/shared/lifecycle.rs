//! Configuring, initialising, terminating, resetting and freeing an instance: the functions
//! that are the same in both versions, and the experiment both versions set.

use crate::error::FmuError;
use crate::exports::guard::{c_slice, c_str, with_instance};
use crate::fmi2_types::*;
use crate::fmi3_types::*;
use crate::instance::{Instance, Interface, Stage, masks};
use crate::log::CATEGORIES;
use flyloop_core::number::Compact;
use std::ffi::CStr;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Frees the instance behind `c` (the body of fmi2FreeInstance and fmi3FreeInstance).
fn free_instance(c: fmi2Component, function: &'static str) {
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

exports! {
    /// Frees the instance and every FMU state it handed out. NULL is ignored.
    fn fmi2FreeInstance(c: fmi2Component) {
        free_instance(c, "fmi2FreeInstance");
    }

    /// FMI 3.0's [`fmi2FreeInstance`].
    fn fmi3FreeInstance(instance: fmi3Instance) {
        free_instance(instance, "fmi3FreeInstance");
    }
}

twins! {
    /// Switches log categories: those named in `categories`, or all of them when
    /// `nCategories` is 0. An unknown category name is an error (the others still switch).
    fn fmi2SetDebugLogging / fmi3SetDebugLogging(
        c,
        loggingOn: fmi2Boolean | fmi3Boolean,
        nCategories: usize,
        categories: *const fmi2String,
    ) = masks::SET_DEBUG_LOGGING => |i, f| {
        let on = loggingOn != 0;
        let names = c_slice(categories, nCategories, "categories[]")?;
        if names.is_empty() {
            i.logging = [on; 4];
        }
        let mut worst = fmi2Status::fmi2OK;
        for &name in names {
            let name = c_str(name).map(CStr::to_string_lossy);
            let known = |n: &str| CATEGORIES.iter().position(|(c, _)| c.to_str() == Ok(n));
            let error = match name.as_deref().map(|n| (n, known(n))) {
                Some((_, Some(category))) => {
                    i.logging[category] = on;
                    continue;
                }
                Some((n, None)) => FmuError::InvalidArgument(format!(
                    "unknown log category `{n}` (known: logEvents, logStatusWarning, \
                     logStatusError, logStatusFatal)"
                )),
                None => FmuError::NullArgument("categories[i]"),
            };
            worst = worst.max(i.report(f, &error));
        }
        Ok(worst)
    };
    /// Co-Simulation goes to step mode, Model Exchange to event mode.
    fn fmi2ExitInitializationMode / fmi3ExitInitializationMode(c) =
        masks::EXIT_INITIALIZATION_MODE => |i, f| {
            let stage = match i.interface {
                Interface::CoSimulation => Stage::StepComplete,
                Interface::ModelExchange => Stage::EventMode,
            };
            i.enter(stage, &format!("{f}: t = {}", Compact(i.sim.time())))
        };
    fn fmi2Terminate / fmi3Terminate(c) = masks::TERMINATE => |i, f| {
        i.enter(Stage::Terminated, &format!("{f}: t = {}", Compact(i.sim.time())))
    };
    /// Back to the state right after instantiation: start values, no experiment. FMU states
    /// handed out stay valid.
    fn fmi2Reset / fmi3Reset(c) = masks::RESET => |i, f| {
        i.sim.reset()?;
        i.enter(Stage::Instantiated, &format!("{f}: back to the start values"))
    };
}
