//! A logger for Rust code that plays the importer (the crate's tests and benchmarks): the
//! one place where a fixed-arity Rust function becomes the variadic `fmi2CallbackLogger`.
//!
//! The FMU always calls its logger with exactly one argument after the format ("%s",
//! message). On x86-64 and AArch64 Linux a variadic call passes that argument where a
//! fixed-arity function with one more string parameter reads it. (Stable Rust cannot define
//! a C-variadic function.)

use crate::fmi2_types::{
    fmi2CallbackFunctions, fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status, fmi2String,
};

/// The logger's one call shape: environment, instance name, status, category, format
/// ("%s") and the message.
pub type LoggerShape = unsafe extern "C" fn(
    fmi2ComponentEnvironment,
    fmi2String,
    fmi2Status,
    fmi2String,
    fmi2String,
    fmi2String,
);

/// `receiver` as the variadic callback type.
pub fn variadic(receiver: LoggerShape) -> fmi2CallbackLogger {
    // SAFETY: same argument registers for the one call shape the FMU uses (module docs).
    unsafe { std::mem::transmute::<LoggerShape, fmi2CallbackLogger>(receiver) }
}

/// Callbacks with `receiver` as the logger, `environment` handed back to it, and no memory
/// or step-finished callbacks.
pub fn callbacks(
    receiver: LoggerShape,
    environment: fmi2ComponentEnvironment,
) -> fmi2CallbackFunctions {
    fmi2CallbackFunctions {
        logger: Some(variadic(receiver)),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: environment,
    }
}

/// A receiver that drops every message (benchmarks).
///
/// # Safety
///
/// Nothing to uphold: it reads none of its arguments (`unsafe` only to have the logger's type).
pub unsafe extern "C" fn quiet(
    _env: fmi2ComponentEnvironment,
    _name: fmi2String,
    _status: fmi2Status,
    _category: fmi2String,
    _format: fmi2String,
    _message: fmi2String,
) {
}
