//! `flyloop._native`: flyloop's core tasks in-process for Python.
//!
//! - [`batch::Batch`]: N task instances stepped in one call (the GIL released, split over a
//!   thread pool), writing into numpy arrays the caller preallocated; N = 1 serves the
//!   single env.
//! - [`multi_batch::MultiBatch`]: W worlds × N agents of a multi-agent task in one call.
//! - [`tables::describe`]: a task's observation bounds, action bounds, control period, info
//!   layout and parameter table, straight from the core, so Python keeps no copy;
//!   [`tables::frames`] the shipped frames' rotor tables.
//! - [`sitl_command::sitl_main`]: the `flyloop-sitl` program as a library call (the wheel's
//!   console command).
//!
//! Nothing here computes physics, a reward or a termination: every step goes through the
//! core's task registry the SITL flies too ([`flyloop_core::tasks::registry`]): the same
//! [`TaskInstance`](flyloop_core::tasks::registry::TaskInstance), actions treated by
//! [`clamp_controls`](flyloop_core::tasks::registry::clamp_controls) and info values
//! flattened by [`push_infos`](flyloop_core::tasks::registry::push_infos). The SITL crate is
//! linked for the `flyloop-sitl` command alone ([`sitl_command`]).

mod batch;
mod multi_batch;
mod sitl_command;
mod tables;

use pyo3::prelude::*;

/// Panics with `message`: lets the tests check that a Rust panic reaches Python as an
/// exception (pyo3's PanicException), never an abort. Not part of the API.
#[pyfunction]
fn _panic_for_test(message: &str) {
    panic!("{message}");
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<batch::Batch>()?;
    m.add_class::<multi_batch::MultiBatch>()?;
    m.add_function(wrap_pyfunction!(tables::describe, m)?)?;
    m.add_function(wrap_pyfunction!(tables::frames, m)?)?;
    m.add_function(wrap_pyfunction!(tables::fault_catalogue, m)?)?;
    m.add_function(wrap_pyfunction!(sitl_command::sitl_main, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    sitl_command::add_frame_layout(m)?;
    Ok(())
}
