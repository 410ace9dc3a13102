//! One vehicle flown by ArduPilot, without sockets: servo packets in, JSON lines out. The
//! server feeds it; tests drive it directly.

use super::packet::{self, MAX_PWM, PacketError, ServoFrame};
use super::reply::{self, State};
use crate::autopilot_record::Sent;
use crate::config::AutopilotVehicle;
use crate::control_link::ControlLink;
use crate::kinematics::attitude_ned;
use crate::link_line::ReplyLine;
use crate::session_faults::SessionFaults;
use crate::speed::SpeedLog;
use crate::stats::us_per;
use crate::track::SessionTrack;
use flyloop_core::ParamError;
use flyloop_core::quadrotor::standing_multirotor;
use flyloop_core::sensors::{ImuReading, Sensors};
use flyloop_core::vehicle::{Kinematics, Vehicle, VehicleStart};
use nalgebra::Vector3;
use std::fmt;
use std::net::SocketAddr;
use std::time::{Duration, Instant};

/// What a session is built from.
#[derive(Debug, Clone)]
pub struct SessionOptions {
    /// The vehicle and its sensors (the IMU's noise and bias; ArduPilot models the rest).
    pub vehicle: AutopilotVehicle,
    /// Seed of the vehicle's and the IMU's random generators.
    pub seed: u64,
}

/// What the session counted.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Counters {
    /// Datagrams received.
    pub datagrams: u64,
    /// Frames stepped (one physics step each).
    pub steps: u64,
    /// Frames answered again without a step (the same frame count re-sent).
    pub repeats: u64,
    /// ArduPilots served (the first, and each restart after it).
    pub connections: u64,
    /// Frame counts that skipped ahead (stepped once).
    pub gaps: u64,
    // Bad input.
    pub bad_length: u64,
    pub bad_magic: u64,
    pub bad_frame_rate: u64,
    /// Frames with a motor output above the PWM limit: the previous command held.
    pub absurd_pwm: u64,
    /// States with a non-finite value (written as 0).
    pub non_finite: u64,
    /// Socket errors (logged, never fatal).
    pub io_errors: u64,
    /// Servo frames dropped by a `link_loss` fault (the last command held).
    pub link_dropped: u64,
    /// Time in the handler (decode, physics, IMU, encoding; no socket calls).
    pub handling: Duration,
    /// Of which physics and the IMU.
    pub physics: Duration,
}

impl Counters {
    /// Every skipped or refused input.
    pub fn bad_input(&self) -> u64 {
        self.bad_length + self.bad_magic + self.bad_frame_rate + self.absurd_pwm
    }
}

impl fmt::Display for Counters {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "datagrams={} steps={} repeats={} connections={} gaps={} bad_length={} bad_magic={} \
             bad_frame_rate={} absurd_pwm={} non_finite={} io_errors={} \
             handling_us_per_datagram={:.2} physics_us_per_step={:.2}",
            self.datagrams,
            self.steps,
            self.repeats,
            self.connections,
            self.gaps,
            self.bad_length,
            self.bad_magic,
            self.bad_frame_rate,
            self.absurd_pwm,
            self.non_finite,
            self.io_errors,
            us_per(self.handling, self.datagrams),
            us_per(self.physics, self.steps),
        )
    }
}

/// The physics step of a frame at `frame_rate` Hz, whole µs (at least 1).
pub fn frame_step_us(frame_rate: u16) -> u64 {
    ((1e6 / f64::from(frame_rate.max(1))).round() as u64).max(1)
}

/// Kinds of bad input, each logged once.
#[derive(Debug, Clone, Copy)]
enum Kind {
    Length,
    Magic,
    FrameRate,
    Pwm,
    Gap,
    NonFinite,
}

/// The vehicle, its IMU and ArduPilot's lockstep state.
#[derive(Debug)]
pub struct Session {
    start: (VehicleStart, Sensors),
    vehicle: Box<dyn Vehicle + Send>,
    sensors: Sensors,
    /// Physics time of the last reply, µs (whole microseconds, so ArduPilot's clock, which
    /// counts whole microseconds, follows it exactly).
    time_us: u64,
    /// Frame count of the last frame stepped, and who sent it.
    last: Option<(u32, SocketAddr)>,
    /// The answer to the last frame (sent again for a repeat).
    reply: Vec<u8>,
    /// Kinds of bad input already logged.
    logged: u8,
    /// The IMU sample last sent while faults act (what an off IMU sensor repeats).
    last_imu: Option<ImuReading>,
    /// Ground-truth CSV (`--track`), if any.
    pub track: SessionTrack,
    pub stats: Counters,
    /// Simulated time against wall time, logged while ArduPilot steps.
    pub speed: SpeedLog,
    /// The vehicle's faults and the control link (nothing runs without them).
    faults: SessionFaults,
    /// With faults: the JSON frame made this step, and the frames a link fault holds back.
    fresh: Vec<u8>,
    link_line: ReplyLine,
}

