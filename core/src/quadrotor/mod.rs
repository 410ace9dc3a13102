//! The 3D quadrotor of seed 001, with the reference's numbers and without its bugs (both
//! listed in docs/reference/quadrotor.md).
//!
//! See [`dynamics`] for the equations, [`params`] for the parameter table, [`variables`] for
//! the table the FMU and the SITL read.

pub mod contact;
pub mod continuous;
pub mod dynamics;
mod effectiveness;
pub mod frame;
mod mixing;
pub mod model;
pub mod params;
mod rotor;
mod seam;
pub mod state;
pub mod variables;
pub mod wind;

pub use frame::{Frame, FrameError, FrameTable, Rotor, Spin};
pub use model::Quadrotor;
pub use params::{QuadrotorInitial, QuadrotorParams};
pub use seam::{multirotor_at, restore_air_vehicle, standing_multirotor, standing_multirotor_at};
pub use state::{BodyState, Motors, WindState};
