//! One PX4 of the fleet, without sockets: its stream decoded into answers, its sensors
//! encoded (HIL_SENSOR every step, HIL_GPS at the GPS rate) from its vehicle's kinematics.

use crate::px4::messages;
use crate::stats::Stats;
use crate::wire::{Encoder, StreamDecoder};
use flyloop_core::faults::VehicleFaults;
use flyloop_core::sensors::Sensors;
use flyloop_core::vehicle::Kinematics;
use mavlink::dialects::common::MavMessage;

/// System id of the simulator's messages to PX4 (as in single-vehicle PX4 mode).
const SIMULATOR_SYSTEM: u8 = 1;

/// What PX4 said on its stream.
#[derive(Debug, Clone, PartialEq)]
pub enum Said {
    /// HIL_ACTUATOR_CONTROLS: controls[0..n] (n rotors), each finite, and its `time_usec`
    /// (PX4's time: the HIL_SENSOR it answers).
    Controls(Vec<f64>, u64),
    /// HIL_ACTUATOR_CONTROLS with a non-finite control (counted): answered with the
    /// command in effect.
    BadControls(u64),
    /// A HEARTBEAT from this system id.
    Heartbeat(u8),
}

/// PX4's link state and its sensors.
#[derive(Debug, Clone)]
pub struct Px4Member {
    start: Sensors,
    sensors: Sensors,
    decoder: StreamDecoder,
    encoder: Encoder,
    /// UNIX time of simulation time 0 for HIL_GPS, µs.
    gps_epoch_us: u64,
    /// Time of the last sensors, µs.
    last_us: u64,
    pub stats: Stats,
}

impl Px4Member {
    pub fn new(sensors: Sensors) -> Self {
        Px4Member {
            start: sensors.clone(),
            sensors,
            decoder: StreamDecoder::default(),
            encoder: Encoder::default(),
            gps_epoch_us: 0,
            last_us: 0,
            stats: Stats::default(),
        }
    }

    /// A new connection at world time `now_us`: sensors back to their start state,
    /// nothing buffered. `gps_epoch_us`: UNIX time (µs) of world time 0.
    pub fn connect(&mut self, now_us: u64, gps_epoch_us: u64) {
        self.sensors = self.start.clone();
        self.decoder.clear();
        self.gps_epoch_us = gps_epoch_us;
        self.last_us = now_us;
    }

    /// Bytes from PX4, as what it said (frames it may send that a simulator needs not
    /// answer are counted and dropped).
    pub fn receive(&mut self, bytes: &[u8], rotors: usize) -> Vec<Said> {
        self.stats.datagrams += 1;
        self.decoder.push(bytes);
        let mut said = Vec::new();
        while let Some(frame) = self.decoder.next_frame() {
            let incoming = match frame {
                Ok(incoming) => incoming,
                Err(e) => {
                    self.stats.count_frame_error(e);
                    continue;
                }
            };
            self.stats.frames += 1;
            match incoming.message {
                MavMessage::HIL_ACTUATOR_CONTROLS(c) => {
                    let command: Vec<f64> =
                        c.controls[..rotors].iter().map(|&x| f64::from(x)).collect();
                    if command.iter().all(|x| x.is_finite()) {
                        said.push(Said::Controls(command, c.time_usec));
                    } else {
                        self.stats.refused_controls += 1;
                        said.push(Said::BadControls(c.time_usec));
                    }
                }
                MavMessage::HEARTBEAT(_) => said.push(Said::Heartbeat(incoming.header.system_id)),
                _ => self.stats.ignored_messages += 1,
            }
        }
        said
    }

    /// HIL_SENSOR at `time_us` (PX4 refuses time 0: stamped at least 1 µs), and HIL_GPS
    /// when a fix is delivered, appended to `out`; through the vehicle's sensor faults
    /// (with its motor states) if it has any.
    pub fn emit(
        &mut self,
        k: &Kinematics,
        time_us: u64,
        out: &mut Vec<u8>,
        faults: Option<(&mut VehicleFaults, &[f64])>,
    ) {
        let dt = (time_us.saturating_sub(self.last_us)).max(1) as f64 * 1e-6;
        self.last_us = time_us;
        let mut reading = self.sensors.sample(k, dt);
        let t = time_us as f64 * 1e-6;
        let fix = match faults {
            None => {
                let sensor = messages::hil_sensor(&reading, time_us.max(1));
                self.encoder.push(out, SIMULATOR_SYSTEM, &sensor);
                self.sensors.gps(k, t)
            }
            Some((f, motors)) => {
                let p = self.sensors.params();
                let d = f.reading(&mut reading, t, dt, p, motors);
                let fields = messages::delivered_fields(&d);
                let sensor = messages::hil_sensor_delivered(&reading, time_us.max(1), fields);
                self.encoder.push(out, SIMULATOR_SYSTEM, &sensor);
                let fix = self.sensors.gps(k, t);
                fix.and_then(|fix| f.gps(fix, t, self.sensors.params()))
            }
        };
        if let Some(fix) = fix {
            let stamp = self.gps_epoch_us + (fix.measured_at * 1e6).round() as u64;
            self.encoder
                .push(out, SIMULATOR_SYSTEM, &messages::hil_gps(&fix, stamp));
        }
        self.stats.steps += 1;
    }
}
