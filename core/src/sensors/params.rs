//! The sensor parameter table: home point, Earth's magnetic field there, and the noise of
//! each sensor (the defaults of PX4's Gazebo classic iris, which model an ADIS16448 IMU, except
//! the accelerometer's bias walk: the ADIS16448's datasheet value, see `accel_bias_random_walk`).

use crate::param;
use crate::params::{ParamSpec, Parameters};
use serde::{Deserialize, Serialize};

/// Sensor parameters. Units are in each field's name or doc; ranges in [`SensorParams::specs`].
///
/// The magnetic field defaults are the World Magnetic Model at the default home (PX4's SITL
/// home in Zürich) as PX4 itself looks it up (its WMM table, bilinear in 10° cells), so PX4's
/// preflight check of the magnetometer against the WMM at the GPS position passes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SensorParams {
    /// Latitude of the local origin, deg. Default 47.397742 (PX4's SITL home).
    pub home_latitude: f64,
    /// Longitude of the local origin, deg. Default 8.545594.
    pub home_longitude: f64,
    /// Altitude of the local origin above mean sea level, m. Default 488.
    pub home_altitude: f64,
    /// Magnetic declination (east of true north positive), deg. Default 3.27.
    pub mag_declination: f64,
    /// Magnetic inclination (dip, down positive), deg. Default 63.15.
    pub mag_inclination: f64,
    /// Total field strength, gauss. Default 0.482.
    pub mag_strength: f64,
    /// Magnetometer white noise per sample (1σ, each axis), gauss. Default 0.005.
    pub mag_noise: f64,
    /// Gyroscope white noise density, rad/s/√Hz. Default 1.8665e-4 (per 4 ms sample 0.003 rad/s).
    pub gyro_noise_density: f64,
    /// Gyroscope bias random walk, rad/s²/√Hz. Default 3.8785e-5.
    pub gyro_bias_random_walk: f64,
    /// Correlation time of the gyroscope bias (first-order Gauss–Markov), s. Default 1000.
    pub gyro_bias_correlation_time: f64,
    /// Accelerometer white noise density, m/s²/√Hz. Default 4e-3 (per 4 ms sample 0.063 m/s²).
    pub accel_noise_density: f64,
    /// Accelerometer bias random walk, m/s³/√Hz. Default 2e-4: with the 300 s correlation
    /// time the bias wanders with a standard deviation of `accel_bias_random_walk · √(τ/2)`
    /// = 0.0024 m/s² (0.25 mg), the in-run bias stability of the ADIS16448 these defaults
    /// describe. (Gazebo's 6e-3, "twice the ADIS16448", wanders by 0.073 m/s², 30 times
    /// that: PX4's EKF2 and ArduPilot's EKF3 cannot follow a bias moving that fast, and
    /// their height estimates drifted 0.5–0.7 m from the truth; docs/core.md, "Sensors".)
    pub accel_bias_random_walk: f64,
    /// Correlation time of the accelerometer bias, s. Default 300.
    pub accel_bias_correlation_time: f64,
    /// Barometer white noise per sample (1σ), Pa. Default 1.0 (about 8 cm of altitude).
    pub baro_noise: f64,
    /// GPS fixes per second, Hz. Default 10.
    pub gps_rate: f64,
    /// GPS latency: a fix describes the state this long before it is delivered, s. Default 0.
    pub gps_delay: f64,
    /// GPS horizontal position white noise (1σ, each axis), m. Default 0.05.
    pub gps_horizontal_noise: f64,
    /// GPS vertical position white noise (1σ), m. Default 0.1.
    pub gps_vertical_noise: f64,
    /// GPS velocity white noise (1σ, each axis), m/s. Default 0.02.
    pub gps_velocity_noise: f64,
    /// Horizontal accuracy the receiver reports (eph), m. Default 0.3.
    pub gps_eph: f64,
    /// Vertical accuracy the receiver reports (epv), m. Default 0.4.
    pub gps_epv: f64,
    /// Satellites the receiver reports in view. Default 12.
    pub gps_satellites: u8,
}

