//! The FMI 2.0 functions: Co-Simulation for both models, Model Exchange for the quadrotor.

mod cosimulation;
mod lifecycle;
mod model_exchange;
mod values;

pub use cosimulation::*;
pub use lifecycle::*;
pub use model_exchange::*;
pub use values::*;
