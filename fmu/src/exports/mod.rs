//! Every FMI 2.0 and FMI 3.0 function, exported unmangled from the library (`extern "C"`):
//! [`fmi2`] and [`fmi3`] hold each version's own, `shared` those the same in both and the
//! bodies both versions run, and `guard` what every export does around its body. Tests call
//! them directly through the rlib; importers load them from the .so.
// Function and parameter names are the standard's.
#![allow(non_snake_case, non_upper_case_globals)]

/// Defines exported C functions, each a C signature and a body.
macro_rules! exports {
    ($(
        $(#[$attr:meta])*
        fn $name:ident($($arg:ident: $t:ty),* $(,)?) $(-> $ret:ty)? $body:block
    )*) => {$(
        $(#[$attr])*
        ///
        /// # Safety
        /// Every pointer argument must be NULL or valid as the FMI standard says; an instance
        /// must be one this library made and has not freed.
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name($($arg: $t),*) $(-> $ret)? {
            // SAFETY: the caller's contract above, which each body forwards.
            #[allow(unused_unsafe)]
            unsafe { $body }
        }
    )*};
}

/// Defines exported C functions whose body runs once the instance passed the NULL and stage
/// checks of `mask` ([`guard::with_instance`]): `fn name(arguments) -> status = mask => body;`
/// where `body` is `|instance| expression`, or `|instance, function|` with the export's name.
macro_rules! forward {
    ($(
        $(#[$attr:meta])*
        fn $name:ident($c:ident: $ct:ty $(, $arg:ident: $t:ty)* $(,)?) -> $ret:ty =
            $mask:path => |$i:ident $(, $f:ident)?| $body:expr;
    )*) => {$(
        exports! {
            $(#[$attr])*
            fn $name($c: $ct $(, $arg: $t)*) -> $ret {
                $(let $f = stringify!($name);)?
                $crate::exports::guard::with_instance($c, stringify!($name), $mask, |$i| $body)
            }
        }
    )*};
}

/// Defines an FMI 2.0 function and its FMI 3.0 twin, which does the same, from one
/// declaration: `fn fmi2Name / fmi3Name(instance, arguments) = mask => body;` as in
/// [`forward!`]. An argument whose C type differs between the versions is written
/// `name: Fmi2Type | Fmi3Type`.
macro_rules! twins {
    ($(
        $(#[doc = $doc:literal])*
        fn $f2:ident / $f3:ident($c:ident $(, $arg:ident: $t2:ty $(| $t3:ty)?)* $(,)?) =
            $mask:path => |$i:ident $(, $f:ident)?| $body:expr;
    )*) => {$(
        forward! {
            $(#[doc = $doc])*
            fn $f2($c: $crate::fmi2_types::fmi2Component $(, $arg: $t2)*)
                -> $crate::fmi2_types::fmi2Status = $mask => |$i $(, $f)?| $body;
            #[doc = concat!("FMI 3.0's [`", stringify!($f2), "`].")]
            fn $f3($c: $crate::fmi3_types::fmi3Instance $(, $arg: fmi3_side!($t2 $(, $t3)?))*)
                -> $crate::fmi3_types::fmi3Status = $mask => |$i $(, $f)?| $body;
        }
    )*};
}

/// The FMI 3.0 type of a [`twins!`] argument: the second of a pair, or the one for both.
macro_rules! fmi3_side {
    ($both:ty) => {
        $both
    };
    ($fmi2:ty, $fmi3:ty) => {
        $fmi3
    };
}

pub mod fmi2;
pub mod fmi3;
mod guard;
pub(crate) mod shared;

pub use fmi2::*;
pub use fmi3::*;
pub use shared::{fmu_state::*, lifecycle::*, model_exchange::*};
