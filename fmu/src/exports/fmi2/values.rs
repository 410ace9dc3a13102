//! fmi2Get*/fmi2Set* for Real, Integer, Boolean and String. Every element is handled: a
//! refused one is logged with its reason and the call returns the worst status, while the
//! others still take effect (set) or are filled in (get).

use crate::api::Api;
use crate::exports::guard::{c_slice, c_slice_mut};
use crate::fmi2_types::*;
use crate::instance::masks;

/// Defines fmi2Get<T> and fmi2Set<T> for C type `$t` and FMI 2.0 type `$ty`: the getter
/// converts through `$to_c`, the setter (allowed in `$mask`) through `$from_c`. The body is
/// here, not in a helper, so the model is two calls away: the guard, then the engine.
macro_rules! accessors {
    ($get:ident, $set:ident, $t:ty, $ty:expr, $mask:path, $to_c:expr, $from_c:expr $(,)?) => {
        forward! {
            fn $get(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                value: *mut $t,
            ) -> fmi2Status = masks::GET_VALUE => |instance, function| {
                let vrs = c_slice(vr, nvr, "vr[]")?;
                let values = c_slice_mut(value, nvr, "value[]")?;
                let table = instance.sim.table();
                let mut worst = fmi2Status::fmi2OK;
                for (&vr, slot) in vrs.iter().zip(values) {
                    match table.lookup(vr, Api::Fmi2, $ty) {
                        Ok(index) => *slot = $to_c(instance.sim.get(index)),
                        Err(e) => worst = worst.max(instance.report(function, &e)),
                    }
                }
                Ok(worst)
            };
            fn $set(
                c: fmi2Component,
                vr: *const fmi2ValueReference,
                nvr: usize,
                value: *const $t,
            ) -> fmi2Status = $mask => |instance, function| {
                let vrs = c_slice(vr, nvr, "vr[]")?;
                let values = c_slice(value, nvr, "value[]")?;
                let (initialised, table) = (instance.initialised(), instance.sim.table());
                let mut worst = fmi2Status::fmi2OK;
                for (&vr, &v) in vrs.iter().zip(values) {
                    let set = |index| instance.sim.set(index, $from_c(v), initialised);
                    if let Err(e) = table.lookup(vr, Api::Fmi2, $ty).and_then(set) {
                        worst = worst.max(instance.report(function, &e));
                    }
                }
                Ok(worst)
            };
        }
    };
}

accessors! {
    fmi2GetReal,
    fmi2SetReal,
    fmi2Real,
    "Real",
    masks::SET_REAL,
    |v| v,
    |v| v,
}
// Integer variables hold integers within i32 (their table ranges say so).
accessors! {
    fmi2GetInteger,
    fmi2SetInteger,
    fmi2Integer,
    "Integer",
    masks::SET_OTHER,
    |v| v as fmi2Integer,
    f64::from,
}
accessors! {
    fmi2GetBoolean,
    fmi2SetBoolean,
    fmi2Boolean,
    "Boolean",
    masks::SET_OTHER,
    |v| if v != 0.0 { fmi2True } else { fmi2False },
    |v| if v != fmi2False { 1.0 } else { 0.0 },
}
// There are no String variables: every value reference is refused (with its real type when
// it exists); no value is ever converted.
accessors! {
    fmi2GetString,
    fmi2SetString,
    fmi2String,
    "String",
    masks::SET_OTHER,
    |_| std::ptr::null(),
    |_| f64::NAN,
}
