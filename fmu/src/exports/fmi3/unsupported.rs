//! The FMI 3.0 functions for what these FMUs do not have: variables of the other ten types,
//! clocks, structural parameters (configuration mode), per-element dependencies, directional
//! and adjoint derivatives, evaluateDiscreteStates and Scheduled Execution. Each is exported
//! (importers bind every function) and answers fmi3Error with the reason in the log.

use super::values::{accessors, resolve};
use crate::api::Api;
use crate::error::FmuError;
use crate::exports::guard::{c_slice, refuse, with_instance};
use crate::fmi2_types::fmi2Status;
use crate::fmi3_types::*;
use crate::instance::{Instance, masks, masks3};

/// Defines fmi3Get<T> and fmi3Set<T> for types no variable has: every value reference is
/// refused, naming the variable's real type when it exists; no value is ever converted.
macro_rules! no_variables {
    ($($get:ident $set:ident $t:ty, $name:literal = $zero:expr;)*) => {$(
        accessors!(
            $get,
            $set,
            $t,
            $name,
            masks::SET_OTHER,
            |_| $zero,
            |_| f64::NAN
        );
    )*};
}

no_variables! {
    fmi3GetFloat32 fmi3SetFloat32 fmi3Float32, "Float32" = 0.0;
    fmi3GetInt8 fmi3SetInt8 fmi3Int8, "Int8" = 0;
    fmi3GetUInt8 fmi3SetUInt8 fmi3UInt8, "UInt8" = 0;
    fmi3GetInt16 fmi3SetInt16 fmi3Int16, "Int16" = 0;
    fmi3GetUInt16 fmi3SetUInt16 fmi3UInt16, "UInt16" = 0;
    fmi3GetUInt32 fmi3SetUInt32 fmi3UInt32, "UInt32" = 0;
    fmi3GetInt64 fmi3SetInt64 fmi3Int64, "Int64" = 0;
    fmi3GetUInt64 fmi3SetUInt64 fmi3UInt64, "UInt64" = 0;
    fmi3GetString fmi3SetString fmi3String, "String" = std::ptr::null();
}

/// The body of fmi3GetBinary and fmi3SetBinary: after the checks every fmi3Get*/fmi3Set*
/// makes (known value references, `nValues`, `values` not NULL), every variable is refused
/// with its real type.
///
/// # Safety
/// `vr` and `values` must be NULL or hold `nvr` and `n_values` elements.
unsafe fn no_binary<B>(
    instance: &mut Instance,
    function: &str,
    (vr, nvr): (*const fmi3ValueReference, usize),
    values: *const B,
    n_values: usize,
) -> Result<fmi2Status, FmuError> {
    // SAFETY: per the function's contract.
    let vrs = unsafe { c_slice(vr, nvr, "valueReferences[]") }?;
    let variables = resolve(instance.sim.table(), vrs, n_values)?;
    // SAFETY: per the function's contract.
    unsafe { c_slice(values, n_values, "values[]") }?;
    let mut worst = fmi2Status::fmi2OK;
    for (v, _) in variables {
        if let Err(e) = Api::Fmi3.check("Binary", v) {
            worst = worst.max(instance.report(function, &e));
        }
    }
    Ok(worst)
}

forward! {
    /// No Binary variables: every value reference is refused.
    fn fmi3GetBinary(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        _valueSizes: *mut usize,
        values: *mut fmi3Binary,
        nValues: usize,
    ) -> fmi3Status = masks3::GET_VALUE => |i, f| {
        no_binary(i, f, (valueReferences, nValueReferences), values.cast_const(), nValues)
    };
    /// No Binary variables: every value reference is refused.
    fn fmi3SetBinary(
        instance: fmi3Instance,
        valueReferences: *const fmi3ValueReference,
        nValueReferences: usize,
        _valueSizes: *const usize,
        values: *const fmi3Binary,
        nValues: usize,
    ) -> fmi3Status = masks::SET_OTHER => |i, f| {
        no_binary(i, f, (valueReferences, nValueReferences), values, nValues)
    };
}

const NO_CLOCKS: &str = "this FMU has no clocks";
const NO_CONFIGURATION: &str = "configuration mode: this FMU has no structural parameters";
const NO_DEPENDENCIES: &str = "per-element dependencies \
                               (providesPerElementDependencies=\"false\"); the modelDescription's \
                               ModelStructure lists the dependencies";

/// An array of value references (in the signatures below, whose arguments are never read).
type Vrs = *const fmi3ValueReference;

/// Defines exported functions that only refuse, each with the types of its C arguments after
/// the instance.
macro_rules! refused {
    ($($name:ident($($t:ty),* $(,)?) => $why:expr;)*) => {
        $(
            /// Not offered: answers fmi3Error with the reason in the log.
            ///
            /// # Safety
            /// `instance` must be NULL or live; nothing else is read.
            #[unsafe(no_mangle)]
            pub unsafe extern "C" fn $name(instance: fmi3Instance, $(_: $t),*) -> fmi3Status {
                with_instance(instance, stringify!($name), masks3::ANY, |_| refuse($why))
            }
        )*
    };
}

refused! {
    fmi3GetClock(Vrs, usize, *mut fmi3Clock) => NO_CLOCKS;
    fmi3SetClock(Vrs, usize, *const fmi3Clock) => NO_CLOCKS;
    fmi3GetIntervalDecimal(Vrs, usize, *mut f64, *mut fmi3IntervalQualifier) => NO_CLOCKS;
    fmi3GetIntervalFraction(Vrs, usize, *mut u64, *mut u64, *mut fmi3IntervalQualifier)
        => NO_CLOCKS;
    fmi3GetShiftDecimal(Vrs, usize, *mut f64) => NO_CLOCKS;
    fmi3GetShiftFraction(Vrs, usize, *mut u64, *mut u64) => NO_CLOCKS;
    fmi3SetIntervalDecimal(Vrs, usize, *const f64) => NO_CLOCKS;
    fmi3SetIntervalFraction(Vrs, usize, *const u64, *const u64) => NO_CLOCKS;
    fmi3SetShiftDecimal(Vrs, usize, *const f64) => NO_CLOCKS;
    fmi3SetShiftFraction(Vrs, usize, *const u64, *const u64) => NO_CLOCKS;
    fmi3ActivateModelPartition(fmi3ValueReference, f64) => "Scheduled Execution is not offered";
    fmi3EnterConfigurationMode() => NO_CONFIGURATION;
    fmi3ExitConfigurationMode() => NO_CONFIGURATION;
    fmi3EvaluateDiscreteStates()
        => "evaluateDiscreteStates (providesEvaluateDiscreteStates=\"false\")";
    fmi3GetNumberOfVariableDependencies(fmi3ValueReference, *mut usize) => NO_DEPENDENCIES;
    fmi3GetVariableDependencies(
        fmi3ValueReference,
        *mut usize,
        *mut fmi3ValueReference,
        *mut usize,
        *mut fmi3DependencyKind,
        usize,
    ) => NO_DEPENDENCIES;
    fmi3GetDirectionalDerivative(Vrs, usize, Vrs, usize, *const f64, usize, *mut f64, usize)
        => "directional derivatives (providesDirectionalDerivative=\"false\")";
    fmi3GetAdjointDerivative(Vrs, usize, Vrs, usize, *const f64, usize, *mut f64, usize)
        => "adjoint derivatives (providesAdjointDerivatives=\"false\")";
}
