//! Every FMI 2.0 function, exported unmangled from the library (`extern "C"`). Tests call
//! them directly through the rlib; importers load them from the .so.
// Function and parameter names are the standard's.
#![allow(non_snake_case, non_upper_case_globals)]

mod cosimulation;
mod fmu_state;
mod guard;
mod lifecycle;
mod model_exchange;
mod values;

pub use cosimulation::*;
pub use fmu_state::*;
pub use lifecycle::*;
pub use model_exchange::*;
pub use values::*;
