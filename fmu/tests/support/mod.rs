//! A small importer for the tests: calls the library's exported fmi2* functions directly
//! (they are `extern "C"` functions of the rlib) with a logger that records every message.
#![allow(dead_code)]

use flyloop_fmu::exports::*;
use flyloop_fmu::fmi2_types::*;
use flyloop_fmu::models::tables;
use std::ffi::CString;

/// Which FMU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Model {
    Quadrotor,
    Lander2D,
    Hexacopter,
    RateController,
    AttitudeController,
}

impl Model {
    /// Every FMU the library serves.
    pub const ALL: [Model; 5] = [
        Model::Quadrotor,
        Model::Lander2D,
        Model::Hexacopter,
        Model::RateController,
        Model::AttitudeController,
    ];
    /// The plants (the FMUs with motor commands as inputs).
    pub const PLANTS: [Model; 3] = [Model::Quadrotor, Model::Lander2D, Model::Hexacopter];
    /// The multirotor FMUs (one model, two frames).
    pub const MULTIROTORS: [Model; 2] = [Model::Quadrotor, Model::Hexacopter];

    pub fn is_multirotor(self) -> bool {
        matches!(self, Model::Quadrotor | Model::Hexacopter)
    }

    pub fn table(self) -> &'static flyloop_fmu::table::ModelTable {
        match self {
            Model::Quadrotor => tables()[0],
            Model::Lander2D => tables()[1],
            Model::Hexacopter => tables()[2],
            Model::RateController => tables()[3],
            Model::AttitudeController => tables()[4],
        }
    }

    /// The value reference of variable `name`.
    pub fn vr(self, name: &str) -> u32 {
        self.table()
            .by_name(name)
            .unwrap_or_else(|| panic!("no variable {name}"))
            .value_reference
    }
}

pub mod importer_logger;

pub use importer_logger::{Entry, Recorder};

/// The recording logger as the variadic callback type.
pub fn recording_logger() -> fmi2CallbackLogger {
    importer_logger::variadic(importer_logger::record)
}

/// An instance with its recorder; freed on drop.
pub struct Fmu {
    pub c: fmi2Component,
    pub model: Model,
    pub recorder: Box<Recorder>,
    pub callbacks: Box<fmi2CallbackFunctions>,
}

pub fn callbacks_for(recorder: &Recorder) -> Box<fmi2CallbackFunctions> {
    Box::new(recorder.callbacks())
}

impl Fmu {
    /// Instantiates `model` with logging on.
    pub fn new(model: Model) -> Fmu {
        Fmu::named(model, "test", true)
    }

    pub fn named(model: Model, name: &str, logging_on: bool) -> Fmu {
        Fmu::of_type(model, name, logging_on, fmi2CoSimulation)
    }

    /// A Model Exchange instance of `model` with logging on.
    pub fn model_exchange(model: Model) -> Fmu {
        Fmu::of_type(model, "me", true, fmi2ModelExchange)
    }

    pub fn of_type(model: Model, name: &str, logging_on: bool, fmu_type: fmi2Type) -> Fmu {
        let recorder = Box::new(Recorder::default());
        let callbacks = callbacks_for(&recorder);
        let name = CString::new(name).unwrap();
        // SAFETY: valid strings and callbacks that outlive the instance (owned by Fmu).
        let c = unsafe {
            fmi2Instantiate(
                name.as_ptr(),
                fmu_type,
                model.table().guid.as_ptr(),
                std::ptr::null(),
                &*callbacks,
                fmi2False,
                if logging_on { fmi2True } else { fmi2False },
            )
        };
        assert!(!c.is_null(), "instantiate failed: {:?}", recorder.entries);
        Fmu {
            c,
            model,
            recorder,
            callbacks,
        }
    }

    /// Instantiated, set up at `start` (no stop time), initialised.
    pub fn started(model: Model, start: f64, values: &[(&str, f64)]) -> Fmu {
        let fmu = Fmu::new(model);
        assert_eq!(fmu.setup(start, None), fmi2Status::fmi2OK);
        assert_eq!(fmu.enter_init(), fmi2Status::fmi2OK);
        for &(name, value) in values {
            assert_eq!(fmu.set(name, value), fmi2Status::fmi2OK, "{name}");
        }
        assert_eq!(fmu.exit_init(), fmi2Status::fmi2OK);
        fmu
    }

    pub fn vr(&self, name: &str) -> u32 {
        self.model.vr(name)
    }

    pub fn setup(&self, start: f64, stop: Option<f64>) -> fmi2Status {
        // SAFETY: live instance.
        unsafe {
            fmi2SetupExperiment(
                self.c,
                fmi2False,
                0.0,
                start,
                i32::from(stop.is_some()),
                stop.unwrap_or(0.0),
            )
        }
    }

    pub fn enter_init(&self) -> fmi2Status {
        // SAFETY: live instance.
        unsafe { fmi2EnterInitializationMode(self.c) }
    }

    pub fn exit_init(&self) -> fmi2Status {
        // SAFETY: live instance.
        unsafe { fmi2ExitInitializationMode(self.c) }
    }

    pub fn do_step(&self, t: f64, h: f64) -> fmi2Status {
        // SAFETY: live instance.
        unsafe { fmi2DoStep(self.c, t, h, fmi2True) }
    }

