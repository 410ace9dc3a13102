//! One vehicle flown by one PX4 connection, without sockets: bytes from PX4 in, bytes for PX4
//! out. The server feeds it; tests drive it directly.

use super::messages;
use crate::autopilot_record::Sent;
use crate::config::AutopilotVehicle;
use crate::control_link::ControlLink;
use crate::kinematics::Home;
use crate::link_line::LinkLine;
use crate::session_faults::SessionFaults;
use crate::speed::SpeedLog;
use crate::stats::Stats;
use crate::telemetry;
use crate::track::SessionTrack;
use crate::wire::{Encoder, StreamDecoder};
use flyloop_core::ParamError;
use flyloop_core::faults::LinkCondition;
use flyloop_core::quadrotor::standing_multirotor;
use flyloop_core::sensors::{GpsFix, SensorReading, Sensors};
use flyloop_core::vehicle::{Vehicle, VehicleStart};
use mavlink::dialects::common::{COMMAND_LONG_DATA, HilSensorUpdatedFlags, MavCmd, MavMessage};
use std::time::Instant;

/// System id of the simulator's messages to PX4.
const SIMULATOR_SYSTEM: u8 = 1;

/// What a session is built from.
#[derive(Debug, Clone)]
pub struct SessionOptions {
    pub vehicle: AutopilotVehicle,
    /// Physics step per controls message, µs (PX4 expects 4000).
    pub step_us: u64,
    /// Seed of the vehicle's and the sensors' random generators.
    pub seed: u64,
}

/// The vehicle, its sensors and PX4's lockstep state.
#[derive(Debug)]
pub struct Session {
    start: (VehicleStart, Sensors),
    vehicle: Box<dyn Vehicle + Send>,
    sensors: Sensors,
    home: Home,
    step_us: u64,
    /// Simulation time of the latest HIL_SENSOR, µs (> 0: PX4 refuses time 0).
    time_us: u64,
    /// Whether PX4's first HIL_ACTUATOR_CONTROLS has arrived (from then on: lockstep).
    lockstep: bool,
    /// HIL_STATE_QUATERNION interval PX4 asked for, µs.
    state_interval_us: Option<u64>,
    next_state_us: u64,
    /// UNIX time of simulation time 0 for HIL_GPS, µs.
    gps_epoch_us: u64,
    decoder: StreamDecoder,
    encoder: Encoder,
    /// Ground-truth CSV (`--track`), if any.
    pub track: SessionTrack,
    pub stats: Stats,
    /// Simulated time against wall time, logged while PX4 steps.
    pub speed: SpeedLog,
    /// The vehicle's faults and the control link (nothing runs without them).
    faults: SessionFaults,
    /// Samples held back by a `link_delay`.
    link_line: LinkLine<Px4Sample>,
}

/// The start vehicle after one step with the motors off: the state PX4's first controls meet.
fn first_state(start: &VehicleStart, step_us: u64) -> Box<dyn Vehicle + Send> {
    let mut vehicle = start.take();
    vehicle.advance(step_us as f64 * 1e-6);
    vehicle
}

impl Session {
    /// The vehicle at rest on its landing gear at the origin, facing north.
    pub fn new(options: &SessionOptions) -> Result<Self, ParamError> {
        let c = &options.vehicle;
        let start = standing_multirotor(c.quadrotor.clone(), c.frame.clone(), options.seed)?;
        let vehicle = first_state(&start, options.step_us.max(1));
        let sensors = Sensors::new(c.sensors.clone(), options.seed)?;
        let rotors = c.frame.rotor_count();
        let faults = SessionFaults::new(c.faults.clone(), rotors, c.quadrotor.mass, options.seed)?;
        let home = Home {
            latitude_deg: c.sensors.home_latitude,
            longitude_deg: c.sensors.home_longitude,
            altitude_m: c.sensors.home_altitude,
        };
        Ok(Session {
            start: (start, sensors.clone()),
            vehicle,
            sensors,
            home,
            step_us: options.step_us.max(1),
            time_us: 0,
            lockstep: false,
            state_interval_us: None,
            next_state_us: 0,
            gps_epoch_us: 0,
            decoder: StreamDecoder::default(),
            encoder: Encoder::default(),
            track: SessionTrack::default(),
            stats: Stats::default(),
            speed: SpeedLog::default(),
            faults,
            link_line: LinkLine::default(),
        })
    }

    /// Takes MAV_CMD_INJECT_FAILURE on `control` from now on (read while PX4 steps).
    pub fn set_control(&mut self, control: ControlLink) {
        self.faults.set_control(control);
    }

