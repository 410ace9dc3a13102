//! What every export does around its body: the NULL check of the instance, the stage check,
//! the mapping of errors to a status plus a log message, and `catch_unwind`, so that a panic
//! becomes fmi2Fatal with a message instead of unwinding into (and aborting) the importer.

use crate::error::FmuError;
use crate::fmi2_types::{fmi2Component, fmi2Status};
use crate::instance::{Instance, Mask, Stage};
use std::any::Any;
use std::ffi::{CStr, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// Runs `body` for the instance behind `c` if `mask` allows its stage, and answers its status
/// (`()` is OK) in the caller's FMI version. A NULL `c` gives fmi2Error (there is no logger to
/// tell); an `Err` is logged as "`function`: reason"; a panic enters the Fatal stage.
pub(crate) fn with_instance<R: Into<fmi2Status>, S: From<fmi2Status>>(
    c: fmi2Component,
    function: &'static str,
    mask: Mask,
    body: impl FnOnce(&mut Instance) -> Result<R, FmuError>,
) -> S {
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: a non-NULL fmi2Component is a pointer fmi2Instantiate returned and
        // fmi2FreeInstance has not freed (the importer's side of the contract).
        let Some(instance) = (unsafe { c.cast::<Instance>().as_mut() }) else {
            return fmi2Status::fmi2Error;
        };
        let result = instance.check_stage(mask).and_then(|()| body(instance));
        match result {
            Ok(status) => status.into(),
            Err(error) => instance.report(function, &error),
        }
    }));
    S::from(outcome.unwrap_or_else(|payload| {
        let message = panic_message(payload);
        // SAFETY: as above; the borrow inside the closure ended with the unwind.
        if let Some(instance) = unsafe { c.cast::<Instance>().as_mut() } {
            instance.stage = Stage::Fatal;
            let message = format!(
                "{function}: internal error (panic: {message}); the instance is unusable, \
                 call fmi2FreeInstance"
            );
            let _ = catch_unwind(AssertUnwindSafe(|| {
                instance.log(fmi2Status::fmi2Fatal, &message)
            }));
        }
        fmi2Status::fmi2Fatal
    }))
}

/// The body of a function this FMU does not offer: refuses with `why`.
pub(crate) fn refuse(why: &'static str) -> Result<(), FmuError> {
    Err(FmuError::NotSupported(why))
}

/// A body without a status of its own answers OK.
impl From<()> for fmi2Status {
    fn from((): ()) -> Self {
        fmi2Status::fmi2OK
    }
}

/// The text of a panic payload. The payload is leaked, not dropped: a payload whose drop
/// panicked again would abort the importing process.
fn panic_message(payload: Box<dyn Any + Send>) -> String {
    let message = if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic payload".to_string()
    };
    std::mem::forget(payload);
    message
}

/// The slice behind a C array argument; NULL is allowed only for an empty array.
///
/// # Safety
/// If `ptr` is not NULL it must point to `n` readable `T`s that stay valid for `'a`.
pub(crate) unsafe fn c_slice<'a, T>(
    ptr: *const T,
    n: usize,
    name: &'static str,
) -> Result<&'a [T], FmuError> {
    if n == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(FmuError::NullArgument(name));
    }
    if n > isize::MAX as usize / std::mem::size_of::<T>().max(1) {
        return Err(FmuError::InvalidArgument(format!(
            "array `{name}` claims {n} elements, more than memory can hold"
        )));
    }
    // SAFETY: non-NULL, length checked against isize::MAX bytes, validity per the contract.
    Ok(unsafe { std::slice::from_raw_parts(ptr, n) })
}

