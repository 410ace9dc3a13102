//! The FMI 2.0 functions of their own: Co-Simulation for both models, Model Exchange for the
//! quadrotor. Those the same in FMI 3.0 are in `exports::shared`.

mod cosimulation;
mod lifecycle;
mod model_exchange;
mod values;

pub use cosimulation::*;
pub use lifecycle::*;
pub use model_exchange::*;
pub use values::*;
