//! The vehicle seam: what every front end (the FMU, the tasks and gym envs, the MAVLink
//! SITL, the PX4 and ArduPilot sessions, the sensors, the telemetry) needs of a vehicle, in one
//! trait, so none of them reaches into a model's own type.
//!
//! A vehicle takes as many actuator commands as it has actuators (a multirotor: one per
//! rotor of its frame), advances on its own physics grid, and reports its [`Kinematics`] in the
//! core's frames (world ENU, body FLU); [`crate::frames`] turns those into NED / FRD. The
//! sensors read the kinematics, so a sensor model never depends on which model flies.

pub mod air;

pub use air::AirVehicle;

use crate::error::CommandError;
use crate::frames::{enu_to_ned, flu_to_frd};
use crate::snapshot::SnapshotError;
use nalgebra::{UnitQuaternion, Vector3};

/// A vehicle's state as the sensors, the autopilot links and the telemetry read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Kinematics {
    /// Position, world ENU, m.
    pub position: Vector3<f64>,
    /// Velocity, world ENU, m/s.
    pub velocity: Vector3<f64>,
    /// Attitude, body FLU → world ENU.
    pub attitude: UnitQuaternion<f64>,
    /// Angular velocity in the body frame FLU, rad/s.
    pub body_rates: Vector3<f64>,
    /// Kinematic acceleration (total force / mass, gravity included), world ENU, m/s².
    pub acceleration: Vector3<f64>,
    /// Gravitational acceleration of the model, m/s² (positive).
    pub gravity: f64,
    /// Velocity relative to the air, world ENU, m/s.
    pub air_velocity: Vector3<f64>,
}

impl Kinematics {
    /// Position north, east, down from the local origin, m.
    pub fn position_ned(&self) -> Vector3<f64> {
        enu_to_ned(&self.position)
    }

    /// Velocity north, east, down, m/s.
    pub fn velocity_ned(&self) -> Vector3<f64> {
        enu_to_ned(&self.velocity)
    }

    /// Body rates about FRD x, y, z (roll, pitch, yaw rate), rad/s.
    pub fn body_rates_frd(&self) -> Vector3<f64> {
        flu_to_frd(&self.body_rates)
    }

    /// What an accelerometer measures (acceleration minus gravity) in body FRD, m/s²: about
    /// (0, 0, −g) in a level hover.
    pub fn specific_force_frd(&self) -> Vector3<f64> {
        crate::sensors::imu::specific_force_frd(&self.attitude, &self.acceleration, self.gravity)
    }

    /// Speed relative to the air, m/s.
    pub fn airspeed(&self) -> f64 {
        self.air_velocity.norm()
    }
}

/// A simulated vehicle, as every front end drives it.
pub trait Vehicle {
    /// Number of actuator commands the vehicle takes (a multirotor: its rotors).
    fn actuator_count(&self) -> usize;
    /// Sets the actuator commands, one per actuator in the model's order; a vector of the
    /// wrong length or with a non-finite value is refused whole (nothing changes).
    fn set_actuators(&mut self, commands: &[f64]) -> Result<(), CommandError>;
    /// The actuator commands in effect.
    fn actuators(&self) -> Vec<f64>;
    /// What each actuator delivers now, as a fraction of its full output (a multirotor's
    /// motor states, which lag its commands).
    fn actuator_states(&self) -> Vec<f64>;
    /// Advances the vehicle by `dt` seconds on its physics grid.
    fn advance(&mut self, dt: f64);
    /// The state in the core's frames.
    fn kinematics(&self) -> Kinematics;
    /// Whether it touches the ground.
    fn is_grounded(&self) -> bool;
    /// Whether every state value is a finite number.
    fn is_finite(&self) -> bool;
    /// The whole state as bytes; a restored vehicle continues bit for bit.
    fn save(&self) -> Result<Vec<u8>, SnapshotError>;
    /// Wind added to the vehicle's own (the air faults' gusts and shear), world ENU, m/s,
    /// until set again; a vehicle that flies in no wind ignores it.
    fn set_external_wind(&mut self, _wind: Vector3<f64>) {}
}

impl std::fmt::Debug for dyn Vehicle + Send {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Vehicle")
            .field("actuators", &self.actuators())
            .field("kinematics", &self.kinematics())
            .finish()
    }
}

/// A vehicle's start state, to take again and again: every [`VehicleStart::take`] is the same
/// vehicle, bit for bit. An autopilot session goes back to it at each new connection, without
/// knowing which model it flies.
pub struct VehicleStart(Box<dyn Fn() -> Box<dyn Vehicle + Send> + Send + Sync>);

impl VehicleStart {
    /// Starts from a copy of `vehicle`'s state.
    pub fn new<V: Vehicle + Clone + Send + Sync + 'static>(vehicle: V) -> Self {
        VehicleStart(Box::new(move || Box::new(vehicle.clone())))
    }

    /// A new vehicle in the start state.
    pub fn take(&self) -> Box<dyn Vehicle + Send> {
        (self.0)()
    }
}

impl std::fmt::Debug for VehicleStart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("VehicleStart").field(&self.take()).finish()
    }
}

/// An air vehicle's start state, taken again and again as [`VehicleStart`] does: a world's
/// vehicle goes back to it (a fleet's autopilot reconnecting).
pub struct AirVehicleStart(Box<dyn AirVehicle>);

impl AirVehicleStart {
    /// Starts from a copy of `vehicle`'s state.
    pub fn new<V: AirVehicle>(vehicle: V) -> Self {
        AirVehicleStart(Box::new(vehicle))
    }

    /// A new vehicle in the start state.
    pub fn take(&self) -> Box<dyn AirVehicle> {
        self.0.clone_boxed()
    }
}

impl std::fmt::Debug for AirVehicleStart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_tuple("AirVehicleStart").field(&self.0).finish()
    }
}
