//! FMI 2.0 Model Exchange, for an instance made with fmuType fmi2ModelExchange.

use crate::error::FmuError;
use crate::exports::guard::{c_slice, c_slice_mut, with_instance, write_out};
use crate::exports::shared::model_exchange::*;
use crate::fmi2_types::*;
use crate::instance::masks;

exports! {
    /// The discrete changes of the event at the current time (turbulence sample, released
    /// bristles) and the next time event.
    fn fmi2NewDiscreteStates(c: fmi2Component, eventInfo: *mut fmi2EventInfo) -> fmi2Status {
        let function = "fmi2NewDiscreteStates";
        with_instance(c, function, masks::NEW_DISCRETE_STATES, |instance| {
            if eventInfo.is_null() {
                return Err(FmuError::NullArgument("eventInfo"));
            }
            let (changed, next) = discrete_update(instance, function)?;
            let info = fmi2EventInfo {
                newDiscreteStatesNeeded: fmi2False,
                terminateSimulation: fmi2False,
                nominalsOfContinuousStatesChanged: fmi2False,
                valuesOfContinuousStatesChanged: fmi2Boolean::from(changed),
                nextEventTimeDefined: fmi2Boolean::from(next.is_some()),
                nextEventTime: next.unwrap_or(0.0),
            };
            write_out(eventInfo, info, "eventInfo")
        })
    }
}

forward! {
    /// A finite time not before the last event.
    fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status =
        masks::SET_TIME => |i| i.sim.set_time(time);
    /// Sets the states; nothing changes when a value is not finite.
    fn fmi2SetContinuousStates(c: fmi2Component, x: *const fmi2Real, nx: usize) -> fmi2Status =
        masks::SET_CONTINUOUS_STATES => |i| {
            i.sim.set_continuous_states(c_slice(x, nx, "continuous states")?)
        };
    /// The derivatives of the continuous states: the core's right-hand side, bit for bit.
    fn fmi2GetDerivatives(c: fmi2Component, derivatives: *mut fmi2Real, nx: usize) -> fmi2Status =
        masks::GET_DERIVATIVES => |i| {
            i.sim.derivatives(c_slice_mut(derivatives, nx, "derivatives")?)
        };
    /// The foot heights (m): a sign change is a touch-down or a lift-off.
    fn fmi2GetEventIndicators(
        c: fmi2Component,
        eventIndicators: *mut fmi2Real,
        ni: usize,
    ) -> fmi2Status = masks::GET_EVENT_INDICATORS => |i| {
        i.sim.event_indicators(c_slice_mut(eventIndicators, ni, "eventIndicators")?)
    };
    fn fmi2GetContinuousStates(c: fmi2Component, x: *mut fmi2Real, nx: usize) -> fmi2Status =
        masks::GET_CONTINUOUS_STATES => |i| i.sim.continuous_states(c_slice_mut(x, nx, "x")?);
    /// 1 for every state (positions in m, speeds in m/s, quaternion and motors near 1).
    fn fmi2GetNominalsOfContinuousStates(
        c: fmi2Component,
        x_nominal: *mut fmi2Real,
        nx: usize,
    ) -> fmi2Status =
        masks::GET_NOMINALS => |i| i.sim.nominals(c_slice_mut(x_nominal, nx, "x_nominal")?);
    /// Model Exchange only (Co-Simulation has no event mode here).
    fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status =
        masks::ENTER_EVENT_MODE => enter_event_mode;
    fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status =
        masks::ENTER_CONTINUOUS_TIME_MODE => enter_continuous_time_mode;
    /// No step event and no termination; an error once the state is not finite.
    fn fmi2CompletedIntegratorStep(
        c: fmi2Component,
        _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
        enterEventMode: *mut fmi2Boolean,
        terminateSimulation: *mut fmi2Boolean,
    ) -> fmi2Status = masks::COMPLETED_INTEGRATOR_STEP => completed_integrator_step;
}
