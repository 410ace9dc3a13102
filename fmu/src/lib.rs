//! FMI front end of flyloop-core: `Quadrotor.fmu` (FMI 2.0 Co-Simulation and Model Exchange),
//! `Lander2D.fmu` (FMI 2.0 Co-Simulation) and their FMI 3.0 twins `Quadrotor-fmi3.fmu` and
//! `Lander2D-fmi3.fmu`, all from one cdylib that exports both APIs.
//!
//! Layers, from the C boundary down:
//! - [`exports`]: every `fmi2*` and `fmi3*` function ([`exports::fmi2`], [`exports::fmi3`], the
//!   bodies they share in `exports::shared`), each inside `catch_unwind` (a panic becomes
//!   fmi2Fatal, never an abort of the importer), with NULL checks and the stage check.
//! - [`instance`]: the state machine (stages and the allowed-stage mask of each function, as
//!   in modelica/Reference-FMUs), logging by category, the FMU states handed out.
//! - [`engine`]: start values, experiment, the time grid t0 + n·h, variable access, doStep
//!   checks, FMU state bytes and Model Exchange — for any [`model::FmuModel`].
//! - [`models`]: the quadrotor and the lander behind `FmuModel`; the GUID picks one.
//!
//! [`table`] holds each model's variables as the FMI layer looks them up (with the FMI 3.0
//! view: arrays, `time`, event indicators); [`model_description`] writes each
//! modelDescription.xml from it; [`pack`] zips the FMUs (binary
//! `flyloop-fmu-pack`).

pub mod engine;
pub mod error;
pub mod exports;
pub mod fmi2_types;
pub mod fmi3_types;
pub mod guid;
pub mod instance;
pub mod log;
pub mod model;
pub mod model_description;
pub mod models;
pub mod pack;
pub mod state_record;
pub mod table;
pub mod units;

pub use error::FmuError;

// The importer's test logger (tests/support) names the crate by its name, also in unit tests.
#[cfg(test)]
extern crate self as flyloop_fmu;
