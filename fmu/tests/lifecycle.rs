//! The state machine through the exported functions: the allowed sequence, illegal ones
//! ("Illegal call sequence" + fmi2Error, nothing changed), reset, terminate, logging.
// Test code: a failed unwrap is a failed test.

use crate::support;

use flyloop_fmu::exports::*;
use flyloop_fmu::fmi2_types::*;
use std::ffi::CStr;
use support::{Fmu, Model};

use fmi2Status::{fmi2Discard, fmi2Error, fmi2OK};

#[test]
fn version_and_platform_are_the_standards() {
    // SAFETY: static strings.
    unsafe {
        assert_eq!(CStr::from_ptr(fmi2GetVersion()).to_str().unwrap(), "2.0");
        assert_eq!(
            CStr::from_ptr(fmi2GetTypesPlatform()).to_str().unwrap(),
            "default"
        );
    }
}

#[test]
fn a_whole_run_follows_the_allowed_sequence_and_logs_its_events() {
    for model in Model::ALL {
        let fmu = Fmu::new(model);
        assert_eq!(fmu.setup(0.0, Some(1.0)), fmi2OK);
        assert_eq!(fmu.enter_init(), fmi2OK);
        assert_eq!(fmu.exit_init(), fmi2OK);
        for n in 0..50 {
            assert_eq!(fmu.do_step(f64::from(n) * 0.02, 0.02), fmi2OK);
        }
        assert_eq!(fmu.time(), 50.0 * 0.02);
        // SAFETY: live instance.
        assert_eq!(unsafe { fmi2Terminate(fmu.c) }, fmi2OK);
        let messages = fmu.messages();
        for expected in [
            "fmi2Instantiate",
            "fmi2SetupExperiment",
            "fmi2ExitInitializationMode",
            "fmi2Terminate",
        ] {
            assert!(
                messages.iter().any(|m| m.starts_with(expected)),
                "{expected} in {messages:?}"
            );
        }
        assert!(
            fmu.entries()
                .iter()
                .all(|e| e.instance == "test" && e.category == "logEvents")
        );
    }
}

#[test]
fn calls_out_of_sequence_are_refused_with_a_message_and_change_nothing() {
    let fmu = Fmu::new(Model::Quadrotor);
    // doStep before initialisation.
    assert_eq!(fmu.do_step(0.0, 0.01), fmi2Error);
    let message = fmu.last_message();
    assert!(
        message.starts_with("fmi2DoStep: Illegal call sequence"),
        "{message}"
    );
    assert!(
        message.contains("stage Instantiated") && message.contains("StepComplete"),
        "{message}"
    );
    // Outputs cannot be read before initialisation.
    let (status, values) = fmu.get_reals(&[fmu.vr("z")]);
    assert_eq!(status, fmi2Error);
    assert!(values[0].is_nan(), "nothing written");
    assert!(
        fmu.last_message()
            .starts_with("fmi2GetReal: Illegal call sequence")
    );
    // Exit before enter.
    assert_eq!(fmu.exit_init(), fmi2Error);
    // SAFETY: live instance.
    assert_eq!(unsafe { fmi2Terminate(fmu.c) }, fmi2Error);
    // The instance is still usable: the legal sequence works after all of it.
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(
        fmu.setup(0.0, None),
        fmi2Error,
        "setup only before initialisation"
    );
    assert_eq!(fmu.exit_init(), fmi2OK);
    assert_eq!(fmu.enter_init(), fmi2Error);
    assert_eq!(fmu.do_step(0.0, 0.01), fmi2OK);
    // SAFETY: live instance.
    assert_eq!(unsafe { fmi2Terminate(fmu.c) }, fmi2OK);
    assert_eq!(fmu.do_step(0.01, 0.01), fmi2Error);
    assert!(fmu.last_message().contains("stage Terminated"));
    // Values can still be read after termination.
    assert_eq!(fmu.get_reals(&[fmu.vr("z")]).0, fmi2OK);
}

