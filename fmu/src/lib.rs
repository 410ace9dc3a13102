//! FMI front end of flyloop-core: `Quadrotor.fmu` and `Hexacopter.fmu` (one multirotor model
//! with two rotor tables; FMI 2.0 Co-Simulation and Model Exchange), `Lander2D.fmu` (FMI 2.0
//! Co-Simulation) and their FMI 3.0 twins `<Model>-fmi3.fmu`, all from one cdylib that exports
//! both APIs. From the C boundary down:
//! [`exports`], [`instance`] (the state machine), [`engine`] (for any [`model::FmuModel`]),
//! [`models`]; [`model_description`] and [`pack`] write the FMUs.

pub mod api;
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
pub mod table;
pub mod units;

pub use error::FmuError;

// The importer's test logger (tests/support) names the crate by its name, also in unit tests.
#[cfg(test)]
extern crate self as flyloop_fmu;
