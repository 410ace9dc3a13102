//! Creating, configuring, initialising, terminating, resetting and freeing an FMI 2.0
//! instance, and its FMU states.

use crate::exports::guard::{c_str, guarded};
use crate::exports::shared::fmu_state::*;
use crate::exports::shared::instantiate::{Request, instantiate};
use crate::exports::shared::lifecycle::*;
use crate::fmi2_types::*;
use crate::instance::{Interface, Stage, masks};
use crate::log::Sink;
use crate::table::Api;
use std::ffi::c_char;

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

exports! {
    /// Frees the instance and every FMU state it handed out. NULL is ignored.
    fn fmi2FreeInstance(c: fmi2Component) {
        free_instance(c, "fmi2FreeInstance");
    }

    /// Creates a Co-Simulation or Model Exchange instance of the model whose GUID is `fmuGUID`
    /// (Quadrotor: both; Lander2D: Co-Simulation only). Returns NULL, with the reason sent to
    /// the logger when there is one, for NULL or logger-less callbacks, a missing instance
    /// name, an interface the model does not offer, or an unknown GUID.
    fn fmi2Instantiate(
        instanceName: fmi2String,
        fmuType: fmi2Type,
        fmuGUID: fmi2String,
        _fmuResourceLocation: fmi2String,
        functions: *const fmi2CallbackFunctions,
        _visible: fmi2Boolean,
        loggingOn: fmi2Boolean,
    ) -> fmi2Component {
        instantiate(|| {
            let functions = functions.as_ref().copied()?;
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
            let (name, token) = (c_str(instanceName), c_str(fmuGUID));
            let logging_on = loggingOn != fmi2False;
            Some(Request {
                function: "fmi2Instantiate",
                api: Api::Fmi2,
                name,
                interface,
                token,
                sink,
                logging_on,
            })
        })
    }
}

forward! {
    /// Sets the start time (and the stop time, if defined). The tolerance is not used: both
    /// models step on fixed grids.
    fn fmi2SetupExperiment(
        c: fmi2Component,
        _toleranceDefined: fmi2Boolean,
        _tolerance: fmi2Real,
        startTime: fmi2Real,
        stopTimeDefined: fmi2Boolean,
        stopTime: fmi2Real,
    ) -> fmi2Status = masks::SETUP_EXPERIMENT => |i, f| {
        setup_experiment(i, f, startTime, (stopTimeDefined != fmi2False).then_some(stopTime))
    };
    fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status =
        masks::ENTER_INITIALIZATION_MODE => |i, f| i.enter(Stage::InitializationMode, f);
    /// Switches log categories: those named in `categories`, or all of them when
    /// `nCategories` is 0. An unknown category name is an error (the others still switch).
    fn fmi2SetDebugLogging(
        c: fmi2Component,
        loggingOn: fmi2Boolean,
        nCategories: usize,
        categories: *const fmi2String,
    ) -> fmi2Status = masks::SET_DEBUG_LOGGING => set_debug_logging;
    /// Co-Simulation goes to step mode, Model Exchange to event mode.
    fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status =
        masks::EXIT_INITIALIZATION_MODE => exit_initialization_mode;
    fn fmi2Terminate(c: fmi2Component) -> fmi2Status = masks::TERMINATE => terminate;
    /// Back to the state right after fmi2Instantiate: start values, no experiment. FMU
    /// states handed out stay valid.
    fn fmi2Reset(c: fmi2Component) -> fmi2Status = masks::RESET => reset;
    /// Copies the current state. `*FMUstate` NULL gets a new state; a state of this instance
    /// is overwritten in place.
    fn fmi2GetFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status =
        masks::FMU_STATE => get_state;
    /// Restores a state of this instance (stage, time and everything else included);
    /// `FMUstate` is looked up, never dereferenced.
    fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status =
        masks::FMU_STATE => set_state;
    /// Frees a state and sets `*FMUstate` to NULL; a second free is an error.
    fn fmi2FreeFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status =
        masks::FMU_STATE => free_state;
    fn fmi2SerializedFMUstateSize(
        c: fmi2Component,
        FMUstate: fmi2FMUstate,
        size: *mut usize,
    ) -> fmi2Status = masks::FMU_STATE => serialized_size;
    /// Copies a state's bytes; `size` must be what fmi2SerializedFMUstateSize said.
    fn fmi2SerializeFMUstate(
        c: fmi2Component,
        FMUstate: fmi2FMUstate,
        serializedState: *mut fmi2Byte,
        size: usize,
    ) -> fmi2Status = masks::FMU_STATE => serialize;
    /// Makes a state from serialized bytes after checking them completely (format,
    /// checksum, model, a restorable model snapshot); bytes that fail change nothing.
    fn fmi2DeSerializeFMUstate(
        c: fmi2Component,
        serializedState: *const fmi2Byte,
        size: usize,
        FMUstate: *mut fmi2FMUstate,
    ) -> fmi2Status = masks::FMU_STATE => deserialize;
}
