//! Misuse as a user would commit it: unknown value references, wrong types, NaN and
//! out-of-range values, a wrong GUID, NULL callbacks and arguments, two instances side by
//! side. Each returns the documented status, logs why, and crashes nothing.
// Test code: a failed unwrap is a failed test.

use crate::support;

use flyloop_fmu::api::Api;
use flyloop_fmu::exports::*;
use flyloop_fmu::fmi2_types::*;
use std::ffi::CString;
use support::{Fmu, Model, Recorder, callbacks_for};

use fmi2Status::{fmi2Error, fmi2OK};

/// Instantiates with the given arguments; returns the component and the recorder's log.
fn instantiate(
    name: Option<&str>,
    fmu_type: fmi2Type,
    guid: Option<&str>,
    callbacks: Option<&fmi2CallbackFunctions>,
) -> fmi2Component {
    let name = name.map(|n| CString::new(n).unwrap());
    let guid = guid.map(|g| CString::new(g).unwrap());
    // SAFETY: NULL or valid strings and callbacks.
    unsafe {
        fmi2Instantiate(
            name.as_ref().map_or(std::ptr::null(), |n| n.as_ptr()),
            fmu_type,
            guid.as_ref().map_or(std::ptr::null(), |g| g.as_ptr()),
            std::ptr::null(),
            callbacks.map_or(std::ptr::null(), |c| c as *const _),
            fmi2False,
            fmi2True,
        )
    }
}

fn messages(recorder: &Recorder) -> Vec<String> {
    recorder
        .entries
        .lock()
        .unwrap()
        .iter()
        .map(|e| e.message.clone())
        .collect()
}

#[test]
fn a_wrong_guid_gives_null_and_says_which_guids_exist() {
    let recorder = Recorder::default();
    let callbacks = callbacks_for(&recorder);
    let c = instantiate(
        Some("q"),
        fmi2CoSimulation,
        Some("{not-a-guid}"),
        Some(&callbacks),
    );
    assert!(c.is_null());
    let log = messages(&recorder);
    assert_eq!(log.len(), 1);
    assert!(
        log[0].contains("GUID {not-a-guid} is not one of this library's models"),
        "{}",
        log[0]
    );
    assert!(
        log[0].contains(Model::Quadrotor.table().token(Api::Fmi2)) && log[0].contains("Lander2D")
    );
    let entry = recorder.entries.lock().unwrap()[0].clone();
    assert_eq!(
        (
            entry.status,
            entry.category.as_str(),
            entry.instance.as_str()
        ),
        (fmi2Error, "logStatusError", "q")
    );
}

#[test]
fn null_callbacks_a_null_logger_or_a_missing_name_give_null_without_a_crash() {
    let guid = Model::Lander2D.table().token(Api::Fmi2).to_string();
    assert!(instantiate(Some("a"), fmi2CoSimulation, Some(&guid), None).is_null());
    let no_logger = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    };
    assert!(instantiate(Some("a"), fmi2CoSimulation, Some(&guid), Some(&no_logger)).is_null());
    let recorder = Recorder::default();
    let callbacks = callbacks_for(&recorder);
    assert!(instantiate(None, fmi2CoSimulation, Some(&guid), Some(&callbacks)).is_null());
    assert!(instantiate(Some(""), fmi2CoSimulation, Some(&guid), Some(&callbacks)).is_null());
    assert!(instantiate(Some("a"), fmi2CoSimulation, None, Some(&callbacks)).is_null());
    assert!(instantiate(Some("a"), 7, Some(&guid), Some(&callbacks)).is_null());
    let log = messages(&recorder);
    assert_eq!(log.len(), 4, "{log:?}");
    assert!(log[0].contains("instanceName is NULL or empty"));
    assert!(log[1].contains("instanceName is NULL or empty"));
    assert!(log[2].contains("fmuGUID is NULL"));
    assert!(log[3].contains("fmuType 7 is neither Model Exchange (0) nor Co-Simulation (1)"));
    // The memory callbacks are not needed: NULL ones are fine.
    let c = instantiate(Some("a"), fmi2CoSimulation, Some(&guid), Some(&callbacks));
    assert!(!c.is_null());
    // SAFETY: created above.
    unsafe { fmi2FreeInstance(c) };
}

