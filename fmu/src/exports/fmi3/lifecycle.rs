//! Creating, initialising, terminating, resetting and freeing an instance through FMI 3.0.

use super::with_instance3;
use crate::exports::guard::guarded;
use crate::exports::instantiate::{Request, create_instance};
use crate::exports::lifecycle::{
    c_str, exit_initialization_mode, free_instance, reset, set_debug_logging, setup_experiment,
    terminate,
};
use crate::exports::model_exchange::enter_event_mode;
use crate::fmi3_types::*;
use crate::instance::{Interface, Stage, masks3};
use crate::log::Sink;
use crate::table::Api;
use std::ffi::c_char;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Returns "3.0".
#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    guarded(fmi3Version.as_ptr(), || fmi3Version.as_ptr())
}

/// # Safety
/// `categories` must be NULL or point to `nCategories` C strings.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    loggingOn: fmi3Boolean,
    nCategories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    let on = loggingOn != fmi3False;
    // SAFETY: forwarded contract.
    unsafe { set_debug_logging(instance, "fmi3SetDebugLogging", on, nCategories, categories) }
        .into()
}

/// Instantiates for `interface`, or refuses with the reason it holds; NULL on any failure.
///
/// # Safety
/// The strings must be NULL or NUL-terminated.
unsafe fn instantiate(
    function: &'static str,
    interface: Result<Interface, String>,
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: Option<fmi3LogMessageCallback>,
) -> fmi3Instance {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: NULL or NUL-terminated strings (the contract).
        let (name, token) = unsafe { (c_str(instanceName), c_str(instantiationToken)) };
        create_instance(&Request {
            function,
            api: Api::Fmi3,
            name,
            interface,
            token,
            sink: Sink::Fmi3 {
                callback: logMessage,
                environment: instanceEnvironment,
            },
            logging_on: loggingOn != fmi3False,
        })
    }));
    match outcome {
        Ok(Some(instance)) => instance.cast(),
        _ => std::ptr::null_mut(),
    }
}

/// A Model Exchange instance of the model whose token is `instantiationToken` (Quadrotor;
/// Lander2D is Co-Simulation only). NULL, with the reason logged, on any failure.
///
/// # Safety
/// The strings must be NULL or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: Option<fmi3LogMessageCallback>,
) -> fmi3Instance {
    // SAFETY: forwarded contract.
    unsafe {
        instantiate(
            "fmi3InstantiateModelExchange",
            Ok(Interface::ModelExchange),
            instanceName,
            instantiationToken,
            loggingOn,
            instanceEnvironment,
            logMessage,
        )
    }
}

/// A Co-Simulation instance. Refused (NULL, with the reason logged) with `eventModeUsed`:
/// the FMUs declare hasEventMode="false". Early return and intermediate variables are not
/// offered; `earlyReturnAllowed` and the intermediate callback are never used.
///
/// # Safety
/// The strings must be NULL or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    _earlyReturnAllowed: fmi3Boolean,
    _requiredIntermediateVariables: *const fmi3ValueReference,
    _nRequiredIntermediateVariables: usize,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: Option<fmi3LogMessageCallback>,
    _intermediateUpdate: Option<fmi3IntermediateUpdateCallback>,
) -> fmi3Instance {
    let interface = if eventModeUsed != fmi3False {
        Err(
            "eventModeUsed is true, but this FMU has no event mode in Co-Simulation \
             (hasEventMode=\"false\")"
                .to_string(),
        )
    } else {
        Ok(Interface::CoSimulation)
    };
    // SAFETY: forwarded contract.
    unsafe {
        instantiate(
            "fmi3InstantiateCoSimulation",
            interface,
            instanceName,
            instantiationToken,
            loggingOn,
            instanceEnvironment,
            logMessage,
        )
    }
}

/// Scheduled Execution is not offered: always NULL, with the reason logged.
///
/// # Safety
/// The strings must be NULL or NUL-terminated.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: Option<fmi3LogMessageCallback>,
    _clockUpdate: Option<fmi3ClockUpdateCallback>,
    _lockPreemption: Option<fmi3LockPreemptionCallback>,
    _unlockPreemption: Option<fmi3UnlockPreemptionCallback>,
) -> fmi3Instance {
    let refusal = "Scheduled Execution is not offered (the modelDescription has no \
                   ScheduledExecution element)";
    // SAFETY: forwarded contract.
    unsafe {
        instantiate(
            "fmi3InstantiateScheduledExecution",
            Err(refusal.to_string()),
            instanceName,
            instantiationToken,
            loggingOn,
            instanceEnvironment,
            logMessage,
        )
    }
}

/// Frees the instance and every FMU state it handed out. NULL is ignored.
///
/// # Safety
/// `instance` must be NULL or not freed yet.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    free_instance(instance, "fmi3FreeInstance");
}

/// Sets the experiment (start and stop time; the tolerance is not used) and enters
/// initialization mode.
///
/// # Safety
/// `instance` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    _toleranceDefined: fmi3Boolean,
    _tolerance: fmi3Float64,
    startTime: fmi3Float64,
    stopTimeDefined: fmi3Boolean,
    stopTime: fmi3Float64,
) -> fmi3Status {
    let function = "fmi3EnterInitializationMode";
    with_instance3(
        instance,
        function,
        masks3::ENTER_INITIALIZATION_MODE,
        |instance| {
            let stop = (stopTimeDefined != fmi3False).then_some(stopTime);
            setup_experiment(instance, function, startTime, stop)?;
            instance.stage = Stage::InitializationMode;
            Ok(())
        },
    )
}

/// Co-Simulation enters step mode, Model Exchange event mode.
///
/// # Safety
/// `instance` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    exit_initialization_mode(instance, "fmi3ExitInitializationMode").into()
}

/// Model Exchange only (Co-Simulation has no event mode here).
///
/// # Safety
/// `instance` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status {
    enter_event_mode(instance, "fmi3EnterEventMode").into()
}

/// # Safety
/// `instance` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    terminate(instance, "fmi3Terminate").into()
}

/// Back to the state right after instantiation: start values, no experiment.
///
/// # Safety
/// `instance` must be NULL or live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    reset(instance, "fmi3Reset").into()
}
