//! The SITL program as a function, so the wheel ships it without a separate binary.

use pyo3::prelude::*;

/// Runs `flyloop-sitl` with `argv` (program name first) until SIGINT / SIGTERM and returns
/// its exit code. The GIL is released while it runs.
#[pyfunction]
pub fn sitl_main(py: Python<'_>, argv: Vec<String>) -> u8 {
    py.detach(move || flyloop_sitl::app::main_with_args(argv))
}