impl Default for SensorParams {
    fn default() -> Self {
        SensorParams {
            home_latitude: 47.397742,
            home_longitude: 8.545594,
            home_altitude: 488.0,
            mag_declination: 3.27,
            mag_inclination: 63.15,
            mag_strength: 0.482,
            mag_noise: 0.005,
            gyro_noise_density: 1.8665e-4,
            gyro_bias_random_walk: 3.8785e-5,
            gyro_bias_correlation_time: 1000.0,
            accel_noise_density: 4e-3,
            accel_bias_random_walk: 2e-4,
            accel_bias_correlation_time: 300.0,
            baro_noise: 1.0,
            gps_rate: 10.0,
            gps_delay: 0.0,
            gps_horizontal_noise: 0.05,
            gps_vertical_noise: 0.1,
            gps_velocity_noise: 0.02,
            gps_eph: 0.3,
            gps_epv: 0.4,
            gps_satellites: 12,
        }
    }
}

static SENSOR_SPECS: [ParamSpec<SensorParams>; 22] = [
    param!(real home_latitude, "deg", -89.0, 89.0, "Latitude of the local origin (home)"),
    param!(real home_longitude, "deg", -180.0, 180.0, "Longitude of the local origin (home)"),
    param!(real home_altitude, "m", -500.0, 9000.0, "Altitude of the local origin above mean sea level"),
    param!(real mag_declination, "deg", -180.0, 180.0, "Magnetic declination at home (east positive)"),
    param!(real mag_inclination, "deg", -90.0, 90.0, "Magnetic inclination at home (down positive)"),
    param!(real mag_strength, "gauss", 0.0, 2.0, "Earth field strength at home"),
    param!(real mag_noise, "gauss", 0.0, 1.0, "Magnetometer white noise per sample (1 sigma)"),
    param!(real gyro_noise_density, "rad/s/Hz0.5", 0.0, 1.0, "Gyroscope white noise density"),
    param!(real gyro_bias_random_walk, "rad/s2/Hz0.5", 0.0, 1.0, "Gyroscope bias random walk"),
    param!(real gyro_bias_correlation_time, "s", 1.0, 1e6, "Gyroscope bias correlation time"),
    param!(real accel_noise_density, "m/s2/Hz0.5", 0.0, 10.0, "Accelerometer white noise density"),
    param!(real accel_bias_random_walk, "m/s3/Hz0.5", 0.0, 10.0, "Accelerometer bias random walk"),
    param!(real accel_bias_correlation_time, "s", 1.0, 1e6, "Accelerometer bias correlation time"),
    param!(real baro_noise, "Pa", 0.0, 1000.0, "Barometer white noise per sample (1 sigma)"),
    param!(real gps_rate, "Hz", 0.1, 100.0, "GPS fixes per second"),
    param!(real gps_delay, "s", 0.0, 1.0, "GPS latency (age of a fix when delivered)"),
    param!(real gps_horizontal_noise, "m", 0.0, 100.0, "GPS horizontal position noise (1 sigma per axis)"),
    param!(real gps_vertical_noise, "m", 0.0, 100.0, "GPS vertical position noise (1 sigma)"),
    param!(real gps_velocity_noise, "m/s", 0.0, 10.0, "GPS velocity noise (1 sigma per axis)"),
    param!(real gps_eph, "m", 0.0, 100.0, "Horizontal accuracy the receiver reports"),
    param!(real gps_epv, "m", 0.0, 100.0, "Vertical accuracy the receiver reports"),
    param!(integer gps_satellites, "", 0, 64, "Satellites the receiver reports in view"),
];

impl Parameters for SensorParams {
    fn specs() -> &'static [ParamSpec<Self>] {
        &SENSOR_SPECS
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{assert_every_bound_is_enforced, assert_table_is_consistent};

    #[test]
    fn table_is_consistent_and_enforced() {
        assert_table_is_consistent::<SensorParams>();
        assert_every_bound_is_enforced::<SensorParams>();
    }

    /// The default accelerometer bias wanders by the ADIS16448's in-run bias stability
    /// (0.25 mg, 1σ): a first-order Gauss–Markov bias has the stationary standard deviation
    /// random_walk · √(τ/2).
    #[test]
    fn the_default_accel_bias_wanders_by_the_datasheet_bias_stability() {
        let p = SensorParams::default();
        let sigma = p.accel_bias_random_walk * (p.accel_bias_correlation_time / 2.0).sqrt();
        let mg = sigma / 9.80665 * 1e3;
        assert!((0.2..0.3).contains(&mg), "{sigma} m/s² = {mg} mg");
    }

    #[test]
    fn a_bad_value_names_the_parameter_and_its_bound() {
        let err = SensorParams::from_toml_str("gps_rate = 0")
            .unwrap_err()
            .to_string();
        assert!(err.contains("`gps_rate` = 0 Hz is out of range"), "{err}");
    }
}
