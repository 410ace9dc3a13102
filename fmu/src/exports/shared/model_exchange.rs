//! Model Exchange (each mask refuses a Co-Simulation instance): the functions that are the
//! same in both versions, and the event update both versions' discrete-state functions run.

use crate::exports::guard::{c_slice, c_slice_mut, no_null, write_out};
use crate::fmi2_types::fmi2Boolean;
use crate::fmi3_types::fmi3Boolean;
use crate::instance::{Instance, Stage, masks};
use flyloop_core::number::Compact;

/// Logs the event update at the current time as `function`'s event, with the next time
/// event.
pub(crate) fn log_event_update(instance: &Instance, function: &str, next: Option<f64>) {
    instance.event(&format!(
        "{function}: t = {}, next time event {}",
        Compact(instance.sim.time()),
        next.map_or("none".to_string(), |t| Compact(t).to_string())
    ));
}

twins! {
    /// A finite time not before the last event.
    fn fmi2SetTime / fmi3SetTime(c, time: f64) = masks::SET_TIME => |i| i.sim.set_time(time);
    /// Sets the states; nothing changes when a value is not finite.
    fn fmi2SetContinuousStates / fmi3SetContinuousStates(c, x: *const f64, nx: usize) =
        masks::SET_CONTINUOUS_STATES => |i| {
            let x = c_slice(x, nx, "continuous states")?;
            i.sim.hybrid_mut(nx, "nx")?.set_states(x)
        };
    fn fmi2GetContinuousStates / fmi3GetContinuousStates(c, x: *mut f64, nx: usize) =
        masks::GET_CONTINUOUS_STATES => |i| {
            let x = c_slice_mut(x, nx, "x")?;
            i.sim.hybrid(nx, "nx").map(|model| model.states(x))
        };
    /// The foot heights (m): a sign change is a touch-down or a lift-off.
    fn fmi2GetEventIndicators / fmi3GetEventIndicators(
        c,
        eventIndicators: *mut f64,
        ni: usize,
    ) = masks::GET_EVENT_INDICATORS => |i| {
        let z = c_slice_mut(eventIndicators, ni, "eventIndicators")?;
        i.sim.hybrid(ni, "ni").map(|model| model.event_indicators(z))
    };
    /// 1 for every state (positions in m, speeds in m/s, quaternion and motors near 1).
    fn fmi2GetNominalsOfContinuousStates / fmi3GetNominalsOfContinuousStates(
        c,
        x_nominal: *mut f64,
        nx: usize,
    ) = masks::GET_NOMINALS => |i| {
        let nominals = c_slice_mut(x_nominal, nx, "x_nominal")?;
        i.sim.hybrid(nx, "nx").map(|_| nominals.fill(1.0))
    };
    /// Model Exchange only (Co-Simulation has no event mode here).
    fn fmi2EnterEventMode / fmi3EnterEventMode(c) = masks::ENTER_EVENT_MODE => |i| {
        i.stage = Stage::EventMode;
        Ok(())
    };
    fn fmi2EnterContinuousTimeMode / fmi3EnterContinuousTimeMode(c) =
        masks::ENTER_CONTINUOUS_TIME_MODE => |i| {
            i.stage = Stage::ContinuousTimeMode;
            Ok(())
        };
    /// No step event and no termination; an error once the state is not finite.
    fn fmi2CompletedIntegratorStep / fmi3CompletedIntegratorStep(
        c,
        _noSetFMUStatePriorToCurrentPoint: fmi2Boolean | fmi3Boolean,
        enterEventMode: *mut fmi2Boolean | *mut fmi3Boolean,
        terminateSimulation: *mut fmi2Boolean | *mut fmi3Boolean,
    ) = masks::COMPLETED_INTEGRATOR_STEP => |i| {
        let flags = [
            (enterEventMode, "enterEventMode"),
            (terminateSimulation, "terminateSimulation"),
        ];
        no_null(&flags)?;
        i.sim.completed_integrator_step()?;
        write_out(enterEventMode, 0, "enterEventMode")?;
        write_out(terminateSimulation, 0, "terminateSimulation")
    };
}