#[test]
fn unknown_value_references_are_refused_one_by_one_and_the_rest_still_works() {
    let fmu = Fmu::started(Model::Quadrotor, 0.0, &[("initial_z", 2.0)]);
    let z = fmu.vr("z");
    let (status, values) = fmu.get_reals(&[z, 99, 10_000, z]);
    assert_eq!(status, fmi2Error);
    assert_eq!(values[0], 2.0);
    assert!(
        values[1].is_nan() && values[2].is_nan(),
        "unknown ones are left alone"
    );
    assert_eq!(values[3], 2.0);
    let log = fmu.messages();
    assert!(
        log.iter()
            .any(|m| m == "fmi2GetReal: unknown value reference 99 (see modelDescription.xml)"),
        "{log:?}"
    );
    assert!(
        log.iter()
            .any(|m| m.contains("unknown value reference 10000"))
    );
    let m0 = fmu.vr("motor_command_0");
    assert_eq!(fmu.set_reals(&[m0, 4242], &[0.5, 1.0]), fmi2Error);
    assert_eq!(fmu.get("motor_command_0"), 0.5, "the known one took effect");
    assert!(fmu.last_message().contains("unknown value reference 4242"));
}

#[test]
fn a_function_of_the_wrong_type_names_the_right_one() {
    let fmu = Fmu::started(Model::Lander2D, 0.0, &[]);
    let mut out = 0;
    let landed = [fmu.vr("landed")];
    let x = [fmu.vr("x")];
    // SAFETY: one-element arrays.
    unsafe {
        assert_eq!(fmi2GetInteger(fmu.c, x.as_ptr(), 1, &mut out), fmi2Error);
        assert!(
            fmu.last_message()
                .contains("`x` (value reference 100) is of type Real, not Integer")
        );
        assert_eq!(fmi2GetBoolean(fmu.c, landed.as_ptr(), 1, &mut out), fmi2OK);
        assert_eq!(out, fmi2False);
        assert_eq!(fmi2GetReal(fmu.c, landed.as_ptr(), 1, &mut 0.0), fmi2Error);
        assert!(
            fmu.last_message()
                .contains("use fmi2GetBoolean/fmi2SetBoolean")
        );
        let mut s: fmi2String = std::ptr::null();
        assert_eq!(fmi2GetString(fmu.c, x.as_ptr(), 1, &mut s), fmi2Error);
        assert!(fmu.last_message().contains("not String"));
        let text = [c"hello".as_ptr()];
        assert_eq!(
            fmi2SetString(fmu.c, [7u32].as_ptr(), 1, text.as_ptr()),
            fmi2Error
        );
        assert!(fmu.last_message().contains("unknown value reference 7"));
        // No elements: nothing to do, whatever the pointers.
        assert_eq!(
            fmi2GetReal(fmu.c, std::ptr::null(), 0, std::ptr::null_mut()),
            fmi2OK
        );
    }
}

#[test]
fn null_arrays_with_elements_are_refused() {
    let fmu = Fmu::started(Model::Quadrotor, 0.0, &[]);
    // SAFETY: the FMU checks the pointers before reading.
    unsafe {
        assert_eq!(
            fmi2GetReal(fmu.c, std::ptr::null(), 2, [0.0; 2].as_mut_ptr()),
            fmi2Error
        );
        assert!(fmu.last_message().contains("`vr[]` is NULL"));
        assert_eq!(
            fmi2SetReal(fmu.c, [0u32].as_ptr(), 1, std::ptr::null()),
            fmi2Error
        );
        assert!(fmu.last_message().contains("`value[]` is NULL"));
        let mut state: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(fmi2GetFMUstate(fmu.c, std::ptr::null_mut()), fmi2Error);
        assert_eq!(
            fmi2DeSerializeFMUstate(fmu.c, std::ptr::null(), 10, &mut state),
            fmi2Error
        );
        assert!(fmu.last_message().contains("`serializedState` is NULL"));
        assert!(state.is_null());
    }
}