#[test]
fn fixed_parameters_are_settable_until_initialisation_ends_inputs_always() {
    let fmu = Fmu::new(Model::Quadrotor);
    assert_eq!(fmu.set("mass", 1.2), fmi2OK);
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(fmu.set("initial_z", 3.0), fmi2OK);
    assert_eq!(
        fmu.get("z"),
        3.0,
        "initial values shape the outputs during initialisation"
    );
    assert_eq!(fmu.exit_init(), fmi2OK);
    assert_eq!(fmu.set("mass", 2.0), fmi2Error);
    let message = fmu.last_message();
    assert!(
        message.contains("`mass` cannot be set") && message.contains("fixed parameter"),
        "{message}"
    );
    assert_eq!(fmu.get("mass"), 1.2);
    assert_eq!(fmu.set("motor_command_0", 0.3), fmi2OK);
    assert_eq!(fmu.get("motor_command_0"), 0.3);
    assert_eq!(fmu.set("z", 1.0), fmi2Error);
    assert!(
        fmu.last_message()
            .contains("`z` cannot be set: it is an output")
    );
}

#[test]
fn inputs_set_before_initialisation_survive_later_start_values() {
    let fmu = Fmu::new(Model::Quadrotor);
    assert_eq!(fmu.set("motor_command_1", 0.8), fmi2OK);
    assert_eq!(fmu.set("initial_motor", 0.4), fmi2OK);
    assert_eq!(fmu.set("seed", 3.0), fmi2OK);
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(fmu.get("motor_command_1"), 0.8, "set explicitly");
    assert_eq!(fmu.get("motor_command_0"), 0.4, "follows initial_motor");
    assert_eq!(fmu.get("motor_state_2"), 0.4);
    assert_eq!(fmu.get("seed"), 3.0);
}

#[test]
fn reset_goes_back_to_the_start_values_from_any_stage() {
    for model in Model::PLANTS {
        let fresh = Fmu::started(model, 0.0, &[]);
        let start = fresh.output_bits();
        let fmu = Fmu::started(model, 0.0, &[("seed", 9.0), ("initial_x", 2.0)]);
        for n in 0..10 {
            assert_eq!(fmu.do_step(f64::from(n) * 0.1, 0.1), fmi2OK);
        }
        // SAFETY: live instance.
        assert_eq!(unsafe { fmi2Reset(fmu.c) }, fmi2OK);
        assert_eq!(fmu.do_step(1.0, 0.1), fmi2Error, "back in Instantiated");
        assert_eq!(fmu.enter_init(), fmi2OK);
        assert_eq!(fmu.exit_init(), fmi2OK);
        assert_eq!(fmu.time(), 0.0);
        assert_eq!(fmu.get("seed"), 0.0);
        assert_eq!(
            fmu.output_bits(),
            start,
            "{model:?}: outputs of a fresh instance"
        );
    }
}

#[test]
fn status_queries_answer_what_applies() {
    let fmu = Fmu::started(Model::Lander2D, 2.0, &[]);
    assert_eq!(fmu.do_step(2.0, 0.5), fmi2OK);
    assert_eq!(fmu.time(), 2.5);
    let mut terminated = 7;
    // SAFETY: live instance and valid out pointers.
    unsafe {
        assert_eq!(
            fmi2GetBooleanStatus(fmu.c, fmi2Terminated, &mut terminated),
            fmi2OK
        );
        assert_eq!(terminated, fmi2False);
        let mut status = fmi2OK;
        assert_eq!(
            fmi2GetStatus(fmu.c, fmi2DoStepStatus, &mut status),
            fmi2Discard
        );
        assert!(fmu.last_message().contains("never returns fmi2Pending"));
        assert_eq!(fmi2GetRealStatus(fmu.c, 42, &mut 0.0), fmi2Error);
        assert!(fmu.last_message().contains("unknown fmi2StatusKind 42"));
        assert_eq!(
            fmi2GetRealStatus(fmu.c, fmi2LastSuccessfulTime, std::ptr::null_mut()),
            fmi2Error
        );
        assert!(fmu.last_message().contains("`value` is NULL"));
        assert_eq!(fmi2CancelStep(fmu.c), fmi2Error);
        assert!(
            fmu.last_message()
                .starts_with("fmi2CancelStep: Illegal call sequence")
        );
    }
}

