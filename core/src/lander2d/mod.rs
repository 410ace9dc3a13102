//! The 2D landing drone of seed 000 on rapier2d, with the reference's numbers and without
//! its bugs (see docs/reference/lander2d.md).
//!
//! [`model`] steps a lander (thrust, noise, battery, wind, moving platform) through its
//! [`scene`]: [`free_body`] integrates the [`drone`] in free flight, [`world`] builds the rapier
//! world where a contact is within reach; [`contact`] judges touch-downs, [`params`] holds
//! the parameter tables, [`variables`] the table the FMU and the SITL read.

pub mod contact;
pub mod drone;
pub(crate) mod free_body;
mod kinematics;
pub mod model;
pub mod params;
pub(crate) mod scene;
mod seam;
pub mod variables;
pub mod world;

pub use crate::snapshot::SnapshotError;
pub use contact::{ContactState, wrap_angle};
pub use drone::{DroneGeometry, DroneState};
pub use model::Lander2d;
pub use params::{Lander2dInitial, Lander2dParams};
