//! FMI 3.0 through the C functions, as an importer calls them: Co-Simulation equal to FMI 2.0
//! bit for bit, Model Exchange equal to FMI 2.0's, FMU states that round-trip exactly, and
//! the misuse matrix (wrong call order, unknown references, wrong nValues, NaN, bad state
//! bytes, NULL pointers): an error status and a log line, never a crash.
// Test code: a failed unwrap is a failed test.

use crate::support;

use flyloop_core::variables::Causality;
use flyloop_fmu::api::Api;
use flyloop_fmu::exports::*;
use flyloop_fmu::fmi2_types::{fmi2LastSuccessfulTime, fmi2Status};
use flyloop_fmu::fmi3_types::fmi3Status::{fmi3Error, fmi3OK};
use flyloop_fmu::fmi3_types::*;
use flyloop_fmu::table::{EVENT_INDICATOR_VR, TIME_VR};
use std::ffi::CString;
use support::{Fmu, Model, Recorder};

/// One FMI 3.0 instance with its recorder.
struct Fmu3 {
    c: fmi3Instance,
    model: Model,
    recorder: Box<Recorder>,
}

impl Drop for Fmu3 {
    fn drop(&mut self) {
        // SAFETY: live instance, freed once.
        unsafe { fmi3FreeInstance(self.c) };
    }
}

fn instantiate(model: Model, model_exchange: bool, recorder: &Recorder) -> fmi3Instance {
    let (logger, env) = recorder.fmi3_logger();
    let name = CString::new("fmi3").unwrap();
    let token = model.table().token3.as_ptr();
    // SAFETY: valid strings and callbacks that outlive the instance.
    unsafe {
        if model_exchange {
            fmi3InstantiateModelExchange(
                name.as_ptr(),
                token,
                std::ptr::null(),
                fmi3False,
                fmi3True,
                env,
                Some(logger),
            )
        } else {
            fmi3InstantiateCoSimulation(
                name.as_ptr(),
                token,
                std::ptr::null(),
                fmi3False,
                fmi3True,
                fmi3False,
                fmi3False,
                std::ptr::null(),
                0,
                env,
                Some(logger),
                None,
            )
        }
    }
}

impl Fmu3 {
    fn new(model: Model, model_exchange: bool) -> Fmu3 {
        let recorder = Box::new(Recorder::default());
        let c = instantiate(model, model_exchange, &recorder);
        assert!(!c.is_null(), "{:?}", recorder.entries);
        Fmu3 { c, model, recorder }
    }

    /// Instantiated, configured by `configure` in initialization mode, out of it.
    fn started(model: Model, model_exchange: bool, configure: impl FnOnce(&Fmu3)) -> Fmu3 {
        let fmu = Fmu3::new(model, model_exchange);
        // SAFETY: live instance.
        unsafe {
            assert_eq!(
                fmi3EnterInitializationMode(fmu.c, fmi3False, 0.0, 0.0, fmi3False, 0.0),
                fmi3OK
            );
        }
        configure(&fmu);
        // SAFETY: live instance.
        assert_eq!(unsafe { fmi3ExitInitializationMode(fmu.c) }, fmi3OK);
        fmu
    }

    /// Sets seed (Int32) and the wind switch (Boolean) through their FMI 3.0 types.
    fn seed_and_wind(&self, seed: i32) {
        let (seed_vr, wind_vr) = (self.model.vr("seed"), self.model.vr("wind_enabled"));
        // SAFETY: one value each.
        unsafe {
            assert_eq!(fmi3SetInt32(self.c, &seed_vr, 1, &seed, 1), fmi3OK);
            assert_eq!(fmi3SetBoolean(self.c, &wind_vr, 1, &1u8, 1), fmi3OK);
        }
    }

    fn set(&self, vrs: &[u32], values: &[f64]) -> fmi3Status {
        // SAFETY: slices of the given lengths.
        unsafe {
            fmi3SetFloat64(
                self.c,
                vrs.as_ptr(),
                vrs.len(),
                values.as_ptr(),
                values.len(),
            )
        }
    }

    fn get(&self, vrs: &[u32], n: usize) -> (fmi3Status, Vec<f64>) {
        let mut out = vec![f64::NAN; n];
        // SAFETY: slices of the given lengths.
        let status =
            unsafe { fmi3GetFloat64(self.c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr(), n) };
        (status, out)
    }

