//! What fmi2Instantiate and FMI 3.0's fmi3Instantiate* share.

use crate::api::Api;
use crate::fmi2_types::fmi2Status;
use crate::instance::{Instance, Interface};
use crate::log::{Logger, Sink};
use crate::models;
use std::ffi::{CStr, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// An instantiation request, its C arguments already read.
pub(crate) struct Request<'a> {
    pub function: &'static str,
    pub api: Api,
    pub name: Option<&'a CStr>,
    /// The interface asked for, or why the argument does not name one.
    pub interface: Result<Interface, String>,
    /// FMI 2.0's GUID or FMI 3.0's instantiation token.
    pub token: Option<&'a CStr>,
    pub sink: Sink,
    pub logging_on: bool,
}

/// The instance `request` asks for, or why there is none.
fn new_instance(request: &Request<'_>) -> Result<Instance, String> {
    let name = (request.name.filter(|n| !n.is_empty())).ok_or("instanceName is NULL or empty")?;
    let interface = request.interface.clone()?;
    let token_name = request.api.token_name();
    let token = request.token.ok_or(format!("{token_name} is NULL"))?;
    let token = token.to_string_lossy();
    let Some(sim) = models::simulation_for(request.api, &token) else {
        let known: Vec<String> = models::tables()
            .iter()
            .map(|t| format!("{} {}", t.info.identifier, t.token(request.api)))
            .collect();
        return Err(format!(
            "{token_name} {token} is not one of this library's models ({}); the \
             modelDescription.xml and the binary do not belong together",
            known.join(", ")
        ));
    };
    let sim = sim.map_err(|e| format!("the model does not start: {e}"))?;
    let identifier = sim.table().info.identifier;
    if interface == Interface::ModelExchange && sim.table().model_exchange.is_none() {
        return Err(format!(
            "{identifier} is Co-Simulation only (its physics engine steps internally); \
             instantiate it for Co-Simulation"
        ));
    }
    let logger = Logger {
        sink: request.sink,
        instance_name: name.to_owned(),
    };
    let instance = Instance::new(request.api, interface, logger, request.logging_on, sim);
    let function = request.function;
    instance.event(&format!(
        "{function}: {identifier} {interface:?} instance ({token}) created"
    ));
    Ok(instance)
}

/// The instance `build` asks for, or NULL after logging why not (`build` gives `None` when
/// there is no logger to tell why; a panic, caught here, gives NULL too).
pub(crate) fn instantiate<'a>(build: impl FnOnce() -> Option<Request<'a>>) -> *mut c_void {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let request = build()?;
        let message = match new_instance(&request) {
            Ok(instance) => return Some(Box::into_raw(Box::new(instance)).cast()),
            Err(message) => format!("{}: {message}", request.function),
        };
        let name = request.name.map(CStr::to_owned).unwrap_or_default();
        let logger = Logger {
            sink: request.sink,
            instance_name: name,
        };
        logger.log(fmi2Status::fmi2Error, &message);
        None
    }));
    outcome.ok().flatten().unwrap_or(std::ptr::null_mut())
}
