//! fmi3Get*/fmi3Set* for the three types the models use (Float64, Int32, Boolean), over the
//! FMI 3.0 variables: an array takes `len` consecutive entries of `values`, and `nValues`
//! must be the sum. Unknown value references or a wrong `nValues` refuse the whole call
//! (positions in `values` would be guesswork); after that every variable is handled as in
//! FMI 2.0: a refused one is logged with its reason while the others still take effect.

use crate::error::FmuError;
use crate::fmi3_types::*;
use crate::instance::{Instance, masks, masks3};
use crate::table::{ModelTable, Source, Variable3};
use std::ops::Range;

/// The variables behind `vrs`, each with the range of its values in the caller's array, after
/// checking that every one exists and that together they hold `n_values` values (no
/// allocation: this runs on every get and set).
pub(crate) fn resolve<'a>(
    table: &'static ModelTable,
    vrs: &'a [fmi3ValueReference],
    n_values: usize,
) -> Result<impl Iterator<Item = (&'static Variable3, Range<usize>)> + use<'a>, FmuError> {
    let mut total = 0;
    for &vr in vrs {
        let v = table.variable3(vr);
        total += v.ok_or(FmuError::UnknownValueReference(vr))?.len();
    }
    if total != n_values {
        return Err(FmuError::InvalidArgument(format!(
            "nValues is {n_values}, but the {} value references hold {total} values \
             (an array counts all its elements); nothing was done",
            vrs.len()
        )));
    }
    let mut at = 0;
    Ok(vrs
        .iter()
        .filter_map(|&vr| table.variable3(vr))
        .map(move |v| {
            at += v.len();
            (v, at - v.len()..at)
        }))
}

/// Element `i` of `v`, which is not a model variable.
pub(crate) fn computed(instance: &Instance, v: &Variable3) -> Result<f64, FmuError> {
    match v.source {
        Source::EventIndicator(k) => {
            let mut z = vec![0.0; instance.sim.table().info.event_indicators.len()];
            instance.sim.hybrid(z.len(), "ni")?.event_indicators(&mut z);
            Ok(z[k])
        }
        _ => Ok(instance.sim.time()),
    }
}

/// Why `v`, which is not a model variable, cannot be set.
pub(crate) fn not_settable(v: &Variable3) -> FmuError {
    let (name, reason) = match v.source {
        Source::Time => (
            "time",
            "it is the independent variable (fmi3SetTime or fmi3DoStep moves it)",
        ),
        _ => ("event indicator", "it is calculated from the state"),
    };
    FmuError::NotSettable { name, reason }
}

/// Defines fmi3Get<T> and fmi3Set<T> for C type `$t` and FMI 3.0 type `$ty`: the getter
/// converts through `$to_c`, the setter (allowed in `$mask`) through `$from_c`. The body is
/// here, not in a helper, so the model is two calls away: the guard, then the engine (after
/// [`resolve`] has checked every value reference before any value is touched).
macro_rules! accessors {
    ($get:ident, $set:ident, $t:ty, $ty:expr, $mask:path, $to_c:expr, $from_c:expr $(,)?) => {
        forward! {
            /// Reads the variables (arrays element by element) into `values`.
            fn $get(
                instance: fmi3Instance,
                valueReferences: *const fmi3ValueReference,
                nValueReferences: usize,
                values: *mut $t,
                nValues: usize,
            ) -> fmi3Status = masks3::GET_VALUE => |instance, function| {
                use $crate::exports::fmi3::values::{computed, resolve};
                use $crate::{api::Api, fmi2_types::fmi2Status, table::Source};
                use $crate::exports::guard::{c_slice, c_slice_mut};
                let vrs = c_slice(valueReferences, nValueReferences, "valueReferences[]")?;
                let variables = resolve(instance.sim.table(), vrs, nValues)?;
                let out = c_slice_mut(values, nValues, "values[]")?;
                let mut worst = fmi2Status::fmi2OK;
                for (v, range) in variables {
                    let slots = &mut out[range];
                    let read = Api::Fmi3.check($ty, v).and_then(|()| match &v.source {
                        Source::Model(elements) => {
                            for (slot, index) in slots.iter_mut().zip(elements.clone()) {
                                *slot = $to_c(instance.sim.get(index));
                            }
                            Ok(())
                        }
                        _ => computed(instance, v).map(|value| slots[0] = $to_c(value)),
                    });
                    if let Err(e) = read {
                        worst = worst.max(instance.report(function, &e));
                    }
                }
                Ok(worst)
            };
            /// Writes `values` to the variables (arrays element by element).
            fn $set(
                instance: fmi3Instance,
                valueReferences: *const fmi3ValueReference,
                nValueReferences: usize,
                values: *const $t,
                nValues: usize,
            ) -> fmi3Status = $mask => |instance, function| {
                use $crate::exports::fmi3::values::{not_settable, resolve};
                use $crate::{api::Api, fmi2_types::fmi2Status, table::Source};
                use $crate::exports::guard::c_slice;
                let vrs = c_slice(valueReferences, nValueReferences, "valueReferences[]")?;
                let variables = resolve(instance.sim.table(), vrs, nValues)?;
                let values = c_slice(values, nValues, "values[]")?;
                let initialised = instance.initialised();
                let mut worst = fmi2Status::fmi2OK;
                for (v, range) in variables {
                    let written = Api::Fmi3.check($ty, v).and_then(|()| match &v.source {
                        // Every element is tried; the first refusal is reported.
                        Source::Model(elements) => (elements.clone())
                            .zip(&values[range])
                            .map(|(index, &value)| {
                                instance.sim.set(index, $from_c(value), initialised)
                            })
                            .fold(Ok(()), Result::and),
                        _ => Err(not_settable(v)),
                    });
                    if let Err(e) = written {
                        worst = worst.max(instance.report(function, &e));
                    }
                }
                Ok(worst)
            };
        }
    };
}
pub(crate) use accessors;

accessors! {
    fmi3GetFloat64,
    fmi3SetFloat64,
    fmi3Float64,
    "Float64",
    masks::SET_REAL,
    |v| v,
    |v| v,
}
// Int32 variables hold integers within i32 (their table ranges say so).
accessors! {
    fmi3GetInt32,
    fmi3SetInt32,
    fmi3Int32,
    "Int32",
    masks::SET_OTHER,
    |v| v as i32,
    f64::from,
}
accessors! {
    fmi3GetBoolean,
    fmi3SetBoolean,
    fmi3Boolean,
    "Boolean",
    masks::SET_OTHER,
    |v| u8::from(v != 0.0),
    |v: u8| if v != 0 { 1.0 } else { 0.0 },
}
