//! Sensor models of the quadrotor: what an autopilot (PX4) reads instead of the true state.
//!
//! | sensor | model | frame, units |
//! |---|---|---|
//! | [`imu`] accelerometer | specific force Rᵀ(a + g·up) + Gauss–Markov bias + white noise | body FRD, m/s² |
//! | [`imu`] gyroscope | body rates + Gauss–Markov bias + white noise | body FRD, rad/s |
//! | [`mag`] magnetometer | Earth field at home (declination, inclination, strength) rotated into the body + white noise | body FRD, gauss |
//! | [`baro`] barometer | ISA pressure / temperature at home altitude + height, pressure noise | hPa, °C, m |
//! | [`gps`] GPS | lat/lon/alt around home, NED velocity, course, 3D fix, noise, rate and delay | deg, m MSL, m/s NED |
//!
//! Everything is pure and seeded: a [`Sensors`] holds its parameters, its random generator,
//! the IMU biases and the GPS delay line, all plain data saved by [`Sensors::save`], so the
//! same seed and the same flight give the same sensor stream bit for bit. The core's frames
//! are world ENU / body FLU; [`crate::frames`] turns them into the NED / FRD sensors speak.
//! The sensors read a vehicle's [`Kinematics`] (the vehicle seam), not a model.

pub mod baro;
pub mod gps;
pub mod imu;
pub mod mag;
pub mod params;

#[cfg(test)]
mod tests;

pub use baro::BaroReading;
pub use gps::{Geodetic, GpsFix};
pub use imu::ImuReading;
pub use params::SensorParams;

use crate::error::ParamError;
use crate::frames;
use crate::params::Parameters;
use crate::rng::SimRng;
use crate::snapshot::{self, SnapshotError};
use crate::vehicle::Kinematics;
use gps::GpsTiming;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// One sample of the sensors read at every physics step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorReading {
    pub imu: ImuReading,
    /// Magnetic field, body FRD, gauss.
    pub mag: Vector3<f64>,
    pub baro: BaroReading,
}

/// The sensor suite of one vehicle: parameters plus the random state (RNG, biases, GPS line).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sensors {
    params: SensorParams,
    rng: SimRng,
    /// Gyroscope bias, body FRD, rad/s.
    gyro_bias: Vector3<f64>,
    /// Accelerometer bias, body FRD, m/s².
    accel_bias: Vector3<f64>,
    gps: GpsTiming,
    /// Earth field in world NED, gauss (from the parameters, kept to save the trigonometry).
    field_ned: Vector3<f64>,
}

impl Sensors {
    /// A sensor suite with zero biases, its noise drawn from `seed`.
    pub fn new(params: SensorParams, seed: u64) -> Result<Self, ParamError> {
        params.validate()?;
        let field_ned = mag::earth_field_ned(
            params.mag_declination,
            params.mag_inclination,
            params.mag_strength,
        );
        Ok(Sensors {
            params,
            rng: SimRng::new(seed),
            gyro_bias: Vector3::zeros(),
            accel_bias: Vector3::zeros(),
            gps: GpsTiming::default(),
            field_ned,
        })
    }

    /// The parameters in use.
    pub fn params(&self) -> &SensorParams {
        &self.params
    }

    /// The home point (local origin) as a geodetic position.
    pub fn home(&self) -> Geodetic {
        Geodetic {
            latitude_deg: self.params.home_latitude,
            longitude_deg: self.params.home_longitude,
            altitude_m: self.params.home_altitude,
        }
    }

    /// Current IMU biases (gyro rad/s, accel m/s², body FRD).
    pub fn biases(&self) -> (Vector3<f64>, Vector3<f64>) {
        (self.gyro_bias, self.accel_bias)
    }

