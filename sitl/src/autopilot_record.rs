//! The recording of the autopilot modes (`--px4 --record FILE`, `--ardupilot --record FILE`):
//! the MAVLink telemetry log of lockstep and real time ([`crate::record`]: each frame preceded
//! by its simulation time in µs, big-endian), so one reader replays and plots every mode.
//!
//! Per connection of an autopilot: HOME_POSITION (the truth's local origin, `--home`). Each
//! line the session logs (the autopilot in lockstep, a fault that fires or clears) as
//! STATUSTEXT from flyloop's system [`LINES_SYSTEM`] (the fleet's, 250). Per
//! physics step: what the autopilot sent, as received (PX4: HIL_ACTUATOR_CONTROLS, with PX4's
//! system id, stamped with the time it answers); the ground truth after the step
//! (HIL_STATE_QUATERNION); the motor command the autopilot's outputs set (SERVO_OUTPUT_RAW,
//! 1000–2000 µs); the wind (WIND_COV); and the sensor samples the SITL sent (PX4: its
//! HIL_SENSOR and HIL_GPS frames as sent; ArduPilot: the JSON line's IMU as HIL_SENSOR with
//! only the accel and gyro fields flagged). No task frame: an autopilot flight has no task.
//! Nothing is encoded when no recording is made.
//!
//! Fleet mode ([`crate::fleet::outputs`]) writes the same per vehicle, each from its
//! autopilot's system id ([`AutopilotRecorder::step_of`]), and the fleet's events.

use crate::kinematics::Home;
use crate::px4::messages::hil_imu;
use crate::record::{TlogFile, frames_of, message_id};
use crate::telemetry;
use crate::wire::Encoder;
use flyloop_core::sensors::ImuReading;
use flyloop_core::vehicle::Vehicle;
use mavlink::dialects::common::{MavMessage, MavSeverity};
use std::io;
use std::path::Path;

/// The system id of flyloop's truth in the recording (the view's and the lockstep's vehicle 1).
const TRUTH_SYSTEM: u8 = 1;

/// The system id of flyloop's own lines (STATUSTEXT): the fleet's, so one reader finds both.
pub const LINES_SYSTEM: u8 = crate::fleet::server::FLEET_SYSTEM;

/// The sensor samples the SITL sent the autopilot in one step.
#[derive(Debug, Clone, Copy)]
pub enum Sent<'a> {
    /// MAVLink frames as sent (PX4: HIL_SENSOR, HIL_GPS, HIL_STATE_QUATERNION if it asked).
    Frames(&'a [u8]),
    /// The same as messages, encoded here from the vehicle's system id (a fleet's PX4s are
    /// all sent their sensors from the simulator's system 1).
    Messages(&'a [MavMessage]),
    /// The IMU values of ArduPilot's JSON line (its other fields are the truth).
    Imu(&'a ImuReading),
    /// Nothing this step (a fleet vehicle whose autopilot was not due).
    Nothing,
}

/// A recording of an autopilot flight being written.
#[derive(Debug)]
pub struct AutopilotRecorder {
    out: TlogFile,
    encoder: Encoder,
    home: Home,
    frame: Vec<u8>,
    /// The systems whose HOME_POSITION is written (since the last connection).
    homes: Vec<u8>,
    /// The last STATUSTEXT id (a long line's chunks share one).
    texts: u16,
}

impl AutopilotRecorder {
    /// Creates (truncates) `path`; `home` is the truth's local origin.
    pub fn create(path: &Path, home: Home) -> io::Result<Self> {
        Ok(AutopilotRecorder {
            out: TlogFile::create(path)?,
            encoder: Encoder::default(),
            home,
            frame: Vec::with_capacity(512),
            homes: Vec::new(),
            texts: 0,
        })
    }

    /// A new autopilot connection: its clock starts again, HOME_POSITION is written again.
    pub fn connect(&mut self) {
        self.homes.clear();
    }

    /// Appends a message the autopilot sent (from `system_id`) at simulation time `time_us`.
    pub fn received(&mut self, time_us: u64, system_id: u8, message: &MavMessage) {
        self.frame.clear();
        self.frame.extend_from_slice(&time_us.to_be_bytes());
        self.encoder.push(&mut self.frame, system_id, message);
        self.write();
    }

    /// Appends messages from `system_id` at simulation time `time_us` (the fleet's events).
    pub fn messages(&mut self, time_us: u64, system_id: u8, messages: &[MavMessage]) {
        self.frame.clear();
        for m in messages {
            self.frame.extend_from_slice(&time_us.to_be_bytes());
            self.encoder.push(&mut self.frame, system_id, m);
        }
        self.write();
    }

    /// Appends a line flyloop logged at `time_us`: STATUSTEXT (chunked if long) from
    /// [`LINES_SYSTEM`].
    pub fn line(&mut self, time_us: u64, severity: MavSeverity, text: &str) {
        self.texts = self.texts.wrapping_add(1).max(1);
        let messages = telemetry::statustext(severity, text, self.texts);
        self.messages(time_us, LINES_SYSTEM, &messages);
    }

    /// Appends the step that ended at `time_us`: truth, motor command, wind, sensor samples.
    pub fn step(&mut self, time_us: u64, vehicle: &dyn Vehicle, sent: Sent<'_>) {
        self.step_of(TRUTH_SYSTEM, time_us, vehicle, sent);
    }

    /// [`Self::step`] of the vehicle whose autopilot has system id `system`.
    pub fn step_of(&mut self, system: u8, time_us: u64, vehicle: &dyn Vehicle, sent: Sent<'_>) {
        self.frame.clear();
        let time = time_us.to_be_bytes();
        let k = vehicle.kinematics();
        if !self.homes.contains(&system) {
            self.homes.push(system);
            let home = telemetry::home_position_of(&self.home, time_us);
            self.frame.extend_from_slice(&time);
            self.encoder.push(&mut self.frame, system, &home);
        }
        let mut messages = Vec::with_capacity(4);
        let mut has_state = false;
        match sent {
            Sent::Frames(bytes) => {
                for frame in frames_of(bytes) {
                    has_state |= message_id(frame) == telemetry::id::HIL_STATE_QUATERNION;
                    self.frame.extend_from_slice(&time);
                    self.frame.extend_from_slice(frame);
                }
            }
            Sent::Messages(sent) => {
                for m in sent {
                    has_state |= matches!(m, MavMessage::HIL_STATE_QUATERNION(_));
                    self.frame.extend_from_slice(&time);
                    self.encoder.push(&mut self.frame, system, m);
                }
            }
            Sent::Imu(imu) => messages.push(MavMessage::HIL_SENSOR(hil_imu(imu, time_us))),
            Sent::Nothing => {}
        }
        if !has_state {
            messages.push(telemetry::hil_state_quaternion_of(&k, &self.home, time_us));
        }
        let commands = vehicle.actuators();
        messages.push(telemetry::servo_output_raw_of(
            commands.into_iter(),
            time_us,
        ));
        messages.push(telemetry::wind_cov_of(&k, time_us));
        for m in &messages {
            self.frame.extend_from_slice(&time);
            self.encoder.push(&mut self.frame, system, m);
        }
        self.write();
    }

    fn write(&mut self) {
        self.out.write(&self.frame);
    }

    /// Writes what is buffered (on disconnect, silence and the stop).
    pub fn flush(&mut self) {
        self.out.flush();
    }
}

#[cfg(test)]
mod tests;
