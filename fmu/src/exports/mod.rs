//! Every FMI 2.0 and FMI 3.0 function, exported unmangled from the library (`extern "C"`):
//! [`fmi2`] and [`fmi3`] hold the C signatures, [`shared`] the bodies both versions run, and
//! [`guard`] what every export does around its body. Tests call them directly through the
//! rlib; importers load them from the .so.
// Function and parameter names are the standard's.
#![allow(non_snake_case, non_upper_case_globals)]

/// Defines exported C functions, each a C signature and a body.
macro_rules! exports {
    ($(
        $(#[doc = $doc:literal])*
        fn $name:ident($($arg:ident: $t:ty),* $(,)?) $(-> $ret:ty)? $body:block
    )*) => {$(
        $(#[doc = $doc])*
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
/// where `body` is a function of [`shared`] given the instance, the export's name and its other
/// arguments, or `|instance| expression` (`|instance, function|` with the name).
macro_rules! forward {
    () => {};
    (
        $(#[doc = $doc:literal])*
        fn $name:ident($c:ident: $ct:ty $(, $arg:ident: $t:ty)* $(,)?) -> $ret:ty =
            $mask:path => |$i:ident $(, $f:ident)?| $body:expr;
        $($rest:tt)*
    ) => {
        exports! {
            $(#[doc = $doc])*
            fn $name($c: $ct $(, $arg: $t)*) -> $ret {
                $(let $f = stringify!($name);)?
                $crate::exports::guard::with_instance($c, stringify!($name), $mask, |$i| $body)
            }
        }
        forward! { $($rest)* }
    };
    (
        $(#[doc = $doc:literal])*
        fn $name:ident($c:ident: $ct:ty $(, $arg:ident: $t:ty)* $(,)?) -> $ret:ty =
            $mask:path => $body:path;
        $($rest:tt)*
    ) => {
        forward! {
            $(#[doc = $doc])*
            fn $name($c: $ct $(, $arg: $t)*) -> $ret =
                $mask => |instance, function| $body(instance, function $(, $arg)*);
            $($rest)*
        }
    };
}

pub mod fmi2;
pub mod fmi3;
mod guard;
pub(crate) mod shared;

pub use fmi2::*;
pub use fmi3::*;
