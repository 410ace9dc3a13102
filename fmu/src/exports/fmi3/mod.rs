//! The FMI 3.0 functions: Co-Simulation for both models, Model Exchange for the quadrotor.
//! They run on the same instances, stages, engine and FMU states as the FMI 2.0 functions;
//! what differs is the C signatures, the masks where FMI 3.0 changed them, and the variables
//! (arrays, `time`, event indicators; see [`crate::table::Fmi3View`]).

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

use crate::error::FmuError;
use crate::fmi3_types::{fmi3Instance, fmi3Status};
use crate::instance::{Instance, Mask};

/// [`super::guard::with_instance`] for a body without a status of its own: OK, or the
/// error's status, as an FMI 3.0 status.
pub(crate) fn with_instance3(
    instance: fmi3Instance,
    function: &'static str,
    mask: Mask,
    body: impl FnOnce(&mut Instance) -> Result<(), FmuError>,
) -> fmi3Status {
    super::guard::with_instance(instance, function, mask, |instance| {
        body(instance)?;
        Ok(crate::fmi2_types::fmi2Status::fmi2OK)
    })
    .into()
}
