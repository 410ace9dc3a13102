//! FMU states: get, set, free, serialize, deserialize. A state is a copy of everything the
//! instance holds (model with its RNG and physics world, stage, experiment, time grid, start
//! values), so setting it and stepping again repeats the same outputs bit for bit.

use crate::error::FmuError;
use crate::exports::guard::{c_slice, c_slice_mut, write_out};
use crate::fmi2_types::fmi2Byte;
use crate::fmi3_types::fmi3Byte;
use crate::instance::masks;
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

twins! {
    /// Copies the current state. `*FMUstate` NULL gets a new state; a state of this instance
    /// is overwritten in place.
    fn fmi2GetFMUstate / fmi3GetFMUState(c, FMUstate: *mut StatePtr) =
        masks::FMU_STATE => |i, f| {
            let slot = slot(FMUstate)?;
            let bytes = i.sim.save(i.stage.code())?;
            *slot = i.keep_state(*slot as usize, bytes)?.cast();
            i.event(&format!("{f}: state saved at t = {}", Compact(i.sim.time())));
            Ok(())
        };
    /// Restores a state of this instance (stage, time and everything else included);
    /// `FMUstate` is looked up, never dereferenced.
    fn fmi2SetFMUstate / fmi3SetFMUState(c, FMUstate: StatePtr) = masks::FMU_STATE => |i, f| {
        if FMUstate.is_null() {
            return Err(FmuError::NullArgument("FMUstate"));
        }
        // A copy: the lookup borrows the instance that restore changes. Every state in the
        // registry was made by fmi2GetFMUstate or checked by fmi2DeSerializeFMUstate, stage
        // code included, and restore changes nothing when it fails.
        let bytes = i.state(FMUstate as usize)?.bytes.clone();
        let code = i.sim.restore(&bytes)?;
        i.stage = i.stage_from_code(code)?;
        let (t, stage) = (Compact(i.sim.time()), i.stage);
        i.event(&format!("{f}: state restored, t = {t}, stage {stage:?}"));
        Ok(())
    };
    /// Frees a state and sets `*FMUstate` to NULL (NULL is ignored); a second free is an
    /// error.
    fn fmi2FreeFMUstate / fmi3FreeFMUState(c, FMUstate: *mut StatePtr) =
        masks::FMU_STATE => |i| {
            let slot = slot(FMUstate)?;
            if !slot.is_null() {
                i.release_state(*slot as usize)?;
                *slot = std::ptr::null_mut();
            }
            Ok(())
        };
    fn fmi2SerializedFMUstateSize / fmi3SerializedFMUStateSize(
        c,
        FMUstate: StatePtr,
        size: *mut usize,
    ) = masks::FMU_STATE => |i| write_out(size, i.state(FMUstate as usize)?.bytes.len(), "size");
    /// Copies a state's bytes; `size` must be what fmi2SerializedFMUstateSize said.
    fn fmi2SerializeFMUstate / fmi3SerializeFMUState(
        c,
        FMUstate: StatePtr,
        serializedState: *mut fmi2Byte | *mut fmi3Byte,
        size: usize,
    ) = masks::FMU_STATE => |i| {
        let bytes = &i.state(FMUstate as usize)?.bytes;
        if size != bytes.len() {
            return Err(FmuError::InvalidArgument(format!(
                "size is {size}, but the serialized state has {} bytes \
                 (ask fmi2SerializedFMUstateSize)",
                bytes.len()
            )));
        }
        c_slice_mut(serializedState.cast::<u8>(), size, "serializedState")?.copy_from_slice(bytes);
        Ok(())
    };
    /// Makes a state from serialized bytes after checking them completely (format,
    /// checksum, model, a restorable model snapshot); bytes that fail change nothing.
    fn fmi2DeSerializeFMUstate / fmi3DeserializeFMUState(
        c,
        serializedState: *const fmi2Byte | *const fmi3Byte,
        size: usize,
        FMUstate: *mut StatePtr,
    ) = masks::FMU_STATE => |i| {
        let slot = slot(FMUstate)?;
        let bytes = c_slice(serializedState.cast::<u8>(), size, "serializedState")?;
        i.stage_from_code(i.sim.check_saved(bytes)?)?;
        *slot = i.keep_state(*slot as usize, bytes.to_vec())?.cast();
        Ok(())
    };
}
