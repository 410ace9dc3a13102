//! The quadrotor's state: rigid body, motors and wind. Plain data, serde.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// Rigid body and motor state, in the world ENU / body FLU frames.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BodyState {
    /// Position of the centre of mass in the world (ENU), m.
    pub position: Vector3<f64>,
    /// Velocity in the world (ENU), m/s.
    pub velocity: Vector3<f64>,
    /// Attitude, body (FLU) → world (ENU), unit quaternion `[w, x, y, z]`.
    pub attitude: Quaternion<f64>,
    /// Angular velocity in the BODY frame (FLU), rad/s.
    pub body_rates: Vector3<f64>,
    /// Lagged motor states in [0, 1], PX4 quad-X order (front-right, rear-left, front-left, rear-right).
    pub motors: [f64; 4],
    /// Stretch of each foot's friction bristle along the ground (world x, y), m: the
    /// stick-slip state of Coulomb friction (see `contact`). Zero for a foot off the ground.
    pub gear_stretch: [[f64; 2]; 4],
}

impl BodyState {
    /// At rest at `position` with attitude from roll/pitch/yaw (ZYX, rad) and all motors at `motor`.
    pub fn at_rest(position: Vector3<f64>, roll: f64, pitch: f64, yaw: f64, motor: f64) -> Self {
        BodyState {
            position,
            velocity: Vector3::zeros(),
            attitude: *UnitQuaternion::from_euler_angles(roll, pitch, yaw).quaternion(),
            body_rates: Vector3::zeros(),
            motors: [motor; 4],
            gear_stretch: [[0.0; 2]; 4],
        }
    }

    /// Roll, pitch, yaw (ZYX Tait–Bryan), rad.
    pub fn euler_angles(&self) -> (f64, f64, f64) {
        UnitQuaternion::new_unchecked(self.attitude).euler_angles()
    }

    /// The body z axis (thrust direction) in the world frame.
    pub fn body_z_axis(&self) -> Vector3<f64> {
        let q = &self.attitude;
        let (w, x, y, z) = (q.w, q.i, q.j, q.k);
        Vector3::new(
            2.0 * (x * z + w * y),
            2.0 * (y * z - w * x),
            1.0 - 2.0 * (x * x + y * y),
        )
    }
}

/// Wind at the vehicle: a mean drawn per episode plus Ornstein–Uhlenbeck turbulence.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct WindState {
    /// Mean wind for the episode (world ENU), m/s.
    pub mean: Vector3<f64>,
    /// Turbulence (world ENU), m/s, held since the last sample.
    pub turbulence: Vector3<f64>,
    /// Time since the last turbulence sample, s, in [0, turbulence_dt).
    pub since_sample: f64,
}

impl WindState {
    /// Total wind velocity (world ENU), m/s.
    pub fn velocity(&self) -> Vector3<f64> {
        self.mean + self.turbulence
    }
}
