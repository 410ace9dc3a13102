//! fmi3Get*/fmi3Set* for the three types the models use (Float64, Int32, Boolean), over the
//! FMI 3.0 variables: an array takes `len` consecutive entries of `values`, and `nValues`
//! must be the sum. Unknown value references or a wrong `nValues` refuse the whole call
//! (positions in `values` would be guesswork); after that every variable is handled as in
//! FMI 2.0: a refused one is logged with its reason while the others still take effect.

use crate::error::FmuError;
use crate::exports::guard::{c_slice, c_slice_mut, with_instance};
use crate::exports::values::initialised;
use crate::fmi2_types::fmi2Status;
use crate::fmi3_types::*;
use crate::fmi3_variables::{Layout3, Source, Variable3};
use crate::instance::{Instance, Mask, masks3};
use crate::simulation::FmiType;

/// The variables behind `vrs`, after checking that every one exists and that together they
/// hold `n_values` values (no allocation: this runs on every get and set).
fn resolve<'a>(
    layout: &'static Layout3,
    vrs: &'a [fmi3ValueReference],
    n_values: usize,
) -> Result<impl Iterator<Item = &'static Variable3> + use<'a>, FmuError> {
    let mut total = 0;
    for &vr in vrs {
        total += layout
            .variable(vr)
            .ok_or(FmuError::UnknownValueReference(vr))?
            .len();
    }
    if total != n_values {
        return Err(FmuError::InvalidArgument(format!(
            "nValues is {n_values}, but the {} value references hold {total} values \
             (an array counts all its elements); nothing was done",
            vrs.len()
        )));
    }
    Ok(vrs.iter().filter_map(|&vr| layout.variable(vr)))
}

fn check_type(v: &'static Variable3, ty: FmiType) -> Result<(), FmuError> {
    if ty.matches(v.kind) {
        Ok(())
    } else {
        Err(ty.mismatch(&v.name, v.value_reference, v.kind))
    }
}

/// Element `i` of `v`.
fn read(instance: &Instance, v: &Variable3, i: usize, ty: FmiType) -> Result<f64, FmuError> {
    match &v.source {
        Source::Model(elements) => instance.sim.get(elements[i], ty),
        Source::Time => Ok(instance.sim.time()),
        Source::EventIndicator(k) => {
            let n = instance.sim.table().fmi3.event_indicators.len();
            let mut z = vec![0.0; n];
            instance.sim.event_indicators(&mut z)?;
            Ok(z[*k])
        }
    }
}

/// One fmi3Get* call.
///
/// # Safety
/// `vr` must be NULL or hold `nvr` elements, `values` NULL or `n_values`.
pub(crate) unsafe fn get_values<T>(
    instance: fmi3Instance,
    function: &'static str,
    ty: FmiType,
    (vr, nvr): (*const fmi3ValueReference, usize),
    (values, n_values): (*mut T, usize),
    to_c: fn(f64) -> T,
) -> fmi3Status {
    with_instance(instance, function, masks3::GET_VALUE, |instance| {
        // SAFETY: per the function's contract.
        let vrs = unsafe { c_slice(vr, nvr, "valueReferences[]") }?;
        let variables = resolve(&instance.sim.table().fmi3, vrs, n_values)?;
        // SAFETY: per the function's contract.
        let out = unsafe { c_slice_mut(values, n_values, "values[]") }?;
        let mut worst = fmi2Status::fmi2OK;
        let mut at = 0;
        for v in variables {
            let slots = &mut out[at..at + v.len()];
            at += v.len();
            let result = check_type(v, ty).and_then(|()| {
                for (i, slot) in slots.iter_mut().enumerate() {
                    *slot = to_c(read(instance, v, i, ty)?);
                }
                Ok(())
            });
            if let Err(e) = result {
                worst = worst.max(instance.report(function, &e));
            }
        }
        Ok(worst)
    })
    .into()
}

/// One fmi3Set* function: its name, its allowed stages and its type.
pub(crate) struct Setter {
    pub function: &'static str,
    pub mask: Mask,
    pub ty: FmiType,
}

