//! The 2D landing drone of seed 000 on rapier2d, with the reference's numbers and without
//! its bugs (see docs/reference/lander2d.md).
//!
//! [`world`] builds the rapier scene, [`model`] steps it (thrust, noise, battery, wind,
//! moving platform), [`contact`] judges touch-downs, [`params`] holds the parameter tables,
//! [`variables`] the table the FMU and the SITL read.

pub mod contact;
pub mod model;
pub mod params;
pub mod variables;
pub mod world;

pub use crate::snapshot::SnapshotError;
pub use contact::{ContactState, wrap_angle};
pub use model::Lander2d;
pub use params::{Lander2dInitial, Lander2dParams};
pub use world::{DroneGeometry, DroneState};
