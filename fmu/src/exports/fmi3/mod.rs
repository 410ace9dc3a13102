//! The FMI 3.0 functions: Co-Simulation for both models, Model Exchange for the quadrotor.
//! They run on the same instances, stages, engine and FMU states as their FMI 2.0 twins (whose
//! docs say what they do); what differs is the C signatures, the masks where FMI 3.0 changed
//! them, and the variables (arrays, `time`, event indicators; see [`crate::table::Fmi3View`]).

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
