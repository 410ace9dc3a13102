//! Creating an FMI 2.0 instance and setting up its experiment (FMI 3.0 does both
//! differently).

use crate::api::Api;
use crate::exports::guard::c_str;
use crate::exports::shared::instantiate::{Request, instantiate, resource_path};
use crate::exports::shared::lifecycle::setup_experiment;
use crate::fmi2_types::*;
use crate::instance::{Interface, Stage, masks};
use crate::log::Sink;
use std::ffi::c_char;

/// Returns "default".
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    fmi2TypesPlatform.as_ptr()
}

/// Returns "2.0".
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    fmi2Version.as_ptr()
}

exports! {
    /// Creates a Co-Simulation or Model Exchange instance of the model whose GUID is `fmuGUID`
    /// (Quadrotor: both; Lander2D: Co-Simulation only). Returns NULL, with the reason sent to
    /// the logger when there is one, for NULL or logger-less callbacks, a missing instance
    /// name, an interface the model does not offer, or an unknown GUID.
    fn fmi2Instantiate(
        instanceName: fmi2String,
        fmuType: fmi2Type,
        fmuGUID: fmi2String,
        fmuResourceLocation: fmi2String,
        functions: *const fmi2CallbackFunctions,
        _visible: fmi2Boolean,
        loggingOn: fmi2Boolean,
    ) -> fmi2Component {
        let sink = functions.as_ref().and_then(|f| {
            Some(Sink::Fmi2 {
                callback: f.logger?,
                environment: f.componentEnvironment,
            })
        });
        let interface = match fmuType {
            fmi2CoSimulation => Ok(Interface::CoSimulation),
            fmi2ModelExchange => Ok(Interface::ModelExchange),
            other => Err(format!(
                "fmuType {other} is neither Model Exchange (0) nor Co-Simulation (1)"
            )),
        };
        instantiate(Request {
            function: "fmi2Instantiate",
            api: Api::Fmi2,
            name: c_str(instanceName),
            interface,
            token: c_str(fmuGUID),
            resources: c_str(fmuResourceLocation)
                .and_then(|uri| resource_path(&uri.to_string_lossy())),
            sink,
            logging_on: loggingOn != fmi2False,
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
}
