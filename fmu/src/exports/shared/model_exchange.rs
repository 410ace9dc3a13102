//! The Model Exchange bodies of FMI 2.0 and FMI 3.0 (each mask refuses a Co-Simulation
//! instance).

use crate::error::FmuError;
use crate::exports::guard::write_out;
use crate::instance::{Instance, Stage};
use flyloop_core::number::Compact;

/// The body of fmi2EnterEventMode and fmi3EnterEventMode.
pub(crate) fn enter_event_mode(instance: &mut Instance, _function: &str) -> Result<(), FmuError> {
    instance.stage = Stage::EventMode;
    Ok(())
}

/// The body of fmi2EnterContinuousTimeMode and fmi3EnterContinuousTimeMode.
pub(crate) fn enter_continuous_time_mode(
    instance: &mut Instance,
    _function: &str,
) -> Result<(), FmuError> {
    instance.stage = Stage::ContinuousTimeMode;
    Ok(())
}

/// The discrete changes of the event at the current time, logged as `function`'s event:
/// whether the continuous states changed, and the next time event.
pub(crate) fn discrete_update(
    instance: &mut Instance,
    function: &str,
) -> Result<(bool, Option<f64>), FmuError> {
    let (changed, next) = instance.sim.new_discrete_states()?;
    instance.event(&format!(
        "{function}: t = {}, next time event {}",
        Compact(instance.sim.time()),
        next.map_or("none".to_string(), |t| Compact(t).to_string())
    ));
    Ok((changed, next))
}

/// The body of fmi2CompletedIntegratorStep and fmi3CompletedIntegratorStep: no step event
/// and no termination (`B::default()` is the version's false); an error (Error stage) once the
/// state is not finite.
///
/// # Safety
/// The two flags must be NULL or writable.
pub(crate) unsafe fn completed_integrator_step<B: Copy + Default>(
    instance: &mut Instance,
    _function: &str,
    _no_set_fmu_state_prior_to_current_point: B,
    enter_event_mode: *mut B,
    terminate_simulation: *mut B,
) -> Result<(), FmuError> {
    if enter_event_mode.is_null() {
        return Err(FmuError::NullArgument("enterEventMode"));
    }
    if terminate_simulation.is_null() {
        return Err(FmuError::NullArgument("terminateSimulation"));
    }
    instance.sim.completed_integrator_step()?;
    // SAFETY: both non-NULL (checked above) and writable per the contract.
    unsafe {
        write_out(enter_event_mode, B::default(), "enterEventMode")?;
        write_out(terminate_simulation, B::default(), "terminateSimulation")
    }
}
