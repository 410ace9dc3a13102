//! FMI front end of flyloop-core: `Quadrotor.fmu` (FMI 2.0 Co-Simulation and Model Exchange),
//! `Lander2D.fmu` (FMI 2.0 Co-Simulation) and their FMI 3.0 twins `Quadrotor-fmi3.fmu` and
//! `Lander2D-fmi3.fmu`, all from one cdylib that exports both APIs.
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
//! [`model_description`] and [`model_description3`] write each modelDescription.xml from the
//! core's variable tables ([`fmi3_variables`]: the FMI 3.0 view, with arrays);
//! [`pack`] zips the FMUs (binary `flyloop-fmu-pack`).

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
pub mod model_description3;
pub mod models;
pub mod pack;
pub mod state_record;
pub mod table;
pub mod units;

pub use error::FmuError;

// The importer's test logger (tests/support) names the crate by its name, also in unit tests.
#[cfg(test)]
extern crate self as flyloop_fmu;
