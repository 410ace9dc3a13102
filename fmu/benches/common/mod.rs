//! Set-up the FMU benches share (fmu-policy's bench includes this file too): a co-simulation
//! instance through the C ABI, instantiated and in initialization mode at t = 0, for the
//! bench to set its start values and leave initialization mode.

// Each bench uses some of these; a failed setup is a failed benchmark.
#![allow(dead_code, clippy::unwrap_used, clippy::expect_used)]

use flyloop_fmu::exports::*;
use flyloop_fmu::fmi2_types::*;
use flyloop_fmu::fmi3_types::{fmi3Instance, fmi3Status};
use flyloop_fmu::table::ModelTable;
use std::ffi::CStr;

#[path = "../../tests/support/importer_logger.rs"]
mod importer_logger;

/// An FMI 2.0 instance of `table`'s model with a quiet logger, its experiment set up from 0
/// without stop time or tolerance, in initialization mode.
pub fn initializing2(table: &ModelTable) -> fmi2Component {
    let callbacks = Box::leak(Box::new(importer_logger::callbacks(
        importer_logger::quiet,
        std::ptr::null_mut(),
    )));
    // SAFETY: valid strings, callbacks leaked for the process's lifetime.
    unsafe {
        let c = fmi2Instantiate(
            c"bench".as_ptr(),
            fmi2CoSimulation,
            table.guid.as_ptr(),
            std::ptr::null(),
            callbacks,
            fmi2False,
            fmi2False,
        );
        assert!(!c.is_null());
        assert_eq!(
            fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi2EnterInitializationMode(c), fmi2Status::fmi2OK);
        c
    }
}

/// An FMI 3.0 instance of `table`'s model (resources from `resources`, no logger: FMI 3.0
/// allows NULL), in initialization mode from 0 without stop time or tolerance.
pub fn initializing3(table: &ModelTable, resources: Option<&CStr>) -> fmi3Instance {
    let resources = resources.map_or(std::ptr::null(), CStr::as_ptr);
    // SAFETY: valid strings that outlive the call.
    unsafe {
        let c = fmi3InstantiateCoSimulation(
            c"bench".as_ptr(),
            table.token3.as_ptr(),
            resources,
            0,
            0,
            0,
            0,
            std::ptr::null(),
            0,
            std::ptr::null_mut(),
            None,
            None,
        );
        assert!(!c.is_null());
        assert_eq!(
            fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0),
            fmi3Status::fmi3OK
        );
        c
    }
}
