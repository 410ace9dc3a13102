//! The FMI 3.0 functions of their own: Co-Simulation for both models, Model Exchange for the
//! quadrotor. They run on the same instances, stages, engine and FMU states as FMI 2.0's;
//! what differs is the C signatures, the masks where FMI 3.0 changed them, and the variables
//! (arrays, `time`, event indicators; see [`crate::table::Variable3`]). Those the same in FMI
//! 2.0 are in `exports::shared`.

mod cosimulation;
mod lifecycle;
mod model_exchange;
mod unsupported;
pub(crate) mod values;

pub use cosimulation::*;
pub use lifecycle::*;
pub use model_exchange::*;
pub use unsupported::*;
pub use values::*;