    fn do_step(&self, t: f64, h: f64) -> fmi3Status {
        let (mut event, mut terminate, mut early, mut last) = (9u8, 9u8, 9u8, f64::NAN);
        // SAFETY: live instance, writable outputs.
        let status = unsafe {
            fmi3DoStep(
                self.c,
                t,
                h,
                fmi3True,
                &mut event,
                &mut terminate,
                &mut early,
                &mut last,
            )
        };
        if status == fmi3OK {
            assert_eq!((event, terminate, early), (0, 0, 0));
            assert!((last - (t + h)).abs() < 1e-12, "lastSuccessfulTime {last}");
        }
        status
    }

    fn messages(&self) -> Vec<String> {
        self.recorder
            .entries
            .lock()
            .unwrap()
            .iter()
            .map(|e| e.message.clone())
            .collect()
    }

    fn last_message(&self) -> String {
        self.recorder.last().map(|e| e.message).unwrap_or_default()
    }
}

/// The FMI 3.0 value references and lengths of every Float64 output of `model`.
fn fmi3_outputs(model: Model) -> Vec<(u32, usize)> {
    model
        .table()
        .fmi3
        .iter()
        .filter(|v| {
            v.causality == Causality::Output && v.kind == flyloop_core::params::ValueKind::Real
        })
        .map(|v| (v.value_reference, v.dimension.unwrap_or(1)))
        .collect()
}

/// The same outputs read through FMI 2.0, element by element.
fn fmi2_outputs(model: Model) -> Vec<u32> {
    let table = model.table();
    let mut vrs = Vec::new();
    for (vr, _) in fmi3_outputs(model) {
        if let flyloop_fmu::table::Source::Model(elements) = &table.variable3(vr).unwrap().source {
            let elements = &table.variables[elements.clone()];
            vrs.extend(elements.iter().map(|v| v.value_reference));
        }
    }
    vrs
}

#[test]
fn fmi3_co_simulation_equals_fmi2_bit_for_bit_with_wind_and_arrays() {
    for model in Model::ALL {
        // The controllers have no weather: their inputs are setpoints and the plant's outputs.
        let controller = matches!(model, Model::RateController | Model::AttitudeController);
        let weather: &[(&str, f64)] = if controller {
            &[]
        } else {
            &[("seed", 11.0), ("wind_enabled", 1.0)]
        };
        let fmu2 = Fmu::started(model, 0.0, weather);
        let fmu3 = Fmu3::started(model, false, |f| {
            if !controller {
                f.seed_and_wind(11)
            }
        });
        let inputs2: Vec<u32> = model
            .table()
            .variables
            .iter()
            .filter(|v| {
                let input = v.causality == flyloop_core::variables::Causality::Input;
                input && (controller || v.name.starts_with("motor_command"))
            })
            .map(|v| v.value_reference)
            .collect();
        // An array is named by its first element's value reference.
        let table = model.table();
        let inputs3: Vec<u32> = inputs2
            .iter()
            .copied()
            .filter(|&vr| table.variable3(vr).is_some())
            .collect();
        let outputs3 = fmi3_outputs(model);
        let outputs2 = fmi2_outputs(model);
        let n: usize = outputs3.iter().map(|&(_, n)| n).sum();
        assert_eq!(n, outputs2.len());
        let vrs3: Vec<u32> = outputs3.iter().map(|&(vr, _)| vr).collect();
        let mut t = 0.0;
        for k in 0..400 {
            // Varying commands and step sizes (0.01 then 0.0123: off the 0.02 s grid).
            let commands: Vec<f64> = (0..inputs2.len())
                .map(|i| 0.55 + 0.1 * ((k as f64) * 0.05 + i as f64).sin())
                .collect();
            assert_eq!(
                fmu2.set_reals(&inputs2, &commands),
                fmi2Status::fmi2OK,
                "{}",
                fmu2.last_message()
            );
            assert_eq!(fmu3.set(&inputs3, &commands), fmi3OK);
            let h = if k < 200 { 0.01 } else { 0.0123 };
            assert_eq!(fmu2.do_step(t, h), fmi2Status::fmi2OK);
            assert_eq!(fmu3.do_step(t, h), fmi3OK);
            t += h;
            let (status, got3) = fmu3.get(&vrs3, n);
            assert_eq!(status, fmi3OK);
            let (status, got2) = fmu2.get_reals(&outputs2);
            assert_eq!(status, fmi2Status::fmi2OK);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&got3), bits(&got2), "{model:?} step {k}");
            let mut time2 = f64::NAN;
            // SAFETY: live FMI 2.0 instance, writable output.
            unsafe { fmi2GetRealStatus(fmu2.c, fmi2LastSuccessfulTime, &mut time2) };
            assert_eq!(fmu3.get(&[TIME_VR], 1).1[0].to_bits(), time2.to_bits());
        }
    }
}

