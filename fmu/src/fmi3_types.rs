//! The FMI 3.0 C types (fmi3PlatformTypes.h, fmi3FunctionTypes.h), by hand as for FMI 2.0.
//!
//! `fmi3Boolean` is C's `bool`. Values the *caller* hands in are read as `u8` and any
//! non-zero byte counts as true: a Rust `bool` holding anything but 0 or 1 would be undefined
//! behaviour. Caller-given enums are plain `c_int`s for the same reason.
#![allow(non_camel_case_types, non_upper_case_globals, non_snake_case)]

use crate::fmi2_types::fmi2Status;
use std::ffi::{c_char, c_int, c_uint, c_void};

pub type fmi3Instance = *mut c_void;
pub type fmi3InstanceEnvironment = *mut c_void;
pub type fmi3FMUState = *mut c_void;
pub type fmi3ValueReference = c_uint;
pub type fmi3Float32 = f32;
pub type fmi3Float64 = f64;
pub type fmi3Int8 = i8;
pub type fmi3UInt8 = u8;
pub type fmi3Int16 = i16;
pub type fmi3UInt16 = u16;
pub type fmi3Int32 = i32;
pub type fmi3UInt32 = u32;
pub type fmi3Int64 = i64;
pub type fmi3UInt64 = u64;
/// C `bool`, one byte (as `fmi3Clock`).
pub type fmi3Boolean = u8;
pub type fmi3Char = c_char;
pub type fmi3String = *const fmi3Char;
pub type fmi3Byte = u8;
pub type fmi3Binary = *const fmi3Byte;
pub type fmi3Clock = u8;
pub type fmi3IntervalQualifier = c_int;
pub type fmi3DependencyKind = c_int;

pub const fmi3True: fmi3Boolean = 1;
pub const fmi3False: fmi3Boolean = 0;

pub const fmi3Version: &std::ffi::CStr = c"3.0";

/// Status returned by every function; ordered from best to worst.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum fmi3Status {
    fmi3OK = 0,
    fmi3Warning = 1,
    fmi3Discard = 2,
    fmi3Error = 3,
    fmi3Fatal = 4,
}

/// The FMI layer works with FMI 2.0 statuses; fmi2Pending, which no FMI 3.0 function ever
/// produces, would be an error.
impl From<fmi2Status> for fmi3Status {
    fn from(status: fmi2Status) -> Self {
        match status {
            fmi2Status::fmi2OK => fmi3Status::fmi3OK,
            fmi2Status::fmi2Warning => fmi3Status::fmi3Warning,
            fmi2Status::fmi2Discard => fmi3Status::fmi3Discard,
            fmi2Status::fmi2Error | fmi2Status::fmi2Pending => fmi3Status::fmi3Error,
            fmi2Status::fmi2Fatal => fmi3Status::fmi3Fatal,
        }
    }
}

/// Not variadic, unlike FMI 2.0's logger.
pub type fmi3LogMessageCallback =
    unsafe extern "C" fn(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String);

// Never called: intermediate update and Scheduled Execution are not offered.
pub type fmi3IntermediateUpdateCallback = unsafe extern "C" fn(
    fmi3InstanceEnvironment,
    fmi3Float64,
    fmi3Boolean,
    fmi3Boolean,
    fmi3Boolean,
    fmi3Boolean,
    *mut fmi3Boolean,
    *mut fmi3Float64,
);

pub type fmi3ClockUpdateCallback = unsafe extern "C" fn(fmi3InstanceEnvironment);
pub type fmi3LockPreemptionCallback = unsafe extern "C" fn();
pub type fmi3UnlockPreemptionCallback = unsafe extern "C" fn();
