//! Policy.fmu: a trained flyloop policy as an FMI 2.0 and FMI 3.0 Co-Simulation FMU. The
//! network is ONNX, evaluated by tract-onnx; the observation is built inside from inputs
//! named like the plant's outputs, by the recipe the policy was trained with ([`recipe`],
//! [`observation`]). The FMI layer is flyloop-fmu's (its exports are this library's too):
//! this crate adds a model ([`model::Policy`]) read from the FMU's resources, and registers
//! its [`catalog::Policies`] with that layer when the library is loaded. A library of its own,
//! so that the plant FMUs do not link tract.

pub mod catalog;
pub mod error;
pub mod estimate;
pub mod model;
pub mod network;
pub mod observation;
pub mod pack;
pub mod ports;
pub mod recipe;

pub use error::PolicyError;

/// Registers [`catalog::Policies`] with the FMI layer (again: no effect). The library does
/// it when loaded; tests and benchmarks linking the rlib call it themselves.
pub extern "C" fn register() {
    flyloop_fmu::models::register_catalog(&catalog::Policies);
}

// Runs `register` when the library is loaded (before any fmi2Instantiate): the ELF
// constructor list, which the linker keeps. FMUs here are linux64 / x86_64-linux only.
#[used]
#[unsafe(link_section = ".init_array")]
static REGISTER: extern "C" fn() = register;
