//! The drone of the lander as the physics sees it: its kinematic state and the shapes and
//! masses of its three parts (frame and two motors), from the parameters.

use super::params::Lander2dParams;
use serde::{Deserialize, Serialize};

/// Kinematic state of the drone's body (its origin is the centre of mass).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct DroneState {
    /// Centre x, m.
    pub x: f64,
    /// Centre y, m.
    pub y: f64,
    /// Angle, counter-clockwise from level, rad.
    pub angle: f64,
    /// Velocity along x, m/s.
    pub vx: f64,
    /// Velocity along y, m/s.
    pub vy: f64,
    /// Angular velocity, counter-clockwise, rad/s.
    pub angular_velocity: f64,
}

/// Shapes and masses of the drone's three parts, in body coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DroneGeometry {
    /// Half extents of the frame box, m.
    pub frame_half: (f64, f64),
    /// Half side of each square motor box, m.
    pub motor_half: f64,
    /// x of the motor centres (left at −x, right at +x), m.
    pub motor_x: f64,
    /// Masses of frame and of each motor, kg.
    pub frame_mass: f64,
    pub motor_mass: f64,
}

impl DroneGeometry {
    /// Farthest point of the drone from its centre (a motor's outer corner), m.
    pub fn reach(&self) -> f64 {
        (self.motor_x + self.motor_half).hypot(self.motor_half.max(self.frame_half.1))
    }

    pub fn of(p: &Lander2dParams) -> Self {
        let motor_x = (p.drone_width - p.drone_height) / 2.0;
        DroneGeometry {
            frame_half: (motor_x, p.drone_height / 4.0),
            motor_half: p.drone_height / 2.0,
            motor_x,
            frame_mass: 0.2 * p.drone_mass,
            motor_mass: 0.4 * p.drone_mass,
        }
    }
}