#[test]
fn nan_and_out_of_range_inputs_are_refused_and_the_previous_value_stays() {
    for model in Model::PLANTS {
        let input = if model.is_multirotor() {
            "motor_command_2"
        } else {
            "motor_command_left"
        };
        let fmu = Fmu::started(model, 0.0, &[]);
        assert_eq!(fmu.set(input, 0.25), fmi2OK);
        assert_eq!(fmu.set(input, f64::NAN), fmi2Error);
        let message = fmu.last_message();
        assert!(
            message.contains(&format!("`{input}` = NaN")) && message.contains("out of range"),
            "{message}"
        );
        assert_eq!(fmu.set(input, f64::INFINITY), fmi2Error);
        assert_eq!(fmu.set(input, 7.0), fmi2Error);
        assert_eq!(fmu.get(input), 0.25);
        assert_eq!(fmu.do_step(0.0, 0.1), fmi2OK, "{model:?} steps on");
        assert!(fmu.get("x").is_finite());
    }
}

#[test]
fn a_negative_mass_is_refused_naming_the_parameter_and_its_bound() {
    let fmu = Fmu::new(Model::Quadrotor);
    assert_eq!(fmu.set("mass", -1.0), fmi2Error);
    let message = fmu.last_message();
    assert!(
        message
            .contains("parameter `mass` = -1 kg is out of range: it must be in [0.001, 10000] kg"),
        "{message}"
    );
    let lander = Fmu::new(Model::Lander2D);
    assert_eq!(lander.set("drone_mass", -1.0), fmi2Error);
    assert!(lander.last_message().contains("`drone_mass` = -1 kg"));
    assert_eq!(lander.set("physics_step", 0.0), fmi2Error);
    assert!(
        lander
            .last_message()
            .contains("`physics_step` = 0 s is out of range: it must be in [0.0001, 1] s")
    );
    assert_eq!(lander.set("wind_speed", 101.0), fmi2Error);
    // Relations between parameters are checked too.
    assert_eq!(fmu.set("wind_speed_min", 8.0), fmi2Error);
    assert!(
        fmu.last_message()
            .contains("must not exceed wind_speed_max")
    );
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(fmu.get("mass"), 1.0, "the default stays");
}

#[test]
fn two_instances_side_by_side_do_not_share_anything() {
    let a = Fmu::named(Model::Quadrotor, "a", true);
    let b = Fmu::named(Model::Quadrotor, "b", true);
    let lander = Fmu::named(Model::Lander2D, "c", true);
    for fmu in [&a, &b, &lander] {
        assert_eq!(fmu.enter_init(), fmi2OK);
    }
    assert_eq!(a.set("motor_command_0", 0.9), fmi2OK);
    assert_eq!(b.set("initial_z", 5.0), fmi2OK);
    for fmu in [&a, &b, &lander] {
        assert_eq!(fmu.exit_init(), fmi2OK);
    }
    assert_eq!(a.do_step(0.0, 0.5), fmi2OK);
    assert_eq!(b.get("motor_command_0"), 0.0);
    assert_eq!(b.get("z"), 5.0);
    assert_eq!(b.time(), 0.0);
    assert_eq!(a.time(), 0.5);
    assert_eq!(lander.do_step(0.0, 0.04), fmi2OK);
    assert_eq!(a.do_step(0.0, 0.5), fmi2Error, "a is at 0.5");
    assert!(a.entries().iter().all(|e| e.instance == "a"));
    assert!(
        !b.messages().iter().any(|m| m.contains("fmi2DoStep")),
        "b's logger saw none of a's errors"
    );
    // A state of one instance means nothing to another.
    let state = a.get_state();
    assert_eq!(b.set_state(state), fmi2Error);
    assert!(
        b.last_message()
            .contains("not a live state of this instance")
    );
}

#[test]
fn a_quadrotor_state_does_not_restore_into_a_lander() {
    let quad = Fmu::started(Model::Quadrotor, 0.0, &[]);
    let lander = Fmu::started(Model::Lander2D, 0.0, &[]);
    let bytes = quad.serialize(quad.get_state());
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    assert_eq!(lander.deserialize(&bytes, &mut state), fmi2Error);
    assert!(state.is_null());
    assert!(
        lander
            .last_message()
            .contains("belongs to a model with GUID"),
        "{}",
        lander.last_message()
    ); // Nor into the hexacopter: the same model type, another FMU.
    let hexa = Fmu::started(Model::Hexacopter, 0.0, &[]);
    assert_eq!(hexa.deserialize(&bytes, &mut state), fmi2Error);
    assert!(hexa.last_message().contains("belongs to a model with GUID"));
}