    /// A new PX4 connection: the vehicle and sensors back to their start state, time back to
    /// the first step, and the first HIL_SENSOR appended to `out`. `gps_epoch_us` is the UNIX
    /// time (µs) HIL_GPS counts from.
    pub fn connect(&mut self, gps_epoch_us: u64, out: &mut Vec<u8>) {
        self.vehicle = first_state(&self.start.0, self.step_us);
        self.sensors = self.start.1.clone();
        self.time_us = self.step_us;
        self.lockstep = false;
        self.state_interval_us = None;
        self.next_state_us = 0;
        self.gps_epoch_us = gps_epoch_us;
        self.decoder.clear();
        self.track.connect();
        self.faults.restart();
        self.link_line.clear();
        self.emit(out);
    }

    /// Whether PX4 drives the steps (its first controls have arrived).
    pub fn is_lockstep(&self) -> bool {
        self.lockstep
    }

    /// Simulation time of the latest HIL_SENSOR, µs.
    pub fn time_us(&self) -> u64 {
        self.time_us
    }

    /// Physics step, µs.
    pub fn step_us(&self) -> u64 {
        self.step_us
    }

    /// The simulated vehicle.
    pub fn vehicle(&self) -> &dyn Vehicle {
        self.vehicle.as_ref()
    }

    /// The home point (local origin).
    pub fn home(&self) -> &Home {
        &self.home
    }

    /// Before lockstep: one step on the simulator's own clock (motors as last commanded,
    /// off until PX4 speaks), sensors appended to `out`.
    pub fn free_step(&mut self, out: &mut Vec<u8>) {
        self.advance(out);
    }

    /// Bytes from PX4. Each HIL_ACTUATOR_CONTROLS is one step, answered in `out`; returns the
    /// number of steps taken.
    pub fn receive(&mut self, bytes: &[u8], out: &mut Vec<u8>) -> u32 {
        self.stats.datagrams += 1;
        self.decoder.push(bytes);
        let mut steps = 0;
        while let Some(frame) = self.decoder.next_frame() {
            let incoming = match frame {
                Ok(incoming) => incoming,
                Err(e) => {
                    self.stats.count_frame_error(e);
                    tracing::debug!(?e, "bad bytes from PX4 skipped");
                    continue;
                }
            };
            self.stats.frames += 1;
            match &incoming.message {
                MavMessage::HIL_ACTUATOR_CONTROLS(c) => {
                    if self.track.is_recording() {
                        let (id, m) = (incoming.header.system_id, &incoming.message);
                        self.track.received(self.time_us, id, m);
                    }
                    if (self.faults)
                        .link_at(self.vehicle.as_mut(), self.time_us)
                        .lost
                    {
                        // A lost link: the controls never arrive; the last ones hold.
                        self.stats.link_dropped += 1;
                    } else {
                        self.apply_controls(&c.controls);
                    }
                    if !self.lockstep {
                        tracing::info!(time_us = self.time_us, "first controls from PX4: lockstep");
                        self.lockstep = true;
                        let t = self.time_us as f64 * 1e-6;
                        let line = format!("PX4: first controls at t={t:.3} s: in lockstep");
                        self.track.info(self.time_us, &line);
                    }
                    self.advance(out);
                    steps += 1;
                }
                MavMessage::COMMAND_LONG(c) => self.command(c),
                _ => self.stats.ignored_messages += 1,
            }
        }
        steps
    }

    /// Motor commands from controls[0..n], one per rotor (PX4's motor n is the frame's rotor
    /// n); a non-finite one refuses the whole set (counted), and the previous command holds.
    fn apply_controls(&mut self, controls: &[f32; 16]) {
        let n = self.vehicle.actuator_count();
        let command: Vec<f64> = controls[..n].iter().map(|&c| f64::from(c)).collect();
        if let Err(e) = self.vehicle.set_actuators(&command) {
            self.stats.refused_controls += 1;
            tracing::warn!(
                refused = self.stats.refused_controls,
                "controls from PX4 skipped: {e}"
            );
        }
    }

    /// SET_MESSAGE_INTERVAL for HIL_STATE_QUATERNION (PX4 asks for it on connect); other
    /// commands need no answer from a simulator.
    fn command(&mut self, c: &COMMAND_LONG_DATA) {
        let is_state = c.param1 == telemetry::id::HIL_STATE_QUATERNION as f32;
        if c.command != MavCmd::MAV_CMD_SET_MESSAGE_INTERVAL || !is_state {
            self.stats.ignored_messages += 1;
            return;
        }
        self.state_interval_us = (c.param2.is_finite() && c.param2 >= 0.0).then(|| {
            // 0 means "the default rate": every step.
            (c.param2 as u64).max(self.step_us)
        });
        self.next_state_us = self.time_us;
    }

