//! flyloop's dynamics core.
//!
//! Two models — [`quadrotor`] (3D, nalgebra, RK4) and `lander2d` (2D, rapier2d) — and the
//! tasks built on them ([`tasks`]): Hover, Waypoints and Landing. Everything here is plain
//! data and pure functions: no I/O, no clock, no FFI, no globals. One seeded [`rng::SimRng`]
//! per instance makes every trajectory reproducible bit for bit.
//!
//! Frames: the quadrotor's world is ENU (x east, y north, z up) and its body FLU (x forward,
//! y left, z up); quaternions are `[w, x, y, z]` (Hamilton, body → world).

pub mod error;
pub mod lander2d;
pub mod params;
pub mod quadrotor;
pub mod rng;
pub mod snapshot;
pub mod tasks;
pub mod variables;

pub use error::ParamError;
pub use params::{ParamSpec, Parameters, ValueKind};
pub use rng::SimRng;
pub use snapshot::SnapshotError;
