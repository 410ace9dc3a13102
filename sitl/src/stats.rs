//! Counters of what came in, what was refused and how long handling took.

use crate::wire::FrameError;
use std::fmt;
use std::time::Duration;

/// What the SITL counted since it started.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// Datagrams on the controller link.
    pub datagrams: u64,
    /// Datagrams on the ground-station link.
    pub gcs_datagrams: u64,
    pub frames: u64,
    pub steps: u64,
    pub resets: u64,
    // Bad input, skipped or refused.
    pub truncated: u64,
    pub bad_crc: u64,
    pub mavlink1: u64,
    pub unknown_message: u64,
    pub malformed: u64,
    pub garbage: u64,
    /// Controls with a NaN or infinite value for a used channel: the step was refused.
    pub refused_controls: u64,
    /// Finite controls outside the action bounds: clamped by the task.
    pub clamped_controls: u64,
    /// Messages addressed to a system id no vehicle has.
    pub unknown_vehicle: u64,
    /// Valid messages this SITL does not act on.
    pub ignored_messages: u64,
    /// Refused PARAM_SET / COMMAND_LONG values.
    pub refused_requests: u64,
    /// Socket errors on receive or send (logged, never fatal).
    pub io_errors: u64,
    /// Lockstep commands that repeated the vehicle's last step (its time_usec): the cached
    /// reply was sent again, nothing stepped.
    pub repeated_steps: u64,
    /// Lockstep commands for a step the vehicle is already past (a late duplicate, or a
    /// step before its last reset): not stepped, answered by a STATUSTEXT.
    pub stale_controls: u64,
    /// Lockstep mode: HIL_ACTUATOR_CONTROLS without the LOCKSTEP flag, not stepped.
    pub unflagged_controls: u64,
    /// HIL_ACTUATOR_CONTROLS on the ground-station link, not flown.
    pub gcs_controls: u64,
    /// STATUSTEXTs that answered refused controls.
    pub refusal_texts: u64,
    /// Refused controls left unanswered by the per-peer rate limit of those texts.
    pub refusal_texts_held: u64,
    /// A multi-agent world: datagrams that ended with some, not all, commands of a step in
    /// (the step waits for the rest; answered by a STATUSTEXT naming the missing vehicles).
    pub held_steps: u64,
    /// Lockstep commands dropped by a `link_loss` fault (the command in effect held).
    pub link_dropped: u64,
    /// Wall time from a datagram's arrival to its reply being sent (controller link).
    pub busy: Duration,
    /// Of which in the handler (decoding, physics, encoding; no socket calls).
    pub handling: Duration,
    /// Of which in the core's task step.
    pub physics: Duration,
}

impl Stats {
    pub fn count_frame_error(&mut self, e: FrameError) {
        match e {
            FrameError::Truncated => self.truncated += 1,
            FrameError::BadCrc { .. } => self.bad_crc += 1,
            FrameError::MavlinkV1 { .. } => self.mavlink1 += 1,
            FrameError::UnknownMessage { .. } => self.unknown_message += 1,
            FrameError::Malformed { .. } => self.malformed += 1,
            FrameError::Garbage => self.garbage += 1,
        }
    }

    /// Every skipped or refused input.
    pub fn bad_input(&self) -> u64 {
        self.truncated
            + self.bad_crc
            + self.mavlink1
            + self.unknown_message
            + self.malformed
            + self.garbage
            + self.refused_controls
            + self.unknown_vehicle
            + self.refused_requests
            + self.unflagged_controls
            + self.gcs_controls
    }
}

impl fmt::Display for Stats {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "datagrams={} gcs_datagrams={} frames={} steps={} resets={} truncated={} bad_crc={} mavlink1={} \
             unknown_message={} malformed={} garbage={} refused_controls={} clamped_controls={} \
             unknown_vehicle={} ignored_messages={} refused_requests={} io_errors={} \
             repeated_steps={} stale_controls={} unflagged_controls={} gcs_controls={} \
             refusal_texts={} refusal_texts_held={} held_steps={} link_dropped={} \
             busy_us_per_datagram={:.2} handling_us_per_datagram={:.2} physics_us_per_step={:.2}",
            self.datagrams,
            self.gcs_datagrams,
            self.frames,
            self.steps,
            self.resets,
            self.truncated,
            self.bad_crc,
            self.mavlink1,
            self.unknown_message,
            self.malformed,
            self.garbage,
            self.refused_controls,
            self.clamped_controls,
            self.unknown_vehicle,
            self.ignored_messages,
            self.refused_requests,
            self.io_errors,
            self.repeated_steps,
            self.stale_controls,
            self.unflagged_controls,
            self.gcs_controls,
            self.refusal_texts,
            self.refusal_texts_held,
            self.held_steps,
            self.link_dropped,
            us_per(self.busy, self.datagrams),
            us_per(self.handling, self.datagrams),
            us_per(self.physics, self.steps),
        )
    }
}

/// Microseconds of `total` per item of `n` (0 with no items), for the stop lines.
pub(crate) fn us_per(total: Duration, n: u64) -> f64 {
    if n == 0 {
        0.0
    } else {
        total.as_secs_f64() * 1e6 / n as f64
    }
}
