//! One rotor of a frame ([`super::frame`]): where it sits, which way it turns, and its own
//! coefficients where they differ from the vehicle's.

use serde::{Deserialize, Serialize};
use std::borrow::Cow;

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

    /// "CW" or "CCW", as the variable descriptions write it.
    pub fn label(self) -> &'static str {
        match self {
            Spin::Cw => "CW",
            Spin::Ccw => "CCW",
        }
    }
}

/// The body's eight compass words, counter-clockwise from forward in 45° steps.
const PLACES: [&str; 8] = [
    "front",
    "front-left",
    "left",
    "rear-left",
    "rear",
    "rear-right",
    "right",
    "front-right",
];

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

    /// Where the rotor sits, seen from above: a compass word of the body ("front-right")
    /// when it is on one of the eight, else its bearing ("30° left of forward").
    pub fn place(&self) -> Cow<'static, str> {
        let bearing = self.y.atan2(self.x).to_degrees();
        let octant = bearing / 45.0;
        if (octant - octant.round()).abs() < 1e-9 {
            return Cow::Borrowed(PLACES[(octant.round() as i64).rem_euclid(8) as usize]);
        }
        let side = if bearing > 0.0 { "left" } else { "right" };
        let degrees = (bearing.abs() * 10.0).round() / 10.0;
        Cow::Owned(format!("{degrees}° {side} of forward"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rotor_is_placed_by_compass_word_or_by_bearing() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let place = |x, y| Rotor::at(x, y, Spin::Cw).place();
        assert_eq!(place(h, -h), "front-right");
        assert_eq!(place(-h, h), "rear-left");
        assert_eq!(place(0.0, -1.0), "right");
        assert_eq!(place(-1.0, 0.0), "rear");
        assert_eq!(place(0.866_025_403_784_438_6, 0.5), "30° left of forward");
        assert_eq!(
            place(-0.923_879_532_511_286_7, -0.382_683_432_365_089_8),
            "157.5° right of forward"
        );
        assert_eq!(Spin::Ccw.label(), "CCW");
    }
}
