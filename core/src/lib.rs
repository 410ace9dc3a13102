//! flyloop's dynamics core.
//!
//! Two models — [`quadrotor`] (3D, nalgebra, RK4) and `lander2d` (2D, rapier2d) — and the
//! tasks built on them ([`tasks`]): Hover, Waypoints and Landing. Everything here is plain
//! data and pure functions: no I/O, no clock, no FFI, no globals. One seeded [`rng::SimRng`]
//! per instance makes every trajectory reproducible bit for bit.
//!
//! Frames: the quadrotor's world is ENU (x east, y north, z up) and its body FLU (x forward,
//! y left, z up); quaternions are `[w, x, y, z]` (Hamilton, body → world).
//!
//! ```
//! use flyloop_core::quadrotor::QuadrotorParams;
//! use flyloop_core::tasks::{Task, flight::FlightParams, hover::Hover};
//!
//! let mut task = Hover::new(QuadrotorParams::default(), FlightParams::default())?;
//! task.reset(42); // same seed → bit-identical episode
//! let outcome = task.step(&[0.495, 0.495, 0.495, 0.495])?;
//! let mut obs = [0f32; 33];
//! task.write_observation(&mut obs);
//! assert!(!outcome.terminated && obs.iter().all(|v| v.is_finite()));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod error;
pub mod faults;
pub mod frames;
pub mod lander2d;
pub mod number;
pub mod params;
pub mod quadrotor;
pub mod rate_loop;
pub mod reference;
pub mod rng;
pub mod sensors;
pub mod snapshot;
pub mod tasks;
pub mod variables;
pub mod vehicle;
pub mod world;

pub use error::{CommandError, InputError, ParamError, Role};
pub use params::{ParamSpec, Parameters, ValueKind};
pub use rng::SimRng;
pub use snapshot::SnapshotError;