/// What to do with a datagram.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// A new frame: stepped; send [`Session::reply`].
    Stepped,
    /// The last frame again: send [`Session::reply`] again (no step).
    Repeated,
    /// Not a servo packet: no answer.
    Skipped,
}

impl Session {
    /// The vehicle at rest on its landing gear at home, facing north.
    pub fn new(options: &SessionOptions) -> Result<Self, ParamError> {
        let c = &options.vehicle;
        let start = standing_multirotor(c.quadrotor.clone(), c.frame.clone(), options.seed)?;
        let sensors = Sensors::new(c.sensors.clone(), options.seed)?;
        let rotors = c.frame.rotor_count();
        let faults =
            SessionFaults::imu_only(c.faults.clone(), rotors, c.quadrotor.mass, options.seed)?;
        Ok(Session {
            vehicle: start.take(),
            start: (start, sensors.clone()),
            sensors,
            time_us: 0,
            last: None,
            reply: Vec::with_capacity(512),
            logged: 0,
            last_imu: None,
            track: SessionTrack::default(),
            stats: Counters::default(),
            speed: SpeedLog::default(),
            faults,
            fresh: Vec::new(),
            link_line: ReplyLine::default(),
        })
    }

    /// Takes MAV_CMD_INJECT_FAILURE on `control` from now on (read while ArduPilot steps).
    pub fn set_control(&mut self, control: ControlLink) {
        self.faults.set_control(control);
    }

    /// Physics time of the last reply, µs.
    pub fn time_us(&self) -> u64 {
        self.time_us
    }

    /// The simulated vehicle.
    pub fn vehicle(&self) -> &dyn Vehicle {
        self.vehicle.as_ref()
    }

    /// Whether an ArduPilot has sent a frame (since the start).
    pub fn is_active(&self) -> bool {
        self.last.is_some()
    }

    /// The JSON line answering the last frame.
    pub fn reply(&self) -> &[u8] {
        &self.reply
    }

    fn log_once(&mut self, kind: Kind, message: fmt::Arguments<'_>) {
        let bit = 1u8 << kind as u8;
        if self.logged & bit == 0 {
            self.logged |= bit;
            tracing::warn!("{message} (logged once; counted in the stop line)");
        } else {
            tracing::debug!("{message}");
        }
    }

    /// A datagram from `from`.
    pub fn receive(&mut self, bytes: &[u8], from: SocketAddr) -> Outcome {
        self.stats.datagrams += 1;
        let Some(frame) = self.servo_frame(bytes, from) else {
            return Outcome::Skipped;
        };
        if !self.is_new_frame(&frame, from) {
            return Outcome::Repeated;
        }
        self.step(&frame);
        self.last = Some((frame.frame_count, from));
        Outcome::Stepped
    }

    /// The datagram's servo frame; `None` for bad input (counted by kind, logged once).
    fn servo_frame(&mut self, bytes: &[u8], from: SocketAddr) -> Option<ServoFrame> {
        let e = match packet::parse(bytes) {
            Ok(frame) => return Some(frame),
            Err(e) => e,
        };
        let kind = match e {
            PacketError::Length(_) => {
                self.stats.bad_length += 1;
                Kind::Length
            }
            PacketError::Magic { .. } => {
                self.stats.bad_magic += 1;
                Kind::Magic
            }
            PacketError::FrameRate => {
                self.stats.bad_frame_rate += 1;
                Kind::FrameRate
            }
        };
        self.log_once(kind, format_args!("datagram from {from} skipped: {e}"));
        None
    }

    /// Whether `frame` is a new one to step; false for the last frame again (counted). The
    /// first frame connects an ArduPilot; a frame count that went back is a restarted one
    /// (the vehicle reset, a new connection); one that skipped ahead is a gap (counted).
    fn is_new_frame(&mut self, frame: &ServoFrame, from: SocketAddr) -> bool {
        match self.last {
            None => {
                tracing::info!(%from, frame_count = frame.frame_count, frame_rate = frame.frame_rate, "ArduPilot connected: lockstep");
                self.connect();
            }
            Some((count, peer)) if frame.frame_count == count && peer == from => {
                self.stats.repeats += 1;
                tracing::debug!(frame_count = count, "frame repeated: answered again");
                return false;
            }
            Some((count, peer)) if frame.frame_count <= count => {
                tracing::warn!(
                    %from,
                    previous = %peer,
                    frame_count = frame.frame_count,
                    last_frame_count = count,
                    time_us = self.time_us(),
                    "ArduPilot restarted (its frame count went back): vehicle reset to its start state, physics time to 0"
                );
                self.reset();
                self.connect();
            }
            Some((count, _)) if frame.frame_count != count.wrapping_add(1) => {
                self.stats.gaps += 1;
                self.log_once(
                    Kind::Gap,
                    format_args!(
                        "frame count jumped from {count} to {}: stepped once",
                        frame.frame_count
                    ),
                );
            }
            Some(_) => {}
        }
        true
    }

