//! Inertial measurement unit: accelerometer (specific force) and gyroscope, body FRD.
//!
//! accel = Rᵀ(a + g·up) + b_a + n_a and gyro = ω + b_g + n_g, with a the model's own
//! acceleration (total force / mass, contact force included, so a vehicle resting on the
//! ground reads (0, 0, −g)), white noise n of standard deviation density/√dt per sample, and
//! biases b that wander as first-order Gauss–Markov processes (random walk with a long
//! correlation time, as an IMU datasheet's bias instability describes).

use crate::frames::flu_to_frd;
use crate::rng::SimRng;
use nalgebra::{UnitQuaternion, Vector3};

/// One IMU sample, body FRD.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuReading {
    /// Specific force (acceleration minus gravity), m/s²; level at rest about (0, 0, −g).
    pub accel: Vector3<f64>,
    /// Angular velocity, rad/s.
    pub gyro: Vector3<f64>,
}

/// Ideal specific force in body FRD for the acceleration `accel_enu` (world ENU, m/s²) of a
/// body with attitude `attitude` (body FLU → world ENU) under gravity `gravity` (m/s²).
pub fn specific_force_frd(
    attitude: &UnitQuaternion<f64>,
    accel_enu: &Vector3<f64>,
    gravity: f64,
) -> Vector3<f64> {
    let world = accel_enu + Vector3::new(0.0, 0.0, gravity);
    flu_to_frd(&attitude.inverse_transform_vector(&world))
}

/// White noise of a sensor given as a density (unit/√Hz), sampled every `dt` seconds: each
/// sample's standard deviation is density / √dt.
pub fn white_noise_std(density: f64, dt: f64) -> f64 {
    density / dt.sqrt()
}

/// One step of length `dt` of a first-order Gauss–Markov bias with driving noise density
/// `random_walk` and correlation time `tau` (exact discretisation: b ← φb + σ·N, φ = e^(−dt/τ),
/// σ² = random_walk²·τ/2·(1 − φ²)).
pub fn step_bias(bias: &mut Vector3<f64>, random_walk: f64, tau: f64, dt: f64, rng: &mut SimRng) {
    let phi = (-dt / tau).exp();
    let sigma = random_walk * (0.5 * tau * (1.0 - phi * phi)).sqrt();
    for b in bias.iter_mut() {
        *b = phi * *b + sigma * rng.normal();
    }
}

/// `v` plus independent normal noise of standard deviation `std` on each axis.
pub fn with_noise(v: Vector3<f64>, std: f64, rng: &mut SimRng) -> Vector3<f64> {
    Vector3::new(
        v.x + std * rng.normal(),
        v.y + std * rng.normal(),
        v.z + std * rng.normal(),
    )
}