/// The mutable slice behind a C output array; NULL is allowed only for an empty array.
///
/// # Safety
/// If `ptr` is not NULL it must point to `n` writable `T`s that stay valid for `'a`.
pub(crate) unsafe fn c_slice_mut<'a, T>(
    ptr: *mut T,
    n: usize,
    name: &'static str,
) -> Result<&'a mut [T], FmuError> {
    // SAFETY: the checks of c_slice, the importer's contract, and the importer does not alias
    // its output arrays.
    let checked = unsafe { c_slice(ptr.cast_const(), n, name) }?;
    Ok(unsafe { std::slice::from_raw_parts_mut(checked.as_ptr().cast_mut(), n) })
}

/// A `&CStr` from a C string argument.
///
/// # Safety
/// `s` must be NULL or NUL-terminated and valid for the call.
pub(crate) unsafe fn c_str<'a>(s: *const c_char) -> Option<&'a CStr> {
    // SAFETY: per the function's contract.
    (!s.is_null()).then(|| unsafe { CStr::from_ptr(s) })
}

/// Fails on the first NULL among the output pointers `outs` (checked before anything is done,
/// so that a call with a NULL one changes nothing).
pub(crate) fn no_null<T>(outs: &[(*mut T, &'static str)]) -> Result<(), FmuError> {
    match outs.iter().find(|(pointer, _)| pointer.is_null()) {
        Some(&(_, name)) => Err(FmuError::NullArgument(name)),
        None => Ok(()),
    }
}

/// `*ptr = value` for an output pointer argument.
///
/// # Safety
/// If `ptr` is not NULL it must be valid for writes of `T`.
pub(crate) unsafe fn write_out<T>(
    ptr: *mut T,
    value: T,
    name: &'static str,
) -> Result<(), FmuError> {
    if ptr.is_null() {
        return Err(FmuError::NullArgument(name));
    }
    // SAFETY: non-NULL and writable per the contract.
    unsafe { ptr.write(value) };
    Ok(())
}

#[cfg(test)]
#[allow(dead_code)]
#[path = "../../tests/support/importer_logger.rs"]
mod importer_logger;

#[cfg(test)]
mod tests {
    use super::importer_logger;
    use super::*;
    use crate::exports::{fmi2DoStep, fmi2FreeInstance, fmi2GetReal, fmi2Instantiate};
    use crate::fmi2_types::*;
    use crate::instance::masks;

    #[test]
    fn a_panic_becomes_fatal_with_a_message_and_only_free_instance_remains() {
        let recorder = importer_logger::Recorder::default();
        let callbacks = recorder.callbacks();
        let guid = crate::models::tables()[0].guid.clone();
        // SAFETY: valid strings and callbacks.
        let c = unsafe {
            fmi2Instantiate(
                c"p".as_ptr(),
                fmi2CoSimulation,
                guid.as_ptr(),
                std::ptr::null(),
                &callbacks,
                fmi2False,
                fmi2False,
            )
        };
        assert!(!c.is_null());
        let status: fmi2Status = with_instance(
            c,
            "fmi2Probe",
            masks::SET_REAL,
            |_| -> Result<(), FmuError> {
                panic!("100% broken");
            },
        );
        assert_eq!(status, fmi2Status::fmi2Fatal);
        let last = recorder.last().unwrap();
        assert_eq!(
            (last.status, last.category.as_str()),
            (fmi2Status::fmi2Fatal, "logStatusFatal")
        );
        let message = last.message;
        assert!(
            message.starts_with("fmi2Probe: internal error (panic: 100% broken)"),
            "{message}"
        );
        // SAFETY: live instance.
        unsafe {
            assert_eq!(fmi2DoStep(c, 0.0, 0.1, 0), fmi2Status::fmi2Error);
            assert_eq!(
                fmi2GetReal(c, [100u32].as_ptr(), 1, [0.0].as_mut_ptr()),
                fmi2Status::fmi2Error
            );
            fmi2FreeInstance(c);
        }
        let last = recorder.last().unwrap();
        assert!(last.message.contains("stage Fatal"), "{last:?}");
        assert!(recorder.bad_formats.lock().unwrap().is_empty());
    }
}