#[test]
fn fmi3_model_exchange_gives_the_fmi2_states_derivatives_and_indicators() {
    let model = Model::Quadrotor;
    let me2 = Fmu::model_exchange(model);
    assert_eq!(me2.setup(0.0, None), fmi2Status::fmi2OK);
    assert_eq!(me2.enter_init(), fmi2Status::fmi2OK);
    assert_eq!(me2.set("initial_z", 0.03), fmi2Status::fmi2OK);
    assert_eq!(me2.exit_init(), fmi2Status::fmi2OK);
    let me3 = Fmu3::started(model, true, |f| {
        assert_eq!(f.set(&[model.vr("initial_z")], &[0.03]), fmi3OK);
    });
    let (mut n_x, mut n_z) = (0usize, 0usize);
    // SAFETY: live instance, writable outputs.
    unsafe {
        assert_eq!(fmi3GetNumberOfContinuousStates(me3.c, &mut n_x), fmi3OK);
        assert_eq!(fmi3GetNumberOfEventIndicators(me3.c, &mut n_z), fmi3OK);
    }
    assert_eq!((n_x, n_z), (25, 4));
    let mut flags = [9u8; 5];
    let mut next = f64::NAN;
    // SAFETY: live instance, writable outputs.
    unsafe {
        let [a, b, c, d, e] = &mut flags;
        assert_eq!(
            fmi3UpdateDiscreteStates(me3.c, a, b, c, d, e, &mut next),
            fmi3OK
        );
        assert_eq!(fmi3EnterContinuousTimeMode(me3.c), fmi3OK);
    }
    assert_eq!(flags[..3], [0, 0, 0]);
    let mut info = std::mem::MaybeUninit::uninit();
    // SAFETY: live instance, writable output.
    unsafe {
        assert_eq!(
            fmi2NewDiscreteStates(me2.c, info.as_mut_ptr()),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi2EnterContinuousTimeMode(me2.c), fmi2Status::fmi2OK);
    }
    let mut x = vec![0.0; n_x];
    // SAFETY: live instance, n_x values.
    unsafe { assert_eq!(fmi3GetContinuousStates(me3.c, x.as_mut_ptr(), n_x), fmi3OK) };
    // A state in motion, tilted, with the feet near the ground.
    x[3] = 0.4;
    x[7] = 0.05;
    x[13] = 0.7;
    let (mut dx2, mut dx3) = (vec![0.0; n_x], vec![0.0; n_x]);
    let (mut z2, mut z3) = (vec![0.0; n_z], vec![0.0; n_z]);
    // SAFETY: live instances, arrays of the declared lengths.
    unsafe {
        assert_eq!(fmi2SetTime(me2.c, 0.25), fmi2Status::fmi2OK);
        assert_eq!(fmi3SetTime(me3.c, 0.25), fmi3OK);
        assert_eq!(
            fmi2SetContinuousStates(me2.c, x.as_ptr(), n_x),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi3SetContinuousStates(me3.c, x.as_ptr(), n_x), fmi3OK);
        assert_eq!(
            fmi2GetDerivatives(me2.c, dx2.as_mut_ptr(), n_x),
            fmi2Status::fmi2OK
        );
        assert_eq!(
            fmi3GetContinuousStateDerivatives(me3.c, dx3.as_mut_ptr(), n_x),
            fmi3OK
        );
        assert_eq!(
            fmi2GetEventIndicators(me2.c, z2.as_mut_ptr(), n_z),
            fmi2Status::fmi2OK
        );
        assert_eq!(fmi3GetEventIndicators(me3.c, z3.as_mut_ptr(), n_z), fmi3OK);
    }
    assert_eq!(dx2, dx3);
    assert_eq!(z2, z3);
    assert!(dx3.iter().any(|&d| d != 0.0));
    // The variables behind them: der(motor_state) as an array, the indicators, time.
    let der_motor = (model.table().fmi3.iter())
        .find(|v| v.name == "der(motor_state)")
        .unwrap();
    let (status, values) = me3.get(&[der_motor.value_reference], 4);
    assert_eq!(status, fmi3OK);
    assert_eq!(values, dx3[13..17]);
    let indicator_vrs: Vec<u32> = (EVENT_INDICATOR_VR..).take(n_z).collect();
    assert_eq!(me3.get(&indicator_vrs, n_z).1, z3);
    assert_eq!(me3.get(&[TIME_VR], 1).1, [0.25]);
    // An FMU state of the Model Exchange instance brings back states, time and stage exactly.
    let mut saved: fmi3FMUState = std::ptr::null_mut();
    let mut after = vec![0.0; n_x];
    // SAFETY: live instance, arrays of the declared lengths.
    unsafe {
        assert_eq!(fmi3GetFMUState(me3.c, &mut saved), fmi3OK);
        let moved: Vec<f64> = x.iter().map(|v| v + 0.125).collect();
        assert_eq!(fmi3SetTime(me3.c, 0.5), fmi3OK);
        assert_eq!(fmi3SetContinuousStates(me3.c, moved.as_ptr(), n_x), fmi3OK);
        assert_eq!(fmi3SetFMUState(me3.c, saved), fmi3OK);
        assert_eq!(
            fmi3GetContinuousStates(me3.c, after.as_mut_ptr(), n_x),
            fmi3OK
        );
        assert_eq!(fmi3FreeFMUState(me3.c, &mut saved), fmi3OK);
    }
    assert_eq!(after, x);
    assert_eq!(me3.get(&[TIME_VR], 1).1, [0.25]);
    let mut enter = 9u8;
    let mut terminate = 9u8;
    // SAFETY: live instance, writable outputs.
    unsafe {
        assert_eq!(
            fmi3CompletedIntegratorStep(me3.c, fmi3True, &mut enter, &mut terminate),
            fmi3OK
        );
        assert_eq!(fmi3EnterEventMode(me3.c), fmi3OK);
        assert_eq!(fmi3Terminate(me3.c), fmi3OK);
    }
    assert_eq!((enter, terminate), (0, 0));
}