    /// Reads IMU, magnetometer and barometer of a vehicle in state `k`; `dt` (s) is the time
    /// since the previous sample: it sets the white noise per sample and moves the biases.
    pub fn sample(&mut self, k: &Kinematics, dt: f64) -> SensorReading {
        let imu = self.sample_imu(k, dt);
        let p = &self.params;
        let rng = &mut self.rng;
        let mag = imu::with_noise(
            mag::body_field_frd(&k.attitude, &self.field_ned),
            p.mag_noise,
            rng,
        );
        let baro = baro::reading(p.home_altitude + k.position.z, p.baro_noise * rng.normal());
        SensorReading { imu, mag, baro }
    }

    /// Reads the IMU alone (for an autopilot that models its other sensors itself, as
    /// ArduPilot does): the same biases, noise and random stream as the IMU part of
    /// [`Sensors::sample`].
    pub fn sample_imu(&mut self, k: &Kinematics, dt: f64) -> ImuReading {
        let p = &self.params;
        let rng = &mut self.rng;
        imu::step_bias(
            &mut self.gyro_bias,
            p.gyro_bias_random_walk,
            p.gyro_bias_correlation_time,
            dt,
            rng,
        );
        imu::step_bias(
            &mut self.accel_bias,
            p.accel_bias_random_walk,
            p.accel_bias_correlation_time,
            dt,
            rng,
        );
        let accel = imu::specific_force_frd(&k.attitude, &k.acceleration, k.gravity);
        let gyro = frames::flu_to_frd(&k.body_rates);
        ImuReading {
            accel: imu::with_noise(
                accel + self.accel_bias,
                imu::white_noise_std(p.accel_noise_density, dt),
                rng,
            ),
            gyro: imu::with_noise(
                gyro + self.gyro_bias,
                imu::white_noise_std(p.gyro_noise_density, dt),
                rng,
            ),
        }
    }

    /// The GPS at simulation time `time` (s): takes a fix of a vehicle in state `k` when one is due (at
    /// `gps_rate`, the first at the first call) and returns the fix that has become
    /// `gps_delay` old, if any.
    pub fn gps(&mut self, k: &Kinematics, time: f64) -> Option<GpsFix> {
        let p = &self.params;
        if self.gps.take_due(time, p.gps_rate) {
            let rng = &mut self.rng;
            let h = p.gps_horizontal_noise;
            let noise = Vector3::new(
                h * rng.normal(),
                h * rng.normal(),
                p.gps_vertical_noise * rng.normal(),
            );
            let velocity = imu::with_noise(k.velocity, p.gps_velocity_noise, rng);
            let fix = gps::fix(
                &self.home(),
                time,
                &(k.position + noise),
                &velocity,
                (p.gps_eph, p.gps_epv),
                p.gps_satellites,
            );
            self.gps.pending.push_back(fix);
        }
        self.gps.deliver(time, self.params.gps_delay)
    }

    /// Back to the start: zero biases, empty GPS line, the generator re-seeded with `seed`.
    pub fn reset(&mut self, seed: u64) {
        self.rng = SimRng::new(seed);
        self.gyro_bias = Vector3::zeros();
        self.accel_bias = Vector3::zeros();
        self.gps = GpsTiming::default();
    }

    /// The whole sensor state as bytes (parameters, RNG, biases, GPS line), bit for bit.
    pub fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        snapshot::encode(SNAPSHOT_TAG, self)
    }

    /// Sensors from [`Sensors::save`] bytes; foreign, damaged or invalid bytes are an error.
    pub fn restore(bytes: &[u8]) -> Result<Self, SnapshotError> {
        let sensors: Sensors = snapshot::decode(SNAPSHOT_TAG, "Sensors", bytes)?;
        sensors
            .params
            .validate()
            .map_err(|e| SnapshotError::Invalid(e.to_string()))?;
        let finite = sensors
            .gyro_bias
            .iter()
            .chain(sensors.accel_bias.iter())
            .chain(sensors.field_ned.iter())
            .all(|v| v.is_finite())
            && sensors.gps.next_fix.is_finite();
        if !finite {
            return Err(SnapshotError::Invalid(
                "sensor state holds a non-finite value".into(),
            ));
        }
        Ok(sensors)
    }
}

/// Format tag of a Sensors snapshot (name and version).
const SNAPSHOT_TAG: &[u8; 8] = b"FLYSEN01";
