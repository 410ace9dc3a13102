//! FMI 2.0 front end of flyloop-core: `Quadrotor.fmu` (Co-Simulation and Model Exchange) and
//! `Lander2D.fmu` (Co-Simulation) from one cdylib.
//!
//! Layers, from the C boundary down:
//! - [`exports`]: every `fmi2*` function, each inside `catch_unwind` (a panic becomes
//!   fmi2Fatal, never an abort of the importer), with NULL checks and the stage check.
//! - [`instance`]: the state machine (stages and the allowed-stage mask of each function, as
//!   in modelica/Reference-FMUs), logging by category, the FMU states handed out.
//! - [`simulation`]: start values, experiment, the time grid t0 + n·h, typed variable access,
//!   doStep checks, FMU state bytes — for any [`model::FmuModel`].
//! - [`exchange`]: Model Exchange on top of the engine (time, states, events).
//! - [`models`]: the quadrotor and the lander behind `FmuModel`; the GUID picks one.
//!
//! [`model_description`] writes each modelDescription.xml from the core's variable tables;
//! [`pack`] zips the FMUs (binary `flyloop-fmu-pack`).

pub mod error;
pub mod exchange;
pub mod exports;
pub mod fmi2_types;
pub mod guid;
pub mod importer_logger;
pub mod instance;
pub mod log;
pub mod model;
pub mod model_description;
pub mod models;
pub mod pack;
pub mod simulation;
pub mod state_record;
pub mod units;

pub use error::FmuError;
