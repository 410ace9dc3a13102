//! One ArduPilot of the fleet, without sockets: servo packets in, JSON state lines out.

use super::frame_rate::FrameRate;
use crate::ardupilot::faulted_imu;
use crate::ardupilot::packet::{self, MAX_PWM, ServoFrame};
use crate::ardupilot::reply::{self, State};
use crate::kinematics::attitude_ned;
use flyloop_core::faults::VehicleFaults;
use flyloop_core::sensors::{ImuReading, Sensors};
use flyloop_core::vehicle::Kinematics;
use std::net::SocketAddr;

/// What a datagram was.
#[derive(Debug, Clone, PartialEq)]
pub enum Frame {
    /// A new frame: its motor command (none when its PWM is absurd: the previous command
    /// holds) and the step it asks for, µs. `first`: the first frame of an ArduPilot
    /// (started, or restarted: its frame count went back).
    New {
        command: Option<Vec<f64>>,
        step_us: u64,
        first: bool,
    },
    /// The last frame again (ArduPilot re-sends after ~1 s unanswered): resend the reply if
    /// it is this frame's.
    Repeat { answered: bool },
    /// Not a servo packet (counted).
    Skipped,
}

/// What an ArduPilot member counted.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Counters {
    pub datagrams: u64,
    pub steps: u64,
    pub repeats: u64,
    pub connections: u64,
    pub bad_input: u64,
}

/// ArduPilot's link state and its IMU.
#[derive(Debug, Clone)]
pub struct ArduPilotMember {
    start: Sensors,
    sensors: Sensors,
    /// Frame count of the last new frame, and who sent it.
    last: Option<(u32, SocketAddr)>,
    /// The frame count the reply in `reply` answers.
    replied: Option<u32>,
    reply: Vec<u8>,
    /// Time of the last reply, µs.
    last_us: u64,
    /// The IMU sample last sent while faults act (what an off gyro or accel repeats).
    last_imu: Option<ImuReading>,
    /// The frame rate it asks for, followed.
    rate: FrameRate,
    pub peer: Option<SocketAddr>,
    pub stats: Counters,
}

impl ArduPilotMember {
    pub fn new(sensors: Sensors) -> Self {
        ArduPilotMember {
            start: sensors.clone(),
            sensors,
            last: None,
            replied: None,
            reply: Vec::with_capacity(512),
            last_us: 0,
            last_imu: None,
            rate: FrameRate::default(),
            peer: None,
            stats: Counters::default(),
        }
    }

    /// The reply to the last frame answered.
    pub fn reply(&self) -> &[u8] {
        &self.reply
    }

    /// A datagram from `from` at world time `now_us`.
    pub fn receive(&mut self, bytes: &[u8], from: SocketAddr, rotors: usize, now_us: u64) -> Frame {
        self.stats.datagrams += 1;
        let Ok(frame) = packet::parse(bytes) else {
            self.stats.bad_input += 1;
            return Frame::Skipped;
        };
        let first = match self.last {
            Some((count, peer)) if frame.frame_count == count && peer == from => {
                self.stats.repeats += 1;
                return Frame::Repeat {
                    answered: self.replied == Some(count),
                };
            }
            Some((count, _)) => frame.frame_count <= count,
            None => true,
        };
        if first {
            self.stats.connections += 1;
            self.sensors = self.start.clone();
            self.replied = None;
            self.last_us = now_us;
            self.rate = FrameRate::default();
            self.peer = Some(from);
        }
        self.last = Some((frame.frame_count, from));
        Frame::New {
            command: self.command(&frame, rotors),
            step_us: self.rate.step_us(frame.frame_rate),
            first,
        }
    }

    fn command(&mut self, frame: &ServoFrame, rotors: usize) -> Option<Vec<f64>> {
        let outputs = &frame.motors[..rotors];
        if outputs.iter().any(|&p| p > MAX_PWM) {
            self.stats.bad_input += 1;
            return None;
        }
        Some(outputs.iter().map(|&p| packet::motor_command(p)).collect())
    }

    /// The state at `time_us` as the reply to the last frame, its IMU through the vehicle's
    /// sensor faults if it has any; returns the IMU sample in it.
    pub fn answer(
        &mut self,
        k: &Kinematics,
        time_us: u64,
        faults: Option<(&mut VehicleFaults, &[f64])>,
    ) -> ImuReading {
        let dt = (time_us.saturating_sub(self.last_us)).max(1) as f64 * 1e-6;
        self.last_us = time_us;
        let mut imu = self.sensors.sample_imu(k, dt);
        if let Some((f, motors)) = faults {
            let (p, t) = (self.sensors.params(), time_us as f64 * 1e-6);
            imu = faulted_imu::apply(imu, k, &mut self.last_imu, |r| {
                f.reading(r, t, dt, p, motors)
            });
        }
        let q = attitude_ned(&k.attitude);
        let state = State {
            timestamp: time_us as f64 / 1e6,
            gyro: imu.gyro.into(),
            accel_body: imu.accel.into(),
            position: k.position_ned().into(),
            velocity: k.velocity_ned().into(),
            quaternion: [q.w, q.i, q.j, q.k],
        };
        reply::write(&mut self.reply, &state);
        self.replied = self.last.map(|(count, _)| count);
        self.stats.steps += 1;
        imu
    }

    /// Gone (timed out and a new ArduPilot expected): the next frame is a first one.
    pub fn forget(&mut self) {
        self.last = None;
        self.replied = None;
    }
}
