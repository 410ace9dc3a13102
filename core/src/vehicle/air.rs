//! The seam's air part: what a [`crate::world::World`] and the flight tasks (Hover,
//! Waypoints, the multi-agent task) need of a vehicle beyond [`Vehicle`] — its multirotor
//! state and parameters, the rotor thrust that makes its wake, its hull, the wind and force
//! the world puts on it, its own random stream. Both hold their vehicles as
//! `Box<dyn AirVehicle>`, so neither names a model: any frame of the multirotor flies there,
//! and a model that implements this trait would too.
//!
//! A boxed air vehicle clones ([`AirVehicle::clone_boxed`]), compares, prints and (de)serialises
//! (as its [`Vehicle::save`] bytes, read back by [`restore`]), so the world and the tasks stay
//! plain data that snapshots and clones as before.

use super::Vehicle;
use crate::quadrotor::{BodyState, Frame, Motors, QuadrotorParams};
use crate::rng::SimRng;
use crate::snapshot::SnapshotError;
use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::any::Any;

/// A vehicle that flies in air, with a multirotor's state and parameters (any frame): what a
/// world and the flight tasks read and set of it (module docs). Every accessor is cheap (no
/// derivative is evaluated), so a world reads thousands per grid point.
pub trait AirVehicle: Vehicle + Send + Sync + Any {
    /// Its parameters (mass, gravity, arm length, wind, ground, …).
    fn params(&self) -> &QuadrotorParams;
    /// Mutable parameters (a task's randomisation draws them; a world turns the own wind
    /// off). Set only values that were validated.
    fn params_mut(&mut self) -> &mut QuadrotorParams;
    /// Its rotor table.
    fn frame(&self) -> &Frame;
    /// Its rigid-body and motor state.
    fn body(&self) -> &BodyState;
    /// Mutable state (front ends and tests that place the vehicle by hand).
    fn body_mut(&mut self) -> &mut BodyState;
    /// Attitude, body FLU → world ENU.
    fn attitude(&self) -> UnitQuaternion<f64>;
    /// The motor commands in effect, one per rotor (no allocation).
    fn motor_command(&self) -> Motors;
    /// Linear acceleration (world, total force / mass) and angular acceleration (body) now.
    fn accelerations(&self) -> (Vector3<f64>, Vector3<f64>);
    /// Total wind at the vehicle (its own + the external), world ENU, m/s.
    fn wind_velocity(&self) -> Vector3<f64>;
    /// Total rotor thrust now, N: what makes its wake.
    fn thrust(&self) -> f64;
    /// Motor state at which it hovers (`None` when no state in [0, 1] can).
    fn hover_motor_state(&self) -> Option<f64>;
    /// Starts a new episode in place at `body`, its own wind drawn from `rng`, no external
    /// wind or force.
    fn restart(&mut self, body: BodyState, rng: SimRng);
    /// Its random stream (tasks that sample from the same stream).
    fn rng_mut(&mut self) -> &mut SimRng;
    /// The wind added from outside, world ENU, m/s (what [`Vehicle::set_external_wind`]
    /// last set: a world's wind field, the faults' air).
    fn external_wind(&self) -> Vector3<f64>;
    /// Sets the force from outside (a world's contacts and downwash), world ENU, N, held
    /// until changed; not saved with the vehicle (whoever applies it saves it).
    fn set_external_force(&mut self, force: Vector3<f64>);
    /// Hands its air to a world: its own wind off and cleared, no external wind or force.
    fn join_world(&mut self);
    /// A copy in a new box.
    fn clone_boxed(&self) -> Box<dyn AirVehicle>;
    /// Whether `other` is the same model in the same state.
    fn same_as(&self, other: &dyn AirVehicle) -> bool;
    /// Itself as `Any`, for [`AirVehicle::same_as`].
    fn as_any(&self) -> &dyn Any;
}

/// An air vehicle from [`Vehicle::save`] bytes of any model that flies in air (the
/// multirotor, of any frame). Foreign or damaged bytes are an error.
pub fn restore(bytes: &[u8]) -> Result<Box<dyn AirVehicle>, SnapshotError> {
    crate::quadrotor::restore_air_vehicle(bytes)
}

impl Clone for Box<dyn AirVehicle> {
    fn clone(&self) -> Self {
        self.clone_boxed()
    }
}

// On the box, not on `dyn AirVehicle`: a derived `==` on a boxed trait object would try to
// move the box (rust-lang/rust#31740).
impl PartialEq for Box<dyn AirVehicle> {
    fn eq(&self, other: &Self) -> bool {
        self.same_as(other.as_ref())
    }
}

impl std::fmt::Debug for dyn AirVehicle {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AirVehicle")
            .field("frame", &self.frame().name())
            .field("body", self.body())
            .field("command", &self.motor_command())
            .finish()
    }
}

impl Serialize for dyn AirVehicle {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let bytes = self.save().map_err(serde::ser::Error::custom)?;
        bytes.serialize(serializer)
    }
}

impl<'de> Deserialize<'de> for Box<dyn AirVehicle> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let bytes = Vec::<u8>::deserialize(deserializer)?;
        restore(&bytes).map_err(serde::de::Error::custom)
    }
}
