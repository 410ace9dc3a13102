//! The SITL program as a function, so the wheel ships it without a separate binary, and the
//! layout of its task frame for the Python SITL backend's reader.

use flyloop_sitl::task_frame;
use pyo3::prelude::*;

/// Runs `flyloop-sitl` with `argv` (program name first) until SIGINT / SIGTERM and returns
/// its exit code. The GIL is released while it runs.
#[pyfunction]
pub fn sitl_main(py: Python<'_>, argv: Vec<String>) -> u8 {
    py.detach(move || flyloop_sitl::app::main_with_args(argv))
}

/// Adds the task frame's layout constants: `FRAME_HEADER_LEN` values before the
/// observation, `FRAME_ARRAY_LEN` values per DEBUG_FLOAT_ARRAY.
pub fn add_frame_layout(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("FRAME_HEADER_LEN", task_frame::HEADER_LEN)?;
    m.add("FRAME_ARRAY_LEN", task_frame::ARRAY_LEN)
}
