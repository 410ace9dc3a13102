//! HIL_ACTUATOR_CONTROLS on the controller link: which vehicle, whether it is a new lockstep
//! step, a repeat or a late duplicate (protocol §3.1), the lockstep step itself, and the
//! answer to controls that are refused.

use super::refusal::Refusal;
use super::{Link, Mode, Sim};
use crate::vehicle::Vehicle;
use flyloop_core::tasks::registry::ControlError;
use mavlink::MavHeader;
use mavlink::dialects::common::{
    HIL_ACTUATOR_CONTROLS_DATA, HilActuatorControlsFlags, MavSeverity,
};
use std::net::SocketAddr;
use std::time::Instant;

/// What a lockstep command's `time_usec` makes of it, for one vehicle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum StepName {
    /// A step to take: unnamed (0), or named at or above the vehicle's clock, so a client
    /// may name a step by the time it starts at (PX4's convention) or ends at.
    New,
    /// The vehicle's last step again: its cached reply is the answer.
    Repeat,
    /// Not to be stepped: older than the clock, or the last step before a reset.
    Late(Refusal),
}

/// Classifies `step` (a lockstep command's `time_usec`) for vehicle `v`. Only a command
/// equal to the last step's name is a repeat; names at or above the clock step.
pub(crate) fn step_name(v: &Vehicle, step: u64) -> StepName {
    classify_step(v.last_step, v.last_reply.is_some(), v.clock_us, step)
}

/// [`step_name`] for anything that steps by name: its last step's name, whether that
/// step's reply is cached (not since dropped by a reset) and its clock, µs.
pub(crate) fn classify_step(
    last_step: Option<u64>,
    cached: bool,
    clock_us: u64,
    step: u64,
) -> StepName {
    if step == 0 {
        return StepName::New;
    }
    if last_step == Some(step) {
        return if cached {
            StepName::Repeat
        } else {
            StepName::Late(Refusal::BeforeReset { step })
        };
    }
    if step >= clock_us {
        StepName::New
    } else {
        StepName::Late(Refusal::LateDuplicate { step, clock_us })
    }
}

impl Sim {
    pub(super) fn on_controls(
        &mut self,
        header: MavHeader,
        c: &HIL_ACTUATOR_CONTROLS_DATA,
        from: SocketAddr,
        peer: usize,
        now: Instant,
        out: &mut Vec<u8>,
    ) {
        let Some(i) = self.vehicle_to_command(header.system_id, c, from, now, out) else {
            return;
        };
        if self.vehicles[i].link().is_some_and(|l| l.lost) {
            // A lost link: the command never arrives; the one in effect holds.
            self.stats.link_dropped += 1;
        } else if let Err(e) = self.set_controls(i, &c.controls) {
            self.refuse(Link::Controller, from, i, Refusal::BadValue(e), now, out);
            return;
        }
        match self.options.mode {
            Mode::Lockstep => self.lockstep_step(i, peer, c.time_usec, out),
            Mode::Realtime => self.command_arrived(i, now),
        }
    }

    /// The index of the vehicle `system_id` if these controls are a new command for it;
    /// `None` when they are refused (answered by [`Self::refuse`]) or, in lockstep, repeat
    /// the vehicle's last step (its cached reply sent again).
    fn vehicle_to_command(
        &mut self,
        system_id: u8,
        c: &HIL_ACTUATOR_CONTROLS_DATA,
        from: SocketAddr,
        now: Instant,
        out: &mut Vec<u8>,
    ) -> Option<usize> {
        let refusal = match self.vehicle_index(system_id) {
            None => Refusal::UnknownVehicle {
                system_id,
                vehicles: self.vehicles.len(),
            },
            Some(i) if self.options.mode == Mode::Realtime => return Some(i),
            Some(i) => {
                let lockstep = HilActuatorControlsFlags::HIL_ACTUATOR_CONTROLS_FLAGS_LOCKSTEP;
                if !c.flags.contains(lockstep) {
                    Refusal::NotLockstep {
                        flags: c.flags.bits(),
                    }
                } else {
                    match step_name(&self.vehicles[i], c.time_usec) {
                        StepName::New => return Some(i),
                        StepName::Repeat => {
                            self.send_cached_step(i, c.time_usec, out);
                            return None;
                        }
                        StepName::Late(refusal) => refusal,
                    }
                }
            }
        };
        let i = self.vehicle_index(system_id).unwrap_or(0);
        self.refuse(Link::Controller, from, i, refusal, now, out);
        None
    }

    /// The reply cached for vehicle `i`'s last step (named `step`), sent again.
    fn send_cached_step(&mut self, i: usize, step: u64, out: &mut Vec<u8>) {
        let v = &self.vehicles[i];
        self.stats.repeated_steps += 1;
        out.extend_from_slice(v.last_reply.as_deref().unwrap_or_default());
        tracing::debug!(
            system_id = v.system_id,
            step,
            "repeated step: cached reply sent again"
        );
    }

    /// Sets vehicle `i`'s command (clamped into the action bounds, counted).
    fn set_controls(&mut self, i: usize, controls: &[f32]) -> Result<(), ControlError> {
        let report = self.vehicles[i].set_controls(controls)?;
        if report.clamped {
            self.stats.clamped_controls += 1;
            let system_id = self.vehicles[i].system_id;
            tracing::debug!(system_id, "controls clamped into the action bounds");
        }
        Ok(())
    }

    /// One lockstep step of vehicle `i`, answered to `peer`; the answer is kept for a
    /// command naming `step` again (`step` 0 names none).
    fn lockstep_step(&mut self, i: usize, peer: usize, step: u64, out: &mut Vec<u8>) {
        let start = Instant::now();
        self.vehicles[i].step();
        self.stats.physics += start.elapsed();
        self.stats.steps += 1;
        let from = out.len();
        self.push_vehicle_reply(i, peer, out);
        self.record(i, &out[from..]);
        let v = &mut self.vehicles[i];
        if let Some(link) = v.link() {
            // The reply through the task's link faults (the fresh one on a clear link).
            let fresh = out.split_off(from);
            out.extend_from_slice(v.link_line.pass(v.clock_us, &fresh, link));
        }
        v.last_step = (step != 0).then_some(step);
        if step != 0 {
            let cached = v.last_reply.get_or_insert_with(Vec::new);
            cached.clear();
            cached.extend_from_slice(&out[from..]);
        }
    }

    /// Controls not acted on: counted, logged at debug level, and answered to `from` with
    /// a STATUSTEXT from vehicle index `i` unless `from` has had its texts for this window
    /// (see [`super::refusal`]).
    pub(super) fn refuse(
        &mut self,
        link: Link,
        from: SocketAddr,
        i: usize,
        refusal: Refusal,
        now: Instant,
        out: &mut Vec<u8>,
    ) {
        refusal.count(&mut self.stats);
        let Some(system_id) = self.system_id_of(i) else {
            return;
        };
        // The text is made only when it is logged or sent: a flood is mostly held back.
        tracing::debug!(%from, ?link, "{}", refusal.text(system_id));
        let Some(held) = self.refusal_texts.take(from, now) else {
            self.stats.refusal_texts_held += 1;
            return;
        };
        let mut text = refusal.text(system_id);
        if held > 0 {
            text.push_str(&format!(" ({held} more refused since, not answered)"));
        }
        self.stats.refusal_texts += 1;
        self.push_text(link, out, i, MavSeverity::MAV_SEVERITY_WARNING, &text);
    }
}
