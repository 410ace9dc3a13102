//! `flyloop._native`: flyloop's core tasks in-process for Python.
//!
//! - [`batch::Batch`]: N task instances stepped in one call (the GIL released, split over a
//!   thread pool), writing into numpy arrays the caller preallocated; N = 1 serves the
//!   single env.
//! - [`tables::describe`]: a task's observation bounds, action bounds, control period, info
//!   layout and parameter table, straight from the core, so Python keeps no copy.
//! - [`sitl_command::sitl_main`]: the `flyloop-sitl` program as a library call (the wheel's
//!   console command).
//!
//! Nothing here computes physics, a reward or a termination: every step goes through the
//! same [`flyloop_sitl::model::TaskInstance`] the SITL flies, actions are treated by the
//! SITL's [`flyloop_sitl::vehicle::clamp_controls`] and info values flattened by its
//! [`flyloop_sitl::task_frame::push_infos`].

mod batch;
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
    m.add_function(wrap_pyfunction!(tables::describe, m)?)?;
    m.add_function(wrap_pyfunction!(sitl_command::sitl_main, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The task frame's layout (flyloop_sitl::task_frame), for the SITL backend's reader.
    m.add("FRAME_HEADER_LEN", flyloop_sitl::task_frame::HEADER_LEN)?;
    m.add("FRAME_ARRAY_LEN", flyloop_sitl::task_frame::ARRAY_LEN)?;
    Ok(())
}
