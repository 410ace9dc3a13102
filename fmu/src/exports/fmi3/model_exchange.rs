//! Model Exchange through FMI 3.0, for an instance from fmi3InstantiateModelExchange: the
//! same states, derivatives, event indicators and events as FMI 2.0's Model Exchange.

use crate::exports::guard::{c_slice_mut, no_null, write_out};
use crate::exports::shared::model_exchange::log_event_update;
use crate::fmi3_types::*;
use crate::instance::{Instance, masks3};
use crate::table::ModelExchangeTable;

/// How many values a Model Exchange quantity of the model has (0 for a Co-Simulation-only
/// model).
fn count(instance: &Instance, of: fn(&ModelExchangeTable) -> usize) -> usize {
    instance.sim.table().model_exchange.as_ref().map_or(0, of)
}

forward! {
    /// The discrete changes of the event at the current time (turbulence sample, released
    /// bristles) and the next time event. Every output pointer must be writable.
    fn fmi3UpdateDiscreteStates(
        instance: fmi3Instance,
        discreteStatesNeedUpdate: *mut fmi3Boolean,
        terminateSimulation: *mut fmi3Boolean,
        nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
        valuesOfContinuousStatesChanged: *mut fmi3Boolean,
        nextEventTimeDefined: *mut fmi3Boolean,
        nextEventTime: *mut fmi3Float64,
    ) -> fmi3Status = masks3::UPDATE_DISCRETE_STATES => |i, f| {
        let flags = [
            (discreteStatesNeedUpdate, "discreteStatesNeedUpdate"),
            (terminateSimulation, "terminateSimulation"),
            (nominalsOfContinuousStatesChanged, "nominalsOfContinuousStatesChanged"),
            (valuesOfContinuousStatesChanged, "valuesOfContinuousStatesChanged"),
            (nextEventTimeDefined, "nextEventTimeDefined"),
        ];
        no_null(&flags)?;
        no_null(&[(nextEventTime, "nextEventTime")])?;
        let (changed, next) = i.sim.new_discrete_states()?;
        log_event_update(i, f, next);
        let values = [false, false, false, changed, next.is_some()];
        for ((pointer, name), value) in flags.into_iter().zip(values) {
            write_out(pointer, u8::from(value), name)?;
        }
        write_out(nextEventTime, next.unwrap_or(0.0), "nextEventTime")
    };
    /// FMI 3.0's fmi2GetDerivatives, also in initialization mode.
    fn fmi3GetContinuousStateDerivatives(
        instance: fmi3Instance,
        derivatives: *mut fmi3Float64,
        nContinuousStates: usize,
    ) -> fmi3Status = masks3::GET_DERIVATIVES => |i| {
        let dx = c_slice_mut(derivatives, nContinuousStates, "derivatives")?;
        i.sim.hybrid(nContinuousStates, "nx").map(|model| model.derivatives(dx))
    };
    /// The number of event indicators (0 for a Co-Simulation-only model).
    fn fmi3GetNumberOfEventIndicators(
        instance: fmi3Instance,
        nEventIndicators: *mut usize,
    ) -> fmi3Status = masks3::ANY => |i| {
        write_out(nEventIndicators, count(i, |me| me.event_indicators), "the count")
    };
    fn fmi3GetNumberOfContinuousStates(
        instance: fmi3Instance,
        nContinuousStates: *mut usize,
    ) -> fmi3Status = masks3::ANY => |i| {
        write_out(nContinuousStates, count(i, |me| me.states.len()), "the count")
    };
}