/// Serialize a state, go on, deserialize and set it: the same outputs again, bit for bit.
#[test]
fn fmi3_states_round_trip_exactly_through_bytes() {
    let model = Model::Quadrotor;
    let fmu = Fmu3::started(model, false, |f| {
        f.seed_and_wind(3);
        assert_eq!(f.set(&[0], &[0.6; 4]), fmi3OK);
    });
    let outputs = fmi3_outputs(model);
    let vrs: Vec<u32> = outputs.iter().map(|o| o.0).collect();
    let n: usize = outputs.iter().map(|o| o.1).sum();
    let run = |from: f64| -> Vec<u64> {
        let mut seen = Vec::new();
        for k in 0..50 {
            let t = from + f64::from(k) * 0.01;
            assert_eq!(fmu.set(&[0], &[0.6 + 0.001 * f64::from(k); 4]), fmi3OK);
            assert_eq!(fmu.do_step(t, 0.01), fmi3OK);
            seen.extend(fmu.get(&vrs, n).1.iter().map(|x| x.to_bits()));
        }
        seen
    };
    run(0.0);
    let mut state: fmi3FMUState = std::ptr::null_mut();
    let mut size = 0usize;
    // SAFETY: live instance, writable outputs.
    unsafe {
        assert_eq!(fmi3GetFMUState(fmu.c, &mut state), fmi3OK);
        assert_eq!(fmi3SerializedFMUStateSize(fmu.c, state, &mut size), fmi3OK);
    }
    let mut bytes = vec![0u8; size];
    // SAFETY: `size` writable bytes.
    unsafe {
        assert_eq!(
            fmi3SerializeFMUState(fmu.c, state, bytes.as_mut_ptr(), size),
            fmi3OK
        );
        assert_eq!(fmi3FreeFMUState(fmu.c, &mut state), fmi3OK);
    }
    assert!(state.is_null());
    let first = run(0.5);
    let mut restored: fmi3FMUState = std::ptr::null_mut();
    // SAFETY: `size` readable bytes, writable output.
    unsafe {
        assert_eq!(
            fmi3DeserializeFMUState(fmu.c, bytes.as_ptr(), size, &mut restored),
            fmi3OK
        );
        assert_eq!(fmi3SetFMUState(fmu.c, restored), fmi3OK);
    }
    assert_eq!(run(0.5), first);
    // SAFETY: a state of this instance.
    unsafe { assert_eq!(fmi3FreeFMUState(fmu.c, &mut restored), fmi3OK) };
}

