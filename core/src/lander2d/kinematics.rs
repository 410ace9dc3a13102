//! The lander's state in the vehicle seam's frames ([`crate::vehicle::Kinematics`]).

use super::model::Lander2d;
use crate::vehicle::Kinematics;
use nalgebra::{UnitQuaternion, Vector3};

impl Lander2d {
    /// The lander's plane is the world's east–up plane: x → east, y → up, north = 0, the
    /// body's forward axis along the lander's +x. Its angle is counter-clockwise as seen with
    /// east to the right and up on top, i.e. looking north, so it turns the body about the
    /// north axis by −angle: a positive angle lifts the nose (a positive FRD pitch).
    pub fn kinematics(&self) -> Kinematics {
        let d = self.drone();
        let [ax, ay] = self.acceleration();
        let [air_x, air_y] = self.air_velocity();
        Kinematics {
            position: Vector3::new(d.x, 0.0, d.y),
            velocity: Vector3::new(d.vx, 0.0, d.vy),
            attitude: UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -d.angle),
            body_rates: Vector3::new(0.0, -d.angular_velocity, 0.0),
            acceleration: Vector3::new(ax, 0.0, ay),
            gravity: self.params().gravity,
            air_velocity: Vector3::new(air_x, 0.0, air_y),
        }
    }
}
