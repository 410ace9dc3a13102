//! Creating an FMI 3.0 instance and entering initialization mode (with the experiment,
//! which FMI 2.0 sets in a function of its own).

use crate::api::Api;
use crate::exports::guard::c_str;
use crate::exports::shared::instantiate::{Request, instantiate};
use crate::exports::shared::lifecycle::setup_experiment;
use crate::fmi3_types::*;
use crate::instance::{Interface, Stage, masks};
use crate::log::Sink;
use std::ffi::c_char;

/// Returns "3.0".
#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    fmi3Version.as_ptr()
}

/// What the fmi3Instantiate* functions do for `interface` (or the reason it holds).
///
/// # Safety
/// The strings must be NULL or NUL-terminated.
unsafe fn instantiate3(
    function: &'static str,
    interface: Result<Interface, String>,
    (name, token, logging_on): (fmi3String, fmi3String, fmi3Boolean),
    resource_path: fmi3String,
    (environment, callback): (fmi3InstanceEnvironment, Option<fmi3LogMessageCallback>),
) -> fmi3Instance {
    instantiate(Request {
        function,
        api: Api::Fmi3,
        // SAFETY: NULL or NUL-terminated strings (the contract).
        name: unsafe { c_str(name) },
        interface,
        // SAFETY: as above.
        token: unsafe { c_str(token) },
        // SAFETY: as above. FMI 3.0's resourcePath is a plain path.
        resources: unsafe { c_str(resource_path) }
            .map(|p| std::path::PathBuf::from(p.to_string_lossy().into_owned())),
        sink: Some(Sink::Fmi3 {
            callback,
            environment,
        }),
        logging_on: logging_on != fmi3False,
    })
}

exports! {
    /// A Model Exchange instance of the model whose token is `instantiationToken`
    /// (Quadrotor; Lander2D is Co-Simulation only). NULL, with the reason logged, on any
    /// failure.
    fn fmi3InstantiateModelExchange(
        instanceName: fmi3String,
        instantiationToken: fmi3String,
        resourcePath: fmi3String,
        _visible: fmi3Boolean,
        loggingOn: fmi3Boolean,
        instanceEnvironment: fmi3InstanceEnvironment,
        logMessage: Option<fmi3LogMessageCallback>,
    ) -> fmi3Instance {
        let args = (instanceName, instantiationToken, loggingOn);
        let logger = (instanceEnvironment, logMessage);
        instantiate3("fmi3InstantiateModelExchange", Ok(Interface::ModelExchange), args, resourcePath, logger)
    }

    /// A Co-Simulation instance. Refused (NULL, with the reason logged) with
    /// `eventModeUsed`: the FMUs declare hasEventMode="false". Early return and intermediate
    /// variables are not offered; `earlyReturnAllowed` and the intermediate callback are
    /// never used.
    fn fmi3InstantiateCoSimulation(
        instanceName: fmi3String,
        instantiationToken: fmi3String,
        resourcePath: fmi3String,
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
        let args = (instanceName, instantiationToken, loggingOn);
        let logger = (instanceEnvironment, logMessage);
        let interface = if eventModeUsed != fmi3False {
            let why = "eventModeUsed is true, but this FMU has no event mode in Co-Simulation \
                       (hasEventMode=\"false\")";
            Err(why.to_string())
        } else {
            Ok(Interface::CoSimulation)
        };
        instantiate3("fmi3InstantiateCoSimulation", interface, args, resourcePath, logger)
    }

    /// Scheduled Execution is not offered: always NULL, with the reason logged.
    fn fmi3InstantiateScheduledExecution(
        instanceName: fmi3String,
        instantiationToken: fmi3String,
        resourcePath: fmi3String,
        _visible: fmi3Boolean,
        loggingOn: fmi3Boolean,
        instanceEnvironment: fmi3InstanceEnvironment,
        logMessage: Option<fmi3LogMessageCallback>,
        _clockUpdate: Option<fmi3ClockUpdateCallback>,
        _lockPreemption: Option<fmi3LockPreemptionCallback>,
        _unlockPreemption: Option<fmi3UnlockPreemptionCallback>,
    ) -> fmi3Instance {
        let args = (instanceName, instantiationToken, loggingOn);
        let logger = (instanceEnvironment, logMessage);
        let why = "Scheduled Execution is not offered (the modelDescription has no \
                   ScheduledExecution element)";
        instantiate3("fmi3InstantiateScheduledExecution", Err(why.to_string()), args, resourcePath, logger)
    }
}

forward! {
    /// Sets the experiment (start and stop time; the tolerance is not used) and enters
    /// initialization mode.
    fn fmi3EnterInitializationMode(
        instance: fmi3Instance,
        _toleranceDefined: fmi3Boolean,
        _tolerance: fmi3Float64,
        startTime: fmi3Float64,
        stopTimeDefined: fmi3Boolean,
        stopTime: fmi3Float64,
    ) -> fmi3Status = masks::ENTER_INITIALIZATION_MODE => |i, f| {
        let stop = (stopTimeDefined != fmi3False).then_some(stopTime);
        setup_experiment(i, f, startTime, stop).map(|()| i.stage = Stage::InitializationMode)
    };
}
