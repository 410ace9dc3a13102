//! One rotor of a frame ([`super::frame`]): where it sits, which way it turns, and its own
//! coefficients where they differ from the vehicle's.

use serde::{Deserialize, Serialize};

/// Most rotors a frame may have.
pub const MAX_ROTORS: usize = 12;

/// Direction a rotor turns, seen from above.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Spin {
    /// Clockwise: its reaction torque turns the body toward +z (left).
    Cw,
    /// Counter-clockwise: its reaction torque turns the body toward −z.
    Ccw,
}

impl Spin {
    /// +1 for clockwise, −1 for counter-clockwise: the sign of the rotor's yaw torque.
    pub fn sign(self) -> f64 {
        match self {
            Spin::Cw => 1.0,
            Spin::Ccw => -1.0,
        }
    }
}

/// One rotor of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rotor {
    /// Position forward of the centre of mass (body x), in units of `arm_length`.
    pub x: f64,
    /// Position left of the centre of mass (body y), in units of `arm_length`.
    pub y: f64,
    /// Direction of rotation seen from above.
    pub spin: Spin,
    /// Thrust at full motor state, N; none = the vehicle's `thrust_coefficient`.
    #[serde(default)]
    pub thrust_coefficient: Option<f64>,
    /// Spin reaction torque per newton of thrust, m; none = the vehicle's
    /// `yaw_torque_coefficient`.
    #[serde(default)]
    pub torque_coefficient: Option<f64>,
    /// First-order motor lag time constant, s; none = the vehicle's `motor_time_constant`.
    #[serde(default)]
    pub time_constant: Option<f64>,
}

impl Rotor {
    /// A rotor at (x, y) × `arm_length` turning `spin`, with the vehicle's coefficients.
    pub const fn at(x: f64, y: f64, spin: Spin) -> Self {
        Rotor {
            x,
            y,
            spin,
            thrust_coefficient: None,
            torque_coefficient: None,
            time_constant: None,
        }
    }
}