    /// Sets variable `name` through the function of its type.
    pub fn set(&self, name: &str, value: f64) -> fmi2Status {
        let vr = [self.vr(name)];
        let kind = self.model.table().by_name(name).unwrap().kind;
        use flyloop_core::params::ValueKind;
        // SAFETY: one-element arrays.
        unsafe {
            match kind {
                ValueKind::Real => fmi2SetReal(self.c, vr.as_ptr(), 1, &value),
                ValueKind::Integer => fmi2SetInteger(self.c, vr.as_ptr(), 1, &(value as i32)),
                ValueKind::Boolean => fmi2SetBoolean(self.c, vr.as_ptr(), 1, &(value as i32)),
            }
        }
    }

    pub fn set_reals(&self, vrs: &[u32], values: &[f64]) -> fmi2Status {
        assert_eq!(vrs.len(), values.len());
        // SAFETY: arrays of the given length.
        unsafe { fmi2SetReal(self.c, vrs.as_ptr(), vrs.len(), values.as_ptr()) }
    }

    pub fn get_reals(&self, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
        let mut out = vec![f64::NAN; vrs.len()];
        // SAFETY: arrays of the given length.
        let status = unsafe { fmi2GetReal(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr()) };
        (status, out)
    }

    /// Reads variable `name` (any type) as f64; panics on a non-OK status.
    pub fn get(&self, name: &str) -> f64 {
        let vr = [self.vr(name)];
        let kind = self.model.table().by_name(name).unwrap().kind;
        use flyloop_core::params::ValueKind;
        let (status, value) = match kind {
            ValueKind::Real => {
                let (s, v) = self.get_reals(&vr);
                (s, v[0])
            }
            ValueKind::Integer | ValueKind::Boolean => {
                let mut out = -7i32;
                // SAFETY: one-element arrays.
                let s = unsafe {
                    if kind == ValueKind::Integer {
                        fmi2GetInteger(self.c, vr.as_ptr(), 1, &mut out)
                    } else {
                        fmi2GetBoolean(self.c, vr.as_ptr(), 1, &mut out)
                    }
                };
                (s, f64::from(out))
            }
        };
        assert_eq!(
            status,
            fmi2Status::fmi2OK,
            "get {name}: {:?}",
            self.messages()
        );
        value
    }

    /// Every output, as bits (for exact comparisons).
    pub fn output_bits(&self) -> Vec<u64> {
        use flyloop_core::variables::Causality;
        self.model
            .table()
            .variables
            .iter()
            .filter(|v| v.causality == Causality::Output)
            .map(|v| self.get(v.name).to_bits())
            .collect()
    }

    pub fn time(&self) -> f64 {
        let mut t = f64::NAN;
        // SAFETY: live instance, valid out pointer.
        let status = unsafe { fmi2GetRealStatus(self.c, fmi2LastSuccessfulTime, &mut t) };
        assert_eq!(status, fmi2Status::fmi2OK);
        t
    }

    pub fn entries(&self) -> Vec<Entry> {
        self.recorder.entries.lock().unwrap().clone()
    }

    pub fn messages(&self) -> Vec<String> {
        self.entries().into_iter().map(|e| e.message).collect()
    }

    /// The last message logged; panics if there is none.
    pub fn last_message(&self) -> String {
        self.messages().pop().expect("a log message")
    }

    pub fn clear_log(&self) {
        self.recorder.entries.lock().unwrap().clear();
    }

    pub fn get_state(&self) -> fmi2FMUstate {
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        // SAFETY: live instance, valid out pointer.
        let status = unsafe { fmi2GetFMUstate(self.c, &mut state) };
        assert_eq!(status, fmi2Status::fmi2OK, "{:?}", self.messages());
        state
    }

    pub fn set_state(&self, state: fmi2FMUstate) -> fmi2Status {
        // SAFETY: the FMU looks the pointer up before using it.
        unsafe { fmi2SetFMUstate(self.c, state) }
    }

    pub fn serialize(&self, state: fmi2FMUstate) -> Vec<u8> {
        let mut size = 0usize;
        // SAFETY: valid out pointer.
        let status = unsafe { fmi2SerializedFMUstateSize(self.c, state, &mut size) };
        assert_eq!(status, fmi2Status::fmi2OK);
        let mut bytes = vec![0u8; size];
        // SAFETY: buffer of `size` bytes.
        let status =
            unsafe { fmi2SerializeFMUstate(self.c, state, bytes.as_mut_ptr().cast(), size) };
        assert_eq!(status, fmi2Status::fmi2OK);
        bytes
    }

    pub fn deserialize(&self, bytes: &[u8], state: &mut fmi2FMUstate) -> fmi2Status {
        // SAFETY: buffer of bytes.len() bytes, valid state pointer.
        unsafe { fmi2DeSerializeFMUstate(self.c, bytes.as_ptr().cast(), bytes.len(), state) }
    }

    pub fn free_state(&self, state: &mut fmi2FMUstate) -> fmi2Status {
        // SAFETY: valid pointer to a state pointer.
        unsafe { fmi2FreeFMUstate(self.c, state) }
    }

    /// Asserts that no message was passed with a format other than "%s".
    pub fn assert_formats(&self) {
        assert!(self.recorder.bad_formats.lock().unwrap().is_empty());
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        self.assert_formats();
        // SAFETY: created by fmi2Instantiate, freed only here.
        unsafe { fmi2FreeInstance(self.c) };
    }
}
