//! FMU states through FMI 3.0: the same states as FMI 2.0's (see
//! [`crate::exports::fmi2GetFMUstate`]), under FMI 3.0's names.

use crate::exports::fmu_state::{
    deserialize, free_state, get_state, serialize, serialized_size, set_state,
};
use crate::fmi3_types::*;

/// Copies the current state; `*FMUState` NULL gets a new state, a state of this instance is
/// overwritten in place.
///
/// # Safety
/// `FMUState` must be NULL or valid for reads and writes of one pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    // SAFETY: forwarded contract.
    unsafe { get_state(instance, "fmi3GetFMUState", FMUState) }.into()
}

/// Restores a state of this instance (stage, time and everything else included).
///
/// # Safety
/// `instance` must be NULL or live; `FMUState` is looked up, never dereferenced.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
) -> fmi3Status {
    // SAFETY: forwarded contract.
    unsafe { set_state(instance, "fmi3SetFMUState", FMUState) }.into()
}

/// Frees a state and sets `*FMUState` to NULL.
///
/// # Safety
/// `FMUState` must be NULL or valid for reads and writes of one pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    // SAFETY: forwarded contract.
    unsafe { free_state(instance, "fmi3FreeFMUState", FMUState) }.into()
}

/// # Safety
/// `size` must be NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    // SAFETY: forwarded contract.
    unsafe { serialized_size(instance, "fmi3SerializedFMUStateSize", FMUState, size) }.into()
}

/// # Safety
/// `serializedState` must be NULL or writable for `size` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    serializedState: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    let function = "fmi3SerializeFMUState";
    // SAFETY: forwarded contract.
    unsafe { serialize(instance, function, FMUState, serializedState, size) }.into()
}

/// Makes a state from serialized bytes after checking them completely.
///
/// # Safety
/// `serializedState` must be NULL or readable for `size` bytes; `FMUState` NULL or valid for
/// reads and writes of one pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    serializedState: *const fmi3Byte,
    size: usize,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    let function = "fmi3DeserializeFMUState";
    // SAFETY: forwarded contract.
    unsafe { deserialize(instance, function, serializedState, size, FMUState) }.into()
}