/// One fmi3Set* call.
///
/// # Safety
/// `vr` must be NULL or hold `nvr` elements, `values` NULL or `n_values`.
pub(crate) unsafe fn set_values<T: Copy>(
    instance: fmi3Instance,
    setter: Setter,
    (vr, nvr): (*const fmi3ValueReference, usize),
    (values, n_values): (*const T, usize),
    from_c: fn(T) -> f64,
) -> fmi3Status {
    let Setter { function, mask, ty } = setter;
    with_instance(instance, function, mask, |instance| {
        // SAFETY: per the function's contract.
        let vrs = unsafe { c_slice(vr, nvr, "valueReferences[]") }?;
        let variables = resolve(&instance.sim.table().fmi3, vrs, n_values)?;
        // SAFETY: per the function's contract.
        let values = unsafe { c_slice(values, n_values, "values[]") }?;
        let initialised = initialised(instance);
        let mut worst = fmi2Status::fmi2OK;
        let mut at = 0;
        for v in variables {
            let mine = &values[at..at + v.len()];
            at += v.len();
            let result = check_type(v, ty).and_then(|()| match &v.source {
                Source::Model(elements) => {
                    // Every element is tried; the first refusal is reported.
                    let mut first = Ok(());
                    for (&element, &value) in elements.iter().zip(mine) {
                        let r = instance.sim.set(element, ty, from_c(value), initialised);
                        if first.is_ok() {
                            first = r;
                        }
                    }
                    first
                }
                Source::Time => Err(FmuError::NotSettable {
                    name: "time",
                    reason: "it is the independent variable (fmi3SetTime or fmi3DoStep moves it)",
                }),
                Source::EventIndicator(_) => Err(FmuError::NotSettable {
                    name: "event indicator",
                    reason: "it is calculated from the state",
                }),
            });
            if let Err(e) = result {
                worst = worst.max(instance.report(function, &e));
            }
        }
        Ok(worst)
    })
    .into()
}

/// Defines fmi3Get<T> and fmi3Set<T> for C type `$t`: the getter reads variables of
/// `$ty` through `$to_c`, the setter (allowed in `$mask`) writes them through `$from_c`.
macro_rules! accessors {
    ($get:ident, $set:ident, $t:ty, $ty:expr, $mask:expr, $to_c:expr, $from_c:expr) => {
        /// Reads the variables (arrays element by element) into `values`.
        ///
        /// # Safety
        /// `valueReferences` NULL or `nValueReferences` elements; `values` NULL or `nValues`.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $get(
            instance: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            values: *mut $t,
            nValues: usize,
        ) -> fmi3Status {
            let vrs = (valueReferences, nValueReferences);
            let function = stringify!($get);
            // SAFETY: forwarded contract.
            unsafe { get_values(instance, function, $ty, vrs, (values, nValues), $to_c) }
        }

        /// Writes `values` to the variables (arrays element by element).
        ///
        /// # Safety
        /// `valueReferences` NULL or `nValueReferences` elements; `values` NULL or `nValues`.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $set(
            instance: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            values: *const $t,
            nValues: usize,
        ) -> fmi3Status {
            let setter = Setter {
                function: stringify!($set),
                mask: $mask,
                ty: $ty,
            };
            let vrs = (valueReferences, nValueReferences);
            // SAFETY: forwarded contract.
            unsafe { set_values(instance, setter, vrs, (values, nValues), $from_c) }
        }
    };
}
pub(crate) use accessors;

accessors!(
    fmi3GetFloat64,
    fmi3SetFloat64,
    fmi3Float64,
    FmiType::Float64,
    masks3::SET_FLOAT64,
    |v| v,
    |v| v
);
// Int32 variables hold integers within i32 (their table ranges say so).
accessors!(
    fmi3GetInt32,
    fmi3SetInt32,
    fmi3Int32,
    FmiType::Int32,
    masks3::SET_OTHER,
    |v| v as i32,
    f64::from
);
accessors!(
    fmi3GetBoolean,
    fmi3SetBoolean,
    fmi3Boolean,
    FmiType::Boolean3,
    masks3::SET_OTHER,
    |v| u8::from(v != 0.0),
    |v: u8| if v != 0 { 1.0 } else { 0.0 }
);
