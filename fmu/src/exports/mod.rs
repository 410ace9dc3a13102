//! Every FMI 2.0 and FMI 3.0 function, exported unmangled from the library (`extern "C"`). Tests call
//! them directly through the rlib; importers load them from the .so.
// Function and parameter names are the standard's.
#![allow(non_snake_case, non_upper_case_globals)]

mod cosimulation;
mod fmi3;
pub(crate) mod fmu_state;
mod guard;
mod instantiate;
mod lifecycle;
pub(crate) mod model_exchange;
pub(crate) mod values;

pub use cosimulation::*;
pub use fmi3::*;
pub use fmu_state::*;
pub use lifecycle::*;
pub use model_exchange::*;
pub use values::*;