    /// One physics step, then the sensors of the new time.
    fn advance(&mut self, out: &mut Vec<u8>) {
        let start = Instant::now();
        let dt = self.step_us as f64 * 1e-6;
        (self.faults).advance(self.vehicle.as_mut(), self.time_us, dt);
        let lines = self.faults.take_lines();
        self.track.fault_lines(self.time_us, &lines);
        self.time_us += self.step_us;
        self.stats.steps += 1;
        self.emit(out);
        self.stats.physics += start.elapsed();
        self.speed.observe(self.time_us);
    }

    /// HIL_SENSOR now, HIL_GPS when a fix is delivered, HIL_STATE_QUATERNION when due.
    fn emit(&mut self, out: &mut Vec<u8>) {
        let dt = self.step_us as f64 * 1e-6;
        let k = self.vehicle.kinematics();
        let mut reading = self.sensors.sample(&k, dt);
        let sent_from = out.len();
        let link = self.faults.link();
        if self.faults.is_active() {
            let (p, motors) = (self.sensors.params(), self.vehicle.actuator_states());
            let d = (self.faults).reading(&mut reading, self.time_us, dt, p, &motors);
            let fields = messages::delivered_fields(&d);
            let fix = self.sensors.gps(&k, self.time_us as f64 * 1e-6);
            let (p, time_us) = (self.sensors.params(), self.time_us);
            let fix = fix.and_then(|f| self.faults.gps(f, time_us, p));
            let sample = Px4Sample {
                reading,
                fields,
                fix,
            };
            self.send_through_link(sample, link, out);
        } else {
            let sensor = messages::hil_sensor(&reading, self.time_us);
            self.encoder.push(out, SIMULATOR_SYSTEM, &sensor);
            let fix = self.sensors.gps(&k, self.time_us as f64 * 1e-6);
            if let Some(fix) = fix {
                self.push_gps(&fix, out);
            }
        }
        if let Some(interval) = self.state_interval_us {
            if self.time_us >= self.next_state_us && !link.lost {
                let state = telemetry::hil_state_quaternion_of(&k, &self.home, self.time_us);
                self.encoder.push(out, SIMULATOR_SYSTEM, &state);
                self.next_state_us += interval;
                if self.next_state_us <= self.time_us {
                    self.next_state_us = self.time_us + interval;
                }
            }
        }
        let sent = Sent::Frames(&out[sent_from..]);
        if self.faults.is_active() {
            self.track.fault_events(&self.faults.take_events());
        }
        self.track.record(self.time_us, self.vehicle.as_ref(), sent);
    }

    /// A faulted sample to PX4 through the link faults. The HIL_SENSOR of every step goes
    /// out stamped now, with an IMU sample: PX4 runs its rate loop, and so sends its next
    /// controls, only on a new gyro sample, and a step never answered would stall PX4 and
    /// flyloop for good (a real PX4 flight showed it). On a lost link it carries the last
    /// IMU sample delivered again (no mag, baro or GPS); on a delayed one the values sampled
    /// `delay` ago (the last delivered until a sample is that old) and their fix, once.
    fn send_through_link(&mut self, sample: Px4Sample, link: LinkCondition, out: &mut Vec<u8>) {
        use HilSensorUpdatedFlags as F;
        let time_us = self.time_us;
        let (sample, new) = {
            let (s, new) = self.link_line.pass_new(time_us, sample, link);
            (*s, new)
        };
        let fields = if link.lost {
            let imu = F::HIL_SENSOR_UPDATED_XACC
                | F::HIL_SENSOR_UPDATED_YACC
                | F::HIL_SENSOR_UPDATED_ZACC
                | F::HIL_SENSOR_UPDATED_XGYRO
                | F::HIL_SENSOR_UPDATED_YGYRO
                | F::HIL_SENSOR_UPDATED_ZGYRO;
            sample.fields & imu
        } else {
            sample.fields
        };
        let sensor = messages::hil_sensor_delivered(&sample.reading, time_us, fields);
        self.encoder.push(out, SIMULATOR_SYSTEM, &sensor);
        if let (Some(fix), true, false) = (sample.fix, new, link.lost) {
            self.push_gps(&fix, out);
        }
    }

    fn push_gps(&mut self, fix: &GpsFix, out: &mut Vec<u8>) {
        let stamp = self.gps_epoch_us + (fix.measured_at * 1e6).round() as u64;
        self.encoder
            .push(out, SIMULATOR_SYSTEM, &messages::hil_gps(fix, stamp));
    }
}

/// One step's sensors for PX4 after the sensor faults: what a link fault holds back.
#[derive(Debug, Clone, Copy)]
struct Px4Sample {
    reading: SensorReading,
    fields: HilSensorUpdatedFlags,
    fix: Option<GpsFix>,
}

#[cfg(test)]
pub(crate) mod faults_tests;
#[cfg(test)]
mod link_tests;
#[cfg(test)]
pub(crate) mod tests;
