//! The fleet's live view stream (`--view`) and recording (`--record`), every vehicle in
//! each, told apart by its autopilot's system id (docs/view.md). Off unless asked for: a
//! fleet without them encodes nothing. Unlike the track ([`super::outputs`], sampled after
//! each step), they need what only the fleet sees inside a step — the sensor samples each
//! autopilot was sent, the collisions, every notice — so the fleet holds them.
//!
//! - The view: every [`VIEW_INTERVAL_US`](crate::view_stream::VIEW_INTERVAL_US) of world
//!   time, each vehicle's truth and motor commands; events at once.
//! - The recording: per world step, each vehicle's truth, motor command and wind, and the
//!   sensor samples of the autopilots that were due (PX4: HIL_SENSOR and HIL_GPS; ArduPilot:
//!   its IMU as HIL_SENSOR).
//! - Events, in both: a collision as NAMED_VALUE_FLOAT `collision` (its closing speed, m/s,
//!   at the contact's time) from each of the two vehicles' system ids, and every notice the
//!   fleet logs (the collision's line, an autopilot connected, gone or silent, a fault that
//!   fires) as STATUSTEXT from the fleet's system id.

use super::Member;
use super::server::FLEET_SYSTEM;
use crate::autopilot_record::{AutopilotRecorder, Sent};
use crate::telemetry;
use crate::view_stream::ViewStream;
use crate::wire::frames;
use flyloop_core::sensors::ImuReading;
use flyloop_core::vehicle::Vehicle;
use flyloop_core::world::World;
use mavlink::dialects::common::{MavMessage, MavSeverity, NAMED_VALUE_FLOAT_DATA};

/// The name of a collision's NAMED_VALUE_FLOAT.
pub const COLLISION: &str = "collision";

/// The sensor sample an autopilot was sent in a world step.
#[derive(Debug, Clone)]
pub enum Sample {
    /// PX4's frames (HIL_SENSOR, HIL_GPS), from this offset of its member's `out`.
    Px4From(usize),
    /// ArduPilot's IMU.
    Imu(ImuReading),
}

/// The fleet's view stream and recording, each if asked for.
#[derive(Debug, Default)]
pub struct ViewRecord {
    view: Option<ViewStream>,
    recording: Option<AutopilotRecorder>,
    /// STATUSTEXT chunk ids (a long text is split; its chunks share one).
    texts: u16,
}

impl ViewRecord {
    /// Sends every vehicle to a live view from now on.
    pub fn set_view(&mut self, view: ViewStream) {
        self.view = Some(view);
    }

    /// Records every world step from now on.
    pub fn set_recording(&mut self, recording: AutopilotRecorder) {
        self.recording = Some(recording);
    }

    /// Whether anything is written (what only they need is built only then).
    pub fn is_on(&self) -> bool {
        self.view.is_some() || self.recording.is_some()
    }

    /// The world step that ended at `time_us`: every vehicle, with what its autopilot was
    /// `sent` if it was due.
    pub fn step(
        &mut self,
        time_us: u64,
        world: &World,
        members: &[Member],
        sent: &[(usize, Sample)],
    ) {
        if let Some(view) = &mut self.view {
            if view.is_due(time_us) {
                for (i, m) in members.iter().enumerate() {
                    view.push_state(time_us, m.sysid, world.vehicle(i) as &dyn Vehicle, true);
                }
                view.flush();
            }
        }
        let Some(recording) = &mut self.recording else {
            return;
        };
        for (i, m) in members.iter().enumerate() {
            let vehicle = world.vehicle(i) as &dyn Vehicle;
            let messages: Vec<MavMessage>;
            let sample = match sent.iter().find(|(j, _)| *j == i) {
                None => Sent::Nothing,
                Some((_, Sample::Imu(imu))) => Sent::Imu(imu),
                Some((_, Sample::Px4From(from))) => {
                    let bytes = m.out.get(*from..).unwrap_or_default();
                    messages = frames(bytes)
                        .filter_map(Result::ok)
                        .map(|f| f.message)
                        .collect();
                    Sent::Messages(&messages)
                }
            };
            recording.step_of(m.sysid, time_us, vehicle, sample);
        }
    }

    /// Vehicles `a` and `b` (system ids) touched at `contact_s`, closing at `speed` m/s;
    /// `time_us`: the world's time now.
    pub fn collision(&mut self, time_us: u64, contact_s: f64, a: u8, b: u8, speed: f64) {
        if !self.is_on() {
            return;
        }
        let mut name = [0u8; 10];
        name[..COLLISION.len()].copy_from_slice(COLLISION.as_bytes());
        let event = MavMessage::NAMED_VALUE_FLOAT(NAMED_VALUE_FLOAT_DATA {
            time_boot_ms: (contact_s * 1e3).round() as u32,
            value: speed as f32,
            name: name.into(),
        });
        for system in [a, b] {
            self.event(time_us, system, std::slice::from_ref(&event));
        }
    }

    /// A notice the fleet logged, at world time `time_us`.
    pub fn notice(&mut self, time_us: u64, severity: MavSeverity, text: &str) {
        if !self.is_on() {
            return;
        }
        self.texts = self.texts.wrapping_add(1).max(1);
        let messages = telemetry::statustext(severity, text, self.texts);
        self.event(time_us, FLEET_SYSTEM, &messages);
    }

    fn event(&mut self, time_us: u64, system: u8, messages: &[MavMessage]) {
        if let Some(view) = &mut self.view {
            view.event(system, messages);
        }
        if let Some(recording) = &mut self.recording {
            recording.messages(time_us, system, messages);
        }
    }

    /// Writes out what the recording buffered (at the stop).
    pub fn flush(&mut self) {
        if let Some(recording) = &mut self.recording {
            recording.flush();
        }
    }
}

#[cfg(test)]
mod tests;
