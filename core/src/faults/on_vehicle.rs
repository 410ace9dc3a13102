//! Faults of a vehicle flown by an outside autopilot (the SITL's PX4 and ArduPilot
//! sessions): the fault state on the session's clock, through the vehicle seam — the actuator
//! path between the autopilot's outputs and the motors, the air faults' wind, and the sensor
//! path on what the autopilot is sent. A session without faults has none of this: its
//! vehicle and sensors run exactly as before.

use super::catalogue::SensorId;
use super::px4::{Injection, from_px4};
use super::trigger::{Conditions, Reach};
use super::{FaultEvent, FaultPlan, FaultState};
use crate::error::ParamError;
use crate::sensors::{GpsFix, SensorParams, SensorReading, baro, imu};
use crate::vehicle::Vehicle;
use nalgebra::Vector3;

/// Pressure change per metre of height near the ground, Pa/m (ρ·g, ISA sea level): turns the
/// baro's pressure noise into the altitude noise its faults scale.
const PASCAL_PER_METRE: f64 = 12.0;

/// Which sensor groups a faulted sample still delivers (an off sensor delivers nothing).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Delivered {
    pub accel: bool,
    pub gyro: bool,
    pub mag: bool,
    pub baro: bool,
}

impl Delivered {
    /// Every sensor delivers (no fault).
    pub const ALL: Delivered = Delivered {
        accel: true,
        gyro: true,
        mag: true,
        baro: true,
    };
}

/// The faults of one vehicle flown by an autopilot, on the session's clock.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleFaults {
    state: FaultState,
    /// Events already handed out by [`VehicleFaults::new_events`].
    reported: usize,
    /// Mass of the vehicle, kg (a damaged propeller's imbalance shakes it).
    mass: f64,
}

impl VehicleFaults {
    /// The faults of `plan` for a vehicle of `rotors` rotors and `mass` kg flying for as long
    /// as the autopilot flies it (no episode end, no waypoints): a motor the frame lacks or an
    /// `at_waypoint` trigger is refused. `seed` seeds the draws and the faults' noise.
    pub fn new(plan: FaultPlan, rotors: usize, mass: f64, seed: u64) -> Result<Self, ParamError> {
        plan.check(&Reach {
            duration: None,
            waypoints: None,
            rotors,
        })?;
        let mut state = FaultState::new(plan, rotors);
        state.reset(seed);
        Ok(VehicleFaults {
            state,
            reported: 0,
            mass,
        })
    }

    pub fn state(&self) -> &FaultState {
        &self.state
    }

    /// A new autopilot connection (the vehicle back at its start): nothing fired, the
    /// schedule drawn again from `seed`.
    pub fn restart(&mut self, seed: u64) {
        self.state.reset(seed);
        self.reported = 0;
    }

    /// Before the physics step that starts at `time` s: fires and clears faults by their
    /// triggers, and sets the air faults' wind on `vehicle`.
    pub fn begin_step(&mut self, time: f64, vehicle: &mut dyn Vehicle) {
        self.fire_due(time, vehicle);
        let height = vehicle.kinematics().position.z;
        vehicle.set_external_wind(self.state.wind(time, height));
    }

    /// Fires and clears faults by their triggers at `time` s (a vehicle in a world, whose
    /// wind the world sets: no air faults).
    pub fn fire_due(&mut self, time: f64, vehicle: &dyn Vehicle) {
        let k = vehicle.kinematics();
        self.state.update(&Conditions {
            time,
            height: k.position.z,
            takeoff: (!vehicle.is_grounded()).then_some(time),
            waypoint: None,
        });
    }

    /// Advances `vehicle` by `dt` through the actuator path: while a motor fault or a battery
    /// acts, the motors get the faulted commands; afterwards the vehicle holds the autopilot's
    /// own commands again.
    pub fn advance(&mut self, vehicle: &mut dyn Vehicle, dt: f64) {
        let commanded = self.before_advance(vehicle, dt);
        vehicle.advance(dt);
        Self::after_advance(vehicle, commanded);
    }

