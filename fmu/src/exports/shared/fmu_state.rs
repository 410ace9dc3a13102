//! FMU states: get, set, free, serialize, deserialize. A state is a copy of everything the
//! instance holds (model with its RNG and physics world, stage, experiment, time grid, start
//! values), so setting it and stepping again repeats the same outputs bit for bit.

use crate::error::FmuError;
use crate::exports::guard::{c_slice, c_slice_mut, write_out};
use crate::instance::Instance;
use flyloop_core::number::Compact;
use std::ffi::c_void;

/// An FMU state pointer (fmi2FMUstate, fmi3FMUState).
type StatePtr = *mut c_void;

/// The importer's variable behind an `FMUstate` argument.
///
/// # Safety
/// `FMUstate` must be NULL or valid for reads and writes of one pointer.
unsafe fn slot<'a>(FMUstate: *mut StatePtr) -> Result<&'a mut StatePtr, FmuError> {
    // SAFETY: per the contract.
    unsafe { FMUstate.as_mut() }.ok_or(FmuError::NullArgument("FMUstate"))
}

/// # Safety
/// `FMUstate` must be NULL or valid for reads and writes of one pointer.
pub(crate) unsafe fn get_state(
    instance: &mut Instance,
    function: &str,
    FMUstate: *mut StatePtr,
) -> Result<(), FmuError> {
    // SAFETY: per the contract.
    let slot = unsafe { slot(FMUstate) }?;
    let bytes = instance.sim.save(instance.stage.code())?;
    *slot = instance.keep_state(*slot as usize, bytes)?.cast();
    let t = Compact(instance.sim.time());
    instance.event(&format!("{function}: state saved at t = {t}"));
    Ok(())
}

/// `FMUstate` is looked up, never dereferenced.
pub(crate) fn set_state(
    instance: &mut Instance,
    function: &str,
    FMUstate: StatePtr,
) -> Result<(), FmuError> {
    if FMUstate.is_null() {
        return Err(FmuError::NullArgument("FMUstate"));
    }
    // A copy: the lookup borrows the instance that restore changes. Every state in the
    // registry was made by fmi2GetFMUstate or checked by fmi2DeSerializeFMUstate, stage
    // code included, and restore changes nothing when it fails.
    let bytes = instance.state(FMUstate as usize)?.bytes.clone();
    let code = instance.sim.restore(&bytes)?;
    instance.stage = instance.stage_from_code(code)?;
    let (t, stage) = (Compact(instance.sim.time()), instance.stage);
    instance.event(&format!(
        "{function}: state restored, t = {t}, stage {stage:?}"
    ));
    Ok(())
}

/// `*FMUstate` NULL is ignored.
///
/// # Safety
/// `FMUstate` must be NULL or valid for reads and writes of one pointer.
pub(crate) unsafe fn free_state(
    instance: &mut Instance,
    _function: &str,
    FMUstate: *mut StatePtr,
) -> Result<(), FmuError> {
    // SAFETY: per the contract.
    let slot = unsafe { slot(FMUstate) }?;
    if !slot.is_null() {
        instance.release_state(*slot as usize)?;
        *slot = std::ptr::null_mut();
    }
    Ok(())
}

/// # Safety
/// `size` must be NULL or writable.
pub(crate) unsafe fn serialized_size(
    instance: &mut Instance,
    _function: &str,
    FMUstate: StatePtr,
    size: *mut usize,
) -> Result<(), FmuError> {
    let length = instance.state(FMUstate as usize)?.bytes.len();
    // SAFETY: per the contract.
    unsafe { write_out(size, length, "size") }
}

/// # Safety
/// `serializedState` must be NULL or writable for `size` bytes.
pub(crate) unsafe fn serialize<B>(
    instance: &mut Instance,
    _function: &str,
    FMUstate: StatePtr,
    serializedState: *mut B,
    size: usize,
) -> Result<(), FmuError> {
    let bytes = &instance.state(FMUstate as usize)?.bytes;
    if size != bytes.len() {
        return Err(FmuError::InvalidArgument(format!(
            "size is {size}, but the serialized state has {} bytes \
             (ask fmi2SerializedFMUstateSize)",
            bytes.len()
        )));
    }
    // SAFETY: per the contract.
    let out = unsafe { c_slice_mut(serializedState.cast::<u8>(), size, "serializedState") }?;
    out.copy_from_slice(bytes);
    Ok(())
}

/// # Safety
/// `serializedState` must be NULL or readable for `size` bytes; `FMUstate` must be NULL or
/// valid for reads and writes of one pointer.
pub(crate) unsafe fn deserialize<B>(
    instance: &mut Instance,
    _function: &str,
    serializedState: *const B,
    size: usize,
    FMUstate: *mut StatePtr,
) -> Result<(), FmuError> {
    // SAFETY: per the contract.
    let slot = unsafe { slot(FMUstate) }?;
    // SAFETY: per the contract.
    let bytes = unsafe { c_slice(serializedState.cast::<u8>(), size, "serializedState") }?;
    instance.stage_from_code(instance.sim.check_saved(bytes)?)?;
    *slot = instance.keep_state(*slot as usize, bytes.to_vec())?.cast();
    Ok(())
}
