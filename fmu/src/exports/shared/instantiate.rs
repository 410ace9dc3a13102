//! What fmi2Instantiate and FMI 3.0's fmi3Instantiate* share.

use crate::api::Api;
use crate::fmi2_types::fmi2Status;
use crate::instance::{Instance, Interface, Stage};
use crate::log::{Logger, Sink};
use crate::models;
use std::collections::HashMap;
use std::ffi::{CStr, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::PathBuf;

/// An instantiation request, its C arguments already read.
pub(crate) struct Request<'a> {
    pub function: &'static str,
    pub api: Api,
    pub name: Option<&'a CStr>,
    /// The interface asked for, or why the argument does not name one.
    pub interface: Result<Interface, String>,
    /// FMI 2.0's GUID or FMI 3.0's instantiation token.
    pub token: Option<&'a CStr>,
    /// The unpacked FMU's resources folder, when the importer named one it can be read from.
    pub resources: Option<PathBuf>,
    /// `None` (FMI 2.0 without a logger callback): no one to tell why instantiation fails.
    pub sink: Option<Sink>,
    pub logging_on: bool,
}

/// The interface and token `request` names, or why its arguments name none.
fn checked(request: &Request<'_>) -> Result<(Interface, String), String> {
    (request.name.filter(|n| !n.is_empty())).ok_or("instanceName is NULL or empty")?;
    let interface = request.interface.clone()?;
    let token_name = request.api.token_name();
    let token = request.token.ok_or(format!("{token_name} is NULL"))?;
    Ok((interface, token.to_string_lossy().into_owned()))
}

/// Why no model of this library has `token`.
fn unknown(api: Api, token: &str) -> String {
    let known: Vec<String> = models::tables()
        .iter()
        .map(|t| format!("{} {}", t.info.identifier, t.token(api)))
        .collect();
    format!(
        "{} {token} is not one of this library's models ({}); the modelDescription.xml and \
         the binary do not belong together",
        api.token_name(),
        known.join(", ")
    )
}

/// The instance `request` asks for, or NULL after logging why not (without a logger: NULL;
/// a panic, caught here, gives NULL too).
pub(crate) fn instantiate(request: Request<'_>) -> *mut c_void {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let (function, api) = (request.function, request.api);
        let logger = Logger {
            sink: request.sink?,
            instance_name: request.name.map(CStr::to_owned).unwrap_or_default(),
        };
        let found = checked(&request).and_then(|(interface, token)| {
            let sim = models::simulation_in(api, &token, request.resources.as_deref())
                .ok_or_else(|| unknown(api, &token))?;
            let sim = sim.map_err(|e| format!("the model does not start: {e}"))?;
            let table = sim.table();
            if interface == Interface::ModelExchange && table.model_exchange.is_none() {
                return Err(format!(
                    "{} is Co-Simulation only (its physics engine steps internally); \
                     instantiate it for Co-Simulation",
                    table.info.identifier
                ));
            }
            Ok((interface, sim))
        });
        let (interface, sim) = match found {
            Ok(found) => found,
            Err(message) => {
                logger.log(fmi2Status::fmi2Error, &format!("{function}: {message}"));
                return None;
            }
        };
        let on = request.logging_on;
        let instance = Instance {
            api,
            interface,
            logger,
            logging: [on, on, true, true],
            stage: Stage::Instantiated,
            sim,
            states: HashMap::new(),
        };
        let table = instance.sim.table();
        let (identifier, token) = (table.info.identifier, table.token(api));
        instance.event(&format!(
            "{function}: {identifier} {interface:?} instance ({token}) created"
        ));
        Some(Box::into_raw(Box::new(instance)).cast())
    }));
    outcome.ok().flatten().unwrap_or(std::ptr::null_mut())
}

/// FMI 2.0's fmuResourceLocation (a `file:` URI) as a path: `file:///a/b`, `file:/a/b` and
/// `file://localhost/a/b`, with %XX escapes decoded; `None` for another scheme.
pub(crate) fn resource_path(uri: &str) -> Option<PathBuf> {
    let rest = uri.strip_prefix("file:")?;
    let rest = match rest.strip_prefix("//") {
        Some(authority) => &authority[authority.find('/')?..],
        None => rest,
    };
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let escaped = (bytes[i] == b'%')
            .then(|| std::str::from_utf8(bytes.get(i + 1..i + 3)?).ok())
            .flatten()
            .and_then(|hex| u8::from_str_radix(hex, 16).ok());
        match escaped {
            Some(b) => {
                out.push(b);
                i += 3;
            }
            None => {
                out.push(bytes[i]);
                i += 1;
            }
        }
    }
    Some(PathBuf::from(String::from_utf8(out).ok()?))
}

#[cfg(test)]
mod tests {
    use super::resource_path;
    use std::path::Path;

    #[test]
    fn resource_uris_become_paths() {
        let want = Path::new("/tmp/fmu dir/resources");
        for uri in [
            "file:///tmp/fmu%20dir/resources",
            "file:/tmp/fmu%20dir/resources",
            "file://localhost/tmp/fmu%20dir/resources",
        ] {
            assert_eq!(resource_path(uri).as_deref(), Some(want), "{uri}");
        }
        assert_eq!(resource_path("http://example.org/r"), None);
    }
}