#[test]
fn undeclared_capabilities_and_model_exchange_calls_answer_error_with_the_reason() {
    let fmu = Fmu::started(Model::Quadrotor, 0.0, &[]);
    let vr = [0u32];
    let order = [1];
    let mut value = [0.0];
    // SAFETY: live instance, valid one-element arrays.
    unsafe {
        assert_eq!(
            fmi2SetRealInputDerivatives(fmu.c, vr.as_ptr(), 1, order.as_ptr(), value.as_ptr()),
            fmi2Error
        );
        assert!(fmu.last_message().contains("canInterpolateInputs"));
        assert_eq!(
            fmi2GetRealOutputDerivatives(fmu.c, vr.as_ptr(), 1, order.as_ptr(), value.as_mut_ptr()),
            fmi2Error
        );
        assert!(fmu.last_message().contains("maxOutputDerivativeOrder"));
        let dv = [1.0];
        assert_eq!(
            fmi2GetDirectionalDerivative(
                fmu.c,
                vr.as_ptr(),
                1,
                vr.as_ptr(),
                1,
                dv.as_ptr(),
                value.as_mut_ptr()
            ),
            fmi2Error
        );
        assert!(fmu.last_message().contains("providesDirectionalDerivative"));
        // Model Exchange functions on a Co-Simulation instance: not in its stages.
        assert_eq!(fmi2EnterEventMode(fmu.c), fmi2Error);
        assert!(fmu.last_message().contains("Illegal call sequence"));
        assert_eq!(fmi2SetTime(fmu.c, 1.0), fmi2Error);
        assert_eq!(fmi2GetDerivatives(fmu.c, value.as_mut_ptr(), 1), fmi2Error);
    }
    assert_eq!(fmu.do_step(0.0, 0.01), fmi2OK, "still usable");
}

#[test]
fn debug_logging_switches_the_categories_it_names() {
    let fmu = Fmu::named(Model::Quadrotor, "quiet", false);
    assert!(fmu.messages().is_empty(), "loggingOn=false: no events");
    assert_eq!(fmu.do_step(0.0, 0.01), fmi2Error);
    assert_eq!(
        fmu.messages().len(),
        1,
        "errors are logged even with loggingOn=false"
    );
    let error_only = [c"logStatusError".as_ptr()];
    // SAFETY: live instance, valid category arrays.
    unsafe {
        assert_eq!(
            fmi2SetDebugLogging(fmu.c, fmi2False, 1, error_only.as_ptr()),
            fmi2OK
        );
        fmu.clear_log();
        assert_eq!(fmu.do_step(0.0, 0.01), fmi2Error);
        assert!(fmu.messages().is_empty(), "logStatusError switched off");
        assert_eq!(
            fmi2SetDebugLogging(fmu.c, fmi2True, 0, std::ptr::null()),
            fmi2OK
        );
        assert_eq!(fmu.enter_init(), fmi2OK);
        assert_eq!(
            fmu.messages(),
            ["fmi2EnterInitializationMode"],
            "all categories on"
        );
        let unknown = [c"logEverything".as_ptr(), c"logEvents".as_ptr()];
        assert_eq!(
            fmi2SetDebugLogging(fmu.c, fmi2False, 2, unknown.as_ptr()),
            fmi2Error
        );
        assert!(
            fmu.last_message()
                .contains("unknown log category `logEverything`")
        );
        fmu.clear_log();
        assert_eq!(fmu.exit_init(), fmi2OK);
        assert!(
            fmu.messages().is_empty(),
            "logEvents was switched off despite the unknown name"
        );
        assert_eq!(
            fmi2SetDebugLogging(fmu.c, fmi2True, 3, std::ptr::null()),
            fmi2Error
        );
        assert!(fmu.last_message().contains("`categories[]` is NULL"));
    }
    let entries = fmu.entries();
    assert!(entries.iter().all(|e| e.instance == "quiet"));
}

#[test]
fn free_instance_ignores_null_and_works_in_every_stage() {
    // SAFETY: NULL is explicitly allowed.
    unsafe { fmi2FreeInstance(std::ptr::null_mut()) };
    // SAFETY: NULL instance: refused without a crash.
    assert_eq!(
        unsafe { fmi2DoStep(std::ptr::null_mut(), 0.0, 0.1, 0) },
        fmi2Error
    );
    let fmu = Fmu::started(Model::Lander2D, 0.0, &[]);
    let _state = fmu.get_state();
    // The instance frees the state it still holds along with itself.
    drop(fmu);
}
