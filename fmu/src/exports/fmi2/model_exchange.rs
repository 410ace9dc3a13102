//! FMI 2.0 Model Exchange, for an instance made with fmuType fmi2ModelExchange.

use crate::error::FmuError;
use crate::exports::guard::{c_slice_mut, write_out};
use crate::exports::shared::model_exchange::log_event_update;
use crate::fmi2_types::*;
use crate::instance::masks;

forward! {
    /// The discrete changes of the event at the current time (turbulence sample, released
    /// bristles) and the next time event.
    fn fmi2NewDiscreteStates(c: fmi2Component, eventInfo: *mut fmi2EventInfo) -> fmi2Status =
        masks::NEW_DISCRETE_STATES => |i, f| {
            if eventInfo.is_null() {
                return Err(FmuError::NullArgument("eventInfo"));
            }
            let (changed, next) = i.sim.new_discrete_states()?;
            log_event_update(i, f, next);
            let info = fmi2EventInfo {
                newDiscreteStatesNeeded: fmi2False,
                terminateSimulation: fmi2False,
                nominalsOfContinuousStatesChanged: fmi2False,
                valuesOfContinuousStatesChanged: fmi2Boolean::from(changed),
                nextEventTimeDefined: fmi2Boolean::from(next.is_some()),
                nextEventTime: next.unwrap_or(0.0),
            };
            write_out(eventInfo, info, "eventInfo")
        };
    /// The derivatives of the continuous states: the core's right-hand side, bit for bit.
    fn fmi2GetDerivatives(c: fmi2Component, derivatives: *mut fmi2Real, nx: usize) -> fmi2Status =
        masks::GET_DERIVATIVES => |i| {
            let dx = c_slice_mut(derivatives, nx, "derivatives")?;
            i.sim.hybrid(nx, "nx").map(|model| model.derivatives(dx))
        };
}
