//! The multirotor behind the vehicle seam ([`crate::vehicle`]).

use super::frame::Frame;
use super::model::Quadrotor;
use super::params::QuadrotorParams;
use crate::error::{CommandError, ParamError};
use crate::snapshot::SnapshotError;
use crate::vehicle::{Kinematics, Vehicle, VehicleStart};

/// A multirotor of `frame` with `params` standing on its landing gear at the origin, facing
/// north, motors off, its wind drawn from `seed`: what an autopilot session starts from.
pub fn standing_multirotor(
    params: QuadrotorParams,
    frame: Frame,
    seed: u64,
) -> Result<VehicleStart, ParamError> {
    Ok(VehicleStart::new(
        Quadrotor::standing(params, seed)?.with_frame(frame),
    ))
}

impl Vehicle for Quadrotor {
    fn actuator_count(&self) -> usize {
        self.frame().rotor_count()
    }

    fn set_actuators(&mut self, commands: &[f64]) -> Result<(), CommandError> {
        self.set_command(commands)
    }

    fn actuators(&self) -> Vec<f64> {
        self.command().to_vec()
    }

    fn actuator_states(&self) -> Vec<f64> {
        self.body.motors.to_vec()
    }

    fn advance(&mut self, dt: f64) {
        self.step(dt);
    }

    fn kinematics(&self) -> Kinematics {
        let b = &self.body;
        Kinematics {
            position: b.position,
            velocity: b.velocity,
            attitude: self.attitude(),
            body_rates: b.body_rates,
            acceleration: self.accelerations().0,
            gravity: self.params.gravity,
            air_velocity: self.air_velocity(),
        }
    }

    fn is_grounded(&self) -> bool {
        Quadrotor::is_grounded(self)
    }

    fn is_finite(&self) -> bool {
        let b = &self.body;
        (b.position.iter())
            .chain(b.velocity.iter())
            .chain(b.body_rates.iter())
            .chain(b.attitude.coords.iter())
            .chain(b.motors.iter())
            .all(|v| v.is_finite())
    }

    fn save(&self) -> Result<Vec<u8>, SnapshotError> {
        Quadrotor::save(self)
    }
}
