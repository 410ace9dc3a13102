//! The multirotor behind the vehicle seam ([`crate::vehicle`]).

use super::frame::Frame;
use super::model::Quadrotor;
use super::params::QuadrotorParams;
use super::state::{BodyState, Motors, WindState};
use crate::error::{CommandError, ParamError};
use crate::rng::SimRng;
use crate::snapshot::SnapshotError;
use crate::vehicle::{AirVehicle, AirVehicleStart, Kinematics, Vehicle, VehicleStart};
use nalgebra::{UnitQuaternion, Vector3};
use std::any::Any;

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

/// [`standing_multirotor`] standing at (`x`, `y`) (world ENU, m), as an air vehicle: what a
/// fleet's world starts each of its vehicles from.
pub fn standing_multirotor_at(
    params: QuadrotorParams,
    frame: Frame,
    seed: u64,
    [x, y]: [f64; 2],
) -> Result<AirVehicleStart, ParamError> {
    let mut quad = Quadrotor::standing(params, seed)?.with_frame(frame);
    quad.body.position.x = x;
    quad.body.position.y = y;
    Ok(AirVehicleStart::new(quad))
}

/// A multirotor at rest in `body` (motors as `body` says), its wind drawn from `rng`: what a
/// flight task or a world builds its vehicles from.
pub fn multirotor_at(
    params: QuadrotorParams,
    frame: Frame,
    body: BodyState,
    rng: SimRng,
) -> Result<Box<dyn AirVehicle>, ParamError> {
    Ok(Box::new(
        Quadrotor::new(params, body, rng)?.with_frame(frame),
    ))
}

/// An air vehicle from a multirotor's [`Vehicle::save`] bytes (see [`crate::vehicle::air::restore`]).
pub fn restore_air_vehicle(bytes: &[u8]) -> Result<Box<dyn AirVehicle>, SnapshotError> {
    Ok(Box::new(Quadrotor::restore(bytes)?))
}

impl From<Quadrotor> for Box<dyn AirVehicle> {
    fn from(quad: Quadrotor) -> Self {
        Box::new(quad)
    }
}

impl AirVehicle for Quadrotor {
    fn params(&self) -> &QuadrotorParams {
        &self.params
    }

    fn params_mut(&mut self) -> &mut QuadrotorParams {
        &mut self.params
    }

    fn frame(&self) -> &Frame {
        Quadrotor::frame(self)
    }

    fn body(&self) -> &BodyState {
        &self.body
    }

    fn body_mut(&mut self) -> &mut BodyState {
        &mut self.body
    }

    fn attitude(&self) -> UnitQuaternion<f64> {
        Quadrotor::attitude(self)
    }

    fn motor_command(&self) -> Motors {
        self.command()
    }

    fn accelerations(&self) -> (Vector3<f64>, Vector3<f64>) {
        Quadrotor::accelerations(self)
    }

    fn wind_velocity(&self) -> Vector3<f64> {
        Quadrotor::wind_velocity(self)
    }

    fn thrust(&self) -> f64 {
        Quadrotor::thrust(self)
    }

    fn hover_motor_state(&self) -> Option<f64> {
        Quadrotor::hover_motor_state(self)
    }

    fn restart(&mut self, body: BodyState, rng: SimRng) {
        Quadrotor::restart(self, body, rng);
    }

    fn rng_mut(&mut self) -> &mut SimRng {
        Quadrotor::rng_mut(self)
    }

    fn external_wind(&self) -> Vector3<f64> {
        self.external_wind
    }

    fn set_external_force(&mut self, force: Vector3<f64>) {
        self.external_force = force;
    }

    fn join_world(&mut self) {
        self.params.wind_enabled = false;
        self.wind = WindState::default();
        self.external_wind = Vector3::zeros();
        self.external_force = Vector3::zeros();
    }

    fn clone_boxed(&self) -> Box<dyn AirVehicle> {
        Box::new(self.clone())
    }

    fn same_as(&self, other: &dyn AirVehicle) -> bool {
        other.as_any().downcast_ref::<Quadrotor>() == Some(self)
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
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

    fn set_external_wind(&mut self, wind: nalgebra::Vector3<f64>) {
        self.external_wind = wind;
    }
}