#[test]
fn instantiation_refusals_give_null_and_say_why() {
    let recorder = Recorder::default();
    let (logger, env) = recorder.fmi3_logger();
    let name = CString::new("x").unwrap();
    let lander = Model::Lander2D.table();
    // SAFETY: valid strings and callbacks.
    unsafe {
        // FMI 2.0's GUID is not an FMI 3.0 token.
        let wrong = fmi3InstantiateCoSimulation(
            name.as_ptr(),
            lander.guid.as_ptr(),
            std::ptr::null(),
            0,
            1,
            0,
            0,
            std::ptr::null(),
            0,
            env,
            Some(logger),
            None,
        );
        assert!(wrong.is_null());
        assert!(
            recorder
                .last()
                .unwrap()
                .message
                .contains("instantiationToken")
                && recorder
                    .last()
                    .unwrap()
                    .message
                    .contains(lander.token(Api::Fmi3)),
            "{:?}",
            recorder.last()
        );
        let me = fmi3InstantiateModelExchange(
            name.as_ptr(),
            lander.token3.as_ptr(),
            std::ptr::null(),
            0,
            1,
            env,
            Some(logger),
        );
        assert!(me.is_null());
        assert!(
            recorder
                .last()
                .unwrap()
                .message
                .contains("Co-Simulation only")
        );
        let event_mode = fmi3InstantiateCoSimulation(
            name.as_ptr(),
            lander.token3.as_ptr(),
            std::ptr::null(),
            0,
            1,
            1,
            0,
            std::ptr::null(),
            0,
            env,
            Some(logger),
            None,
        );
        assert!(event_mode.is_null());
        assert!(recorder.last().unwrap().message.contains("hasEventMode"));
        let scheduled = fmi3InstantiateScheduledExecution(
            name.as_ptr(),
            lander.token3.as_ptr(),
            std::ptr::null(),
            0,
            1,
            env,
            Some(logger),
            None,
            None,
            None,
        );
        assert!(scheduled.is_null());
        assert!(
            recorder
                .last()
                .unwrap()
                .message
                .contains("Scheduled Execution")
        );
        let no_name = fmi3InstantiateModelExchange(
            std::ptr::null(),
            Model::Quadrotor.table().token3.as_ptr(),
            std::ptr::null(),
            0,
            1,
            env,
            Some(logger),
        );
        assert!(no_name.is_null());
        // FMI 3.0 allows a NULL logger: the instance works and logs nothing.
        let quiet = fmi3InstantiateModelExchange(
            name.as_ptr(),
            Model::Quadrotor.table().token3.as_ptr(),
            std::ptr::null(),
            0,
            1,
            std::ptr::null_mut(),
            None,
        );
        assert!(!quiet.is_null());
        assert_eq!(
            fmi3DoStep(quiet, 0.0, 0.1, 0, &mut 0, &mut 0, &mut 0, &mut 0.0),
            fmi3Error
        );
        fmi3FreeInstance(quiet);
    }
    assert_eq!(recorder.entries.lock().unwrap().len(), 5);
}