    /// A new ArduPilot: counted, and a new connection number in the track.
    fn connect(&mut self) {
        self.stats.connections += 1;
        self.faults.restart();
        self.link_line.clear();
        self.track.connect();
        let line = format!(
            "ArduPilot: connection {}: in lockstep",
            self.stats.connections
        );
        self.track.info(self.time_us, &line);
    }

    /// The vehicle and IMU back to their start state, physics time to 0.
    fn reset(&mut self) {
        self.vehicle = self.start.0.take();
        self.sensors = self.start.1.clone();
        self.time_us = 0;
        self.last = None;
    }

    /// Motor commands from the first servo outputs, one per rotor; absurd ones are refused
    /// (counted) and the previous command holds.
    fn apply_motors(&mut self, frame: &ServoFrame) {
        let outputs = &frame.motors[..self.vehicle.actuator_count()];
        if let Some(&pwm) = outputs.iter().find(|&&p| p > MAX_PWM) {
            self.stats.absurd_pwm += 1;
            self.log_once(
                Kind::Pwm,
                format_args!(
                    "motor PWM {pwm} us above {MAX_PWM} us in frame {}: previous command held",
                    frame.frame_count
                ),
            );
            return;
        }
        let command: Vec<f64> = outputs.iter().map(|&p| packet::motor_command(p)).collect();
        if let Err(e) = self.vehicle.set_actuators(&command) {
            // Commands in [0, 1] are always accepted; kept for a future bound.
            self.stats.absurd_pwm += 1;
            self.log_once(Kind::Pwm, format_args!("motor command refused: {e}"));
        }
    }

    /// One physics step of 1 / frame_rate (rounded to whole microseconds: 833 µs at
    /// 1200 Hz), then the state of the new time as the reply.
    fn step(&mut self, frame: &ServoFrame) {
        let start = Instant::now();
        let link = (self.faults).link_at(self.vehicle.as_mut(), self.time_us);
        if link.lost {
            // A lost link: the servo frame never arrives; the last command holds.
            self.stats.link_dropped += 1;
        } else {
            self.apply_motors(frame);
        }
        let step_us = frame_step_us(frame.frame_rate);
        let dt = step_us as f64 * 1e-6;
        (self.faults).advance(self.vehicle.as_mut(), self.time_us, dt);
        let lines = self.faults.take_lines();
        self.track.fault_lines(self.time_us, &lines);
        self.time_us += step_us;
        let k = self.vehicle.kinematics();
        let mut imu = self.sensors.sample_imu(&k, dt);
        if self.faults.is_active() {
            imu = self.faulted_imu(imu, &k, dt);
        }
        self.stats.steps += 1;
        self.stats.physics += start.elapsed();
        self.speed.observe(self.time_us);
        let q = attitude_ned(&k.attitude);
        let state = State {
            timestamp: self.time_us as f64 / 1e6,
            gyro: imu.gyro.into(),
            accel_body: imu.accel.into(),
            position: k.position_ned().into(),
            velocity: k.velocity_ned().into(),
            quaternion: [q.w, q.i, q.j, q.k],
        };
        if !reply::is_finite(&state) {
            self.stats.non_finite += 1;
            self.log_once(
                Kind::NonFinite,
                format_args!("non-finite state at t = {} s written as 0", state.timestamp),
            );
        }
        if self.faults.is_active() {
            // The JSON frame through the link faults (see crate::link_line).
            reply::write(&mut self.fresh, &state);
            let link = self.faults.link();
            let delivered = self.link_line.pass(self.time_us, &self.fresh, link);
            self.reply.clear();
            self.reply.extend_from_slice(delivered);
        } else {
            reply::write(&mut self.reply, &state);
        }
        let sent = Sent::Imu(&imu);
        if self.faults.is_active() {
            self.track.fault_events(&self.faults.take_events());
        }
        self.track.record(self.time_us, self.vehicle.as_ref(), sent);
    }

    /// The IMU through the sensor path; an off gyro or accelerometer holds its last value
    /// (ArduPilot needs both in every frame: a frame without one would be dropped).
    fn faulted_imu(&mut self, imu: ImuReading, k: &Kinematics, dt: f64) -> ImuReading {
        let motors = self.vehicle.actuator_states();
        let (faults, p, time_us) = (&mut self.faults, self.sensors.params(), self.time_us);
        super::faulted_imu::apply(imu, k, &mut self.last_imu, |r| {
            faults.reading(r, time_us, dt, p, &motors)
        })
    }

    /// The body rates without noise, FRD (for tests).
    pub fn true_gyro(&self) -> Vector3<f64> {
        self.vehicle.kinematics().body_rates_frd()
    }
}

#[cfg(test)]
mod link_tests;
#[cfg(test)]
mod tests;
