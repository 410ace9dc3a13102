//! What the fleet writes beside the flight, from the world's truth after every step: the
//! track (`--track`). One place the loop hands each step to, so more outputs join here.

use super::Fleet;
use super::track::FleetTrack;

/// The fleet's outputs, each if asked for.
#[derive(Debug, Default)]
pub struct Outputs {
    /// Until a write fails (logged; the track ends, the flight goes on).
    pub track: Option<FleetTrack>,
}

impl Outputs {
    /// After a step of the world (and once at the start): what is due.
    pub fn after_step(&mut self, fleet: &Fleet) {
        if let Some(track) = &mut self.track {
            if let Err(e) = track.record(fleet) {
                tracing::error!(error = %e, "writing the track failed: track stopped");
                self.track = None;
            }
        }
    }

    /// Writes out what is buffered (at the stop).
    pub fn flush(&mut self) {
        if let Some(track) = &mut self.track {
            if let Err(e) = track.flush() {
                tracing::error!(error = %e, "writing the track failed");
            }
        }
    }
}