#[test]
fn misuse_gives_an_error_and_a_log_line_and_loses_nothing() {
    let model = Model::Quadrotor;
    let fmu = Fmu3::new(model, false);
    // Wrong call order: a step before initialisation.
    assert_eq!(fmu.do_step(0.0, 0.01), fmi3Error);
    assert!(
        fmu.last_message().contains("Illegal call sequence"),
        "{}",
        fmu.last_message()
    );
    // SAFETY: live instance.
    unsafe {
        assert_eq!(
            fmi3EnterInitializationMode(fmu.c, 0, 0.0, 0.0, 0, 0.0),
            fmi3OK
        );
        assert_eq!(fmi3ExitInitializationMode(fmu.c), fmi3OK);
    }
    let command = [0.5, 0.6, 0.7, 0.8];
    assert_eq!(fmu.set(&[0], &command), fmi3OK);
    // Unknown value reference (element 1 of the array has none of its own): nothing is set.
    assert_eq!(fmu.set(&[0, 1], &[0.1, 0.1, 0.1, 0.1, 0.1]), fmi3Error);
    assert!(
        fmu.last_message().contains("unknown value reference 1"),
        "{}",
        fmu.last_message()
    );
    // nValues that does not fit the arrays.
    assert_eq!(fmu.set(&[0], &[0.1]), fmi3Error);
    assert!(
        fmu.last_message().contains("nValues is 1"),
        "{}",
        fmu.last_message()
    );
    let (status, _) = fmu.get(&[0], 3);
    assert_eq!(status, fmi3Error);
    // NaN and out-of-range elements are refused, naming the variable; the rest stays.
    assert_eq!(fmu.set(&[0], &[f64::NAN, 0.6, 0.7, 0.8]), fmi3Error);
    assert!(
        fmu.last_message().contains("motor_command_0"),
        "{}",
        fmu.last_message()
    );
    assert_eq!(fmu.get(&[0], 4), (fmi3OK, command.to_vec()));
    // A getter of the wrong type names the right one.
    let mut int = 0i32;
    let mut float = 0f32;
    // SAFETY: one value each.
    unsafe {
        assert_eq!(fmi3GetInt32(fmu.c, &100, 1, &mut int, 1), fmi3Error);
        assert!(
            fmu.last_message()
                .contains("use fmi3GetFloat64/fmi3SetFloat64")
        );
        assert_eq!(fmi3GetFloat32(fmu.c, &100, 1, &mut float, 1), fmi3Error);
        assert!(
            fmu.last_message().contains("not Float32"),
            "{}",
            fmu.last_message()
        );
    }
    // Outputs and time are not settable.
    assert_eq!(fmu.set(&[100], &[1.0]), fmi3Error);
    assert_eq!(fmu.set(&[TIME_VR], &[1.0]), fmi3Error);
    assert!(fmu.last_message().contains("independent variable"));
    // NULL arrays and output pointers.
    // SAFETY: NULL where the functions must refuse it.
    unsafe {
        assert_eq!(
            fmi3SetFloat64(fmu.c, std::ptr::null(), 1, command.as_ptr(), 4),
            fmi3Error
        );
        assert_eq!(
            fmi3DoStep(
                fmu.c,
                0.0,
                0.01,
                0,
                std::ptr::null_mut(),
                &mut 0,
                &mut 0,
                &mut 0.0
            ),
            fmi3Error
        );
        assert!(fmu.last_message().contains("eventHandlingNeeded"));
        assert_eq!(fmi3GetFMUState(fmu.c, std::ptr::null_mut()), fmi3Error);
        assert_eq!(
            fmi3SetFloat64(std::ptr::null_mut(), &0, 1, &0.5, 1),
            fmi3Error
        );
    }
    // Bad state bytes and a pointer this instance never handed out.
    let garbage = [7u8; 64];
    let mut state: fmi3FMUState = std::ptr::null_mut();
    // SAFETY: 64 readable bytes; a foreign pointer is looked up, not dereferenced.
    unsafe {
        assert_eq!(
            fmi3DeserializeFMUState(fmu.c, garbage.as_ptr(), garbage.len(), &mut state),
            fmi3Error
        );
        assert!(state.is_null());
        assert_eq!(
            fmi3SetFMUState(fmu.c, garbage.as_ptr() as fmi3FMUState),
            fmi3Error
        );
    }
    // Model Exchange on a Co-Simulation instance; what the FMU does not offer.
    // SAFETY: live instance.
    unsafe {
        assert_eq!(fmi3SetTime(fmu.c, 0.0), fmi3Error);
        assert_eq!(fmi3EnterEventMode(fmu.c), fmi3Error);
        assert_eq!(fmi3EnterConfigurationMode(fmu.c), fmi3Error);
        assert!(fmu.last_message().contains("structural parameters"));
        assert_eq!(fmi3GetClock(fmu.c, &0, 1, &mut 0), fmi3Error);
        assert!(fmu.last_message().contains("no clocks"));
    }
    // After all of it the instance steps as if nothing happened.
    assert_eq!(fmu.do_step(0.0, 0.01), fmi3OK);
    assert!(fmu.messages().iter().all(|m| !m.is_empty()));
}
