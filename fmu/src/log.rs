//! Logging through the importer's logger (FMI 2.0's variadic one or FMI 3.0's), by category.
//! fmi2Instantiate's loggingOn switches events and warnings; errors and fatal errors are on
//! from the start, because a status without its reason helps nobody.

use crate::fmi2_types::{fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status};
use crate::fmi3_types::{fmi3InstanceEnvironment, fmi3LogMessageCallback};
use std::ffi::{CStr, CString};

/// Every category's name and description, in modelDescription order.
#[rustfmt::skip]
pub const CATEGORIES: [(&CStr, &str); 4] = [
    (c"logEvents", "Lifecycle: instantiation, initialisation, reset, termination, FMU states"),
    (c"logStatusWarning", "Calls that return fmi2Warning"),
    (c"logStatusError", "Calls that return fmi2Error, with the reason"),
    (
        c"logStatusFatal",
        "Calls that return fmi2Fatal (an internal failure caught at the C boundary)",
    ),
];

/// The importer's logging callback and the environment it wants back.
#[derive(Debug, Clone, Copy)]
pub enum Sink {
    Fmi2 {
        callback: fmi2CallbackLogger,
        environment: fmi2ComponentEnvironment,
    },
    /// FMI 3.0 allows a NULL logger: then nothing is logged.
    Fmi3 {
        callback: Option<fmi3LogMessageCallback>,
        environment: fmi3InstanceEnvironment,
    },
}

/// The importer's logger and the instance name it is given.
#[derive(Debug)]
pub struct Logger {
    pub sink: Sink,
    pub instance_name: CString,
}

impl Logger {
    /// Calls the callback once with `message` in the category of `status` (NUL bytes in it
    /// become U+FFFD; FMI 2.0: always through a "%s" format so that a '%' in it is printed,
    /// never interpreted).
    pub fn log(&self, status: fmi2Status, message: &str) {
        let text = CString::new(message.replace('\0', "\u{fffd}")).unwrap_or_default();
        let category = CATEGORIES[category_of(status)].0.as_ptr();
        match self.sink {
            // SAFETY: callback and environment came together from the importer, which keeps
            // them valid while the instance lives; every string is NUL-terminated and
            // outlives the call; the format consumes exactly one string argument.
            Sink::Fmi2 {
                callback,
                environment,
            } => unsafe {
                let name = self.instance_name.as_ptr();
                callback(
                    environment,
                    name,
                    status,
                    category,
                    c"%s".as_ptr(),
                    text.as_ptr(),
                );
            },
            // FMI 3.0's logger has no instance name: the environment tells instances apart.
            // SAFETY: as above.
            Sink::Fmi3 {
                callback: Some(callback),
                environment,
            } => unsafe { callback(environment, status.into(), category, text.as_ptr()) },
            Sink::Fmi3 { callback: None, .. } => {}
        }
    }
}

/// The position in [`CATEGORIES`] of the category a message with `status` is logged in.
pub fn category_of(status: fmi2Status) -> usize {
    match status {
        fmi2Status::fmi2OK | fmi2Status::fmi2Pending => 0,
        fmi2Status::fmi2Warning | fmi2Status::fmi2Discard => 1,
        fmi2Status::fmi2Error => 2,
        fmi2Status::fmi2Fatal => 3,
    }
}