    /// The actuator path before `vehicle` advances by `dt` (alone, or in a world with the
    /// others): while a motor fault or a battery acts, the motors get the faulted commands;
    /// returns the autopilot's commands for [`VehicleFaults::after_advance`] (`None`:
    /// nothing changed).
    pub fn before_advance(&mut self, vehicle: &mut dyn Vehicle, dt: f64) -> Option<Vec<f64>> {
        if !self.state.acts_on_motors() {
            return None;
        }
        let commanded = vehicle.actuators();
        let mut motors = commanded.clone();
        let states = vehicle.actuator_states();
        self.state
            .motor_commands(&commanded, &states, dt, &mut motors);
        // Same length as the vehicle's own command, each value in [0, 1]: accepted.
        let _ = vehicle.set_actuators(&motors);
        Some(commanded)
    }

    /// After `vehicle` advanced: it holds the autopilot's `commanded` values again.
    pub fn after_advance(vehicle: &mut dyn Vehicle, commanded: Option<Vec<f64>>) {
        if let Some(commanded) = commanded {
            let _ = vehicle.set_actuators(&commanded);
        }
    }

    /// The sensor path on `r` (sampled at `time` s, `dt` s after the previous sample, with
    /// the noise of `p`), `motors` the motor states (a damaged propeller's shaking): changes
    /// the values in place and says which sensors deliver.
    pub fn reading(
        &mut self,
        r: &mut SensorReading,
        time: f64,
        dt: f64,
        p: &SensorParams,
        motors: &[f64],
    ) -> Delivered {
        r.imu.accel += self.state.imu_vibration(motors, self.mass);
        let baro_faulted = self.state.acts_on_sensor(SensorId::Baro);
        let mut through = |sensor, value: &mut Vector3<f64>, sigma: f64| match self
            .state
            .sensor(sensor, *value, time, sigma)
        {
            Some(v) => {
                *value = v;
                true
            }
            None => false,
        };
        let accel = through(
            SensorId::Accel,
            &mut r.imu.accel,
            imu::white_noise_std(p.accel_noise_density, dt),
        );
        let gyro = through(
            SensorId::Gyro,
            &mut r.imu.gyro,
            imu::white_noise_std(p.gyro_noise_density, dt),
        );
        let mag = through(SensorId::Mag, &mut r.mag, p.mag_noise);
        let mut baro = true;
        if baro_faulted {
            let mut altitude = Vector3::new(r.baro.pressure_altitude, 0.0, 0.0);
            baro = through(
                SensorId::Baro,
                &mut altitude,
                p.baro_noise / PASCAL_PER_METRE,
            );
            if baro {
                r.baro = baro::reading(altitude.x, 0.0);
            }
        }
        Delivered {
            accel,
            gyro,
            mag,
            baro,
        }
    }

    /// The sensor path on a GPS fix delivered at `time` s: `None` when the GPS delivers
    /// nothing.
    pub fn gps(&mut self, fix: GpsFix, time: f64, p: &SensorParams) -> Option<GpsFix> {
        (self.state).gps(fix, time, p.gps_horizontal_noise, p.gps_vertical_noise)
    }

    /// PX4's failure code (MAV_CMD_INJECT_FAILURE) fired or cleared at `time` s; returns
    /// what was done (`fault injected: motor_off:1`), or an error naming the field.
    pub fn inject_px4(
        &mut self,
        unit: u8,
        failure: u8,
        instance: u8,
        rotors: usize,
        time: f64,
    ) -> Result<String, ParamError> {
        let injection = from_px4(unit, failure, instance, rotors)?;
        let done = injection.describe();
        match injection {
            Injection::Fire(spec) => self.state.inject(spec, time),
            Injection::Clear { motor, sensor } => self.state.clear(motor, sensor, time),
        }
        Ok(done)
    }

    /// The events (firings, clearings) since the last call, for the log and the link.
    pub fn new_events(&mut self) -> &[FaultEvent] {
        let events = &self.state.events()[self.reported..];
        self.reported = self.state.events().len();
        events
    }
}
