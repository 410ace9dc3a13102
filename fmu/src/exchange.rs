//! Model Exchange on top of [`Engine`]: the importer's solver owns time and the continuous
//! states; the engine checks array lengths and time, and keeps the time of the last event so
//! the model's discrete changes (turbulence samples, released bristles) happen at events
//! only, never inside the solver's trial steps.

use crate::error::FmuError;
use crate::model::{FmuModel, Hybrid};
use crate::simulation::{Engine, Simulation, TIME_TOLERANCE};
use flyloop_core::number::Compact;

/// The model's hybrid view, after checking that an array argument `name` of length `len`
/// has one entry per continuous state.
pub(crate) fn hybrid<'a, M: FmuModel>(
    engine: &'a Engine<M>,
    len: usize,
    name: &str,
) -> Result<&'a dyn Hybrid, FmuError> {
    let table = M::table();
    let (Some(me), Some(hybrid)) = (&table.model_exchange, engine.model().hybrid()) else {
        return Err(co_simulation_only());
    };
    if len != me.states.len() {
        return Err(FmuError::InvalidArgument(format!(
            "{name} = {len}, but {} has {} continuous states",
            table.info.identifier,
            me.states.len()
        )));
    }
    Ok(hybrid)
}

pub(crate) fn hybrid_mut<M: FmuModel>(engine: &mut Engine<M>) -> Result<&mut dyn Hybrid, FmuError> {
    engine
        .model_mut()
        .hybrid_mut()
        .ok_or_else(co_simulation_only)
}

fn co_simulation_only() -> FmuError {
    FmuError::NotSupported("Model Exchange: this model is Co-Simulation only")
}

pub(crate) fn event_indicators<M: FmuModel>(
    engine: &Engine<M>,
    z: &mut [f64],
) -> Result<(), FmuError> {
    let table = M::table();
    let (Some(me), Some(hybrid)) = (&table.model_exchange, engine.model().hybrid()) else {
        return Err(co_simulation_only());
    };
    if z.len() != me.event_indicators {
        return Err(FmuError::InvalidArgument(format!(
            "ni = {}, but {} has {} event indicators",
            z.len(),
            table.info.identifier,
            me.event_indicators
        )));
    }
    hybrid.event_indicators(z);
    Ok(())
}

/// fmi2SetTime: a finite time not before the last event (a solver may go back within a
/// step it rejects, never past an event it has handled).
pub(crate) fn set_time<M: FmuModel>(engine: &mut Engine<M>, time: f64) -> Result<(), FmuError> {
    hybrid_mut(engine)?;
    let last = engine.event_time;
    if !time.is_finite() || time < last - TIME_TOLERANCE * last.abs().max(1.0) {
        return Err(FmuError::InvalidArgument(format!(
            "time {} is not a finite time at or after the last event ({})",
            Compact(time),
            Compact(last)
        )));
    }
    engine.set_clock(time);
    Ok(())
}

/// fmi2NewDiscreteStates at the current time.
pub(crate) fn new_discrete_states<M: FmuModel>(
    engine: &mut Engine<M>,
) -> Result<(bool, Option<f64>), FmuError> {
    let now = engine.time();
    let elapsed = (now - engine.event_time).max(0.0);
    let n = M::table()
        .model_exchange
        .as_ref()
        .map_or(0, |me| me.states.len());
    let (mut before, mut after) = (vec![0.0; n], vec![0.0; n]);
    let hybrid = hybrid_mut(engine)?;
    hybrid.states(&mut before);
    hybrid.event_update(elapsed);
    hybrid.states(&mut after);
    let next = hybrid.time_event_after().map(|dt| now + dt);
    engine.event_time = now;
    let changed = before
        .iter()
        .zip(&after)
        .any(|(a, b)| a.to_bits() != b.to_bits());
    Ok((changed, next))
}
