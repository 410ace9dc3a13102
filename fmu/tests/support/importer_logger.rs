//! A logger for Rust code that plays the importer (the crate's tests and benchmarks; not part
//! of the shipped library): the
//! one place where a fixed-arity Rust function becomes the variadic `fmi2CallbackLogger`.
//!
//! The FMU always calls its logger with exactly one argument after the format ("%s",
//! message). On x86-64 and AArch64 Linux a variadic call passes that argument where a
//! fixed-arity function with one more string parameter reads it. (Stable Rust cannot define
//! a C-variadic function.)

use flyloop_fmu::fmi2_types::{
    fmi2CallbackFunctions, fmi2CallbackLogger, fmi2ComponentEnvironment, fmi2Status, fmi2String,
};
use flyloop_fmu::fmi3_types::{fmi3InstanceEnvironment, fmi3LogMessageCallback, fmi3Status};
use std::ffi::{CStr, c_char, c_void};
use std::sync::Mutex;

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

/// One message the FMU logged.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    pub instance: String,
    pub status: fmi2Status,
    pub category: String,
    pub message: String,
}

/// A receiver's memory: everything the FMU logged to it (tests).
#[derive(Debug, Default)]
pub struct Recorder {
    pub entries: Mutex<Vec<Entry>>,
    /// Formats other than "%s" (must stay empty: the FMU never passes a raw message).
    pub bad_formats: Mutex<Vec<String>>,
}

impl Recorder {
    /// Callbacks whose logger records into this recorder, which must outlive every instance
    /// they are given to.
    pub fn callbacks(&self) -> fmi2CallbackFunctions {
        callbacks(record, self as *const Recorder as *mut c_void)
    }

    /// FMI 3.0's logger and environment recording into this recorder, which must outlive
    /// every instance they are given to.
    pub fn fmi3_logger(&self) -> (fmi3LogMessageCallback, fmi3InstanceEnvironment) {
        (record3, self as *const Recorder as *mut c_void)
    }

    /// The last message logged, if any.
    pub fn last(&self) -> Option<Entry> {
        self.entries.lock().ok()?.last().cloned()
    }
}

fn text(p: *const c_char) -> String {
    if p.is_null() {
        "<NULL>".into()
    } else {
        // SAFETY: the FMU passes NUL-terminated strings valid for the call.
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }
}

/// The receiver behind [`Recorder::callbacks`].
///
/// # Safety
///
/// `env` must be a live [`Recorder`] and the strings NUL-terminated or NULL.
pub unsafe extern "C" fn record(
    env: fmi2ComponentEnvironment,
    instance: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    format: fmi2String,
    message: fmi2String,
) {
    // SAFETY: the caller's contract (env is a Recorder).
    let recorder = unsafe { &*(env as *const Recorder) };
    let format = text(format);
    if format != "%s" {
        if let Ok(mut bad) = recorder.bad_formats.lock() {
            bad.push(format);
        }
    }
    if let Ok(mut entries) = recorder.entries.lock() {
        entries.push(Entry {
            instance: text(instance),
            status,
            category: text(category),
            message: text(message),
        });
    }
}

/// The FMI 3.0 receiver behind [`Recorder::fmi3_logger`] (no instance name: recorded as "").
///
/// # Safety
///
/// `env` must be a live [`Recorder`] and the strings NUL-terminated or NULL.
pub unsafe extern "C" fn record3(
    env: fmi3InstanceEnvironment,
    status: fmi3Status,
    category: fmi2String,
    message: fmi2String,
) {
    // SAFETY: the caller's contract (env is a Recorder).
    let recorder = unsafe { &*(env as *const Recorder) };
    let status = match status {
        fmi3Status::fmi3OK => fmi2Status::fmi2OK,
        fmi3Status::fmi3Warning => fmi2Status::fmi2Warning,
        fmi3Status::fmi3Discard => fmi2Status::fmi2Discard,
        fmi3Status::fmi3Error => fmi2Status::fmi2Error,
        fmi3Status::fmi3Fatal => fmi2Status::fmi2Fatal,
    };
    if let Ok(mut entries) = recorder.entries.lock() {
        entries.push(Entry {
            instance: String::new(),
            status,
            category: text(category),
            message: text(message),
        });
    }
}
