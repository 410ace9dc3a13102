//! FMU states: get at t1, run to t2, set, run to t2 again: the same outputs bit for bit (RNG
//! and rapier world included); the same through serialize/deserialize, also into another
//! instance; garbage, truncated and damaged bytes are refused; double free is refused.
// Test code: a failed unwrap is a failed test.

use crate::support;

use flyloop_fmu::fmi2_types::fmi2FMUstate;
use flyloop_fmu::fmi2_types::fmi2Status::{fmi2Error, fmi2OK};
use support::{Fmu, Model};

/// Steps from t to `end` in steps of h with a command that changes every step.
fn run(fmu: &Fmu, t: &mut f64, end: f64, h: f64) -> Vec<Vec<u64>> {
    let input = match fmu.model {
        Model::Quadrotor | Model::Hexacopter => "motor_command_1",
        Model::Lander2D => "motor_command_right",
        Model::RateController => "roll_rate",
        Model::AttitudeController => "roll",
    };
    let mut outputs = Vec::new();
    while *t < end - 1e-9 {
        let command = 0.5 + 0.3 * (*t * 7.0).sin();
        assert_eq!(fmu.set(input, command), fmi2OK);
        assert_eq!(fmu.do_step(*t, h), fmi2OK);
        *t = fmu.time();
        outputs.push(fmu.output_bits());
    }
    outputs
}

fn started(model: Model) -> Fmu {
    // Wind and noise on (the defaults), a seed, and a moving platform for the lander: every
    // random draw and every rapier body is part of the state.
    let fmu = Fmu::new(model);
    match model {
        Model::Lander2D => {
            assert_eq!(fmu.set("seed", 21.0), fmi2OK);
            assert_eq!(fmu.set("moving_platform", 1.0), fmi2OK);
        }
        Model::RateController => {
            // A thrust the allocator passes on; the roll rate setpoint moves the motors.
            assert_eq!(fmu.set("thrust", 0.6), fmi2OK);
            assert_eq!(fmu.set("wx", 0.3), fmi2OK);
        }
        Model::AttitudeController => {
            // The time is its state: a yaw step inside the run changes the yaw rate.
            assert_eq!(fmu.set("step_time", 1.2), fmi2OK);
            assert_eq!(fmu.set("target_yaw", 0.5), fmi2OK);
        }
        _ => {
            assert_eq!(fmu.set("seed", 21.0), fmi2OK);
            assert_eq!(fmu.set("initial_motor", 0.5), fmi2OK);
        }
    }
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(fmu.exit_init(), fmi2OK);
    fmu
}

#[test]
fn get_run_set_rerun_repeats_every_output_bit_for_bit() {
    for model in Model::ALL {
        let fmu = started(model);
        let mut t = 0.0;
        run(&fmu, &mut t, 1.0, 0.02);
        let state = fmu.get_state();
        let first = run(&fmu, &mut t, 3.0, 0.02);
        assert_eq!(fmu.set_state(state), fmi2OK);
        assert_eq!(fmu.time(), 1.0);
        let mut t = 1.0;
        let second = run(&fmu, &mut t, 3.0, 0.02);
        assert_eq!(first.len(), 100);
        assert_eq!(first, second, "{model:?}");
        assert_ne!(first[0], first[99], "{model:?} moved");
    }
}

#[test]
fn serialize_and_deserialize_repeat_the_run_here_and_in_a_second_instance() {
    for model in Model::ALL {
        let fmu = started(model);
        let mut t = 0.0;
        run(&fmu, &mut t, 0.6, 0.03);
        let state = fmu.get_state();
        let bytes = fmu.serialize(state);
        let first = run(&fmu, &mut t, 1.5, 0.03);

        let mut restored: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(fmu.deserialize(&bytes, &mut restored), fmi2OK);
        assert_eq!(fmu.set_state(restored), fmi2OK);
        let mut t = 0.6;
        assert_eq!(
            run(&fmu, &mut t, 1.5, 0.03),
            first,
            "{model:?} same instance"
        );

        let other = Fmu::new(model);
        let mut foreign: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(other.deserialize(&bytes, &mut foreign), fmi2OK);
        assert_eq!(
            other.set_state(foreign),
            fmi2OK,
            "stage StepComplete comes with it"
        );
        let mut t = 0.6;
        assert_eq!(
            run(&other, &mut t, 1.5, 0.03),
            first,
            "{model:?} other instance"
        );
        assert_eq!(
            other.serialize(foreign),
            bytes,
            "the bytes survive unchanged"
        );
    }
}

#[test]
fn get_fmu_state_overwrites_a_state_it_is_given_back() {
    let fmu = started(Model::Quadrotor);
    let mut state = fmu.get_state();
    let at_start = fmu.serialize(state);
    assert_eq!(fmu.do_step(0.0, 0.5), fmi2OK);
    // SAFETY: valid pointer to a live state of this instance.
    let status = unsafe { flyloop_fmu::exports::fmi2GetFMUstate(fmu.c, &mut state) };
    assert_eq!(status, fmi2OK);
    assert_ne!(fmu.serialize(state), at_start);
    assert_eq!(fmu.do_step(0.5, 0.5), fmi2OK);
    assert_eq!(fmu.set_state(state), fmi2OK);
    assert_eq!(fmu.time(), 0.5);
}

#[test]
fn garbage_truncated_and_damaged_bytes_are_refused_and_change_nothing() {
    let fmu = started(Model::Lander2D);
    let good = fmu.serialize(fmu.get_state());
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    let mut damaged = good.clone();
    let middle = damaged.len() / 2;
    damaged[middle] ^= 0x10;
    let cases: [(&[u8], &str); 5] = [
        (b"definitely not an FMU state", "not a flyloop FMU state"),
        (&[], "not a flyloop FMU state"),
        (&good[..good.len() - 3], "announces"),
        (&damaged, "checksum"),
        (&[0u8; 64], "not a flyloop FMU state"),
    ];
    for (bytes, expected) in cases {
        assert_eq!(fmu.deserialize(bytes, &mut state), fmi2Error);
        let message = fmu.last_message();
        assert!(
            message.starts_with("fmi2DeSerializeFMUstate: FMU state refused"),
            "{message}"
        );
        assert!(message.contains(expected), "{expected}: {message}");
        assert!(state.is_null(), "no state was made");
    }
    // A live state given as target is left as it was.
    let mut live = fmu.get_state();
    let before = fmu.serialize(live);
    assert_eq!(fmu.deserialize(b"junk", &mut live), fmi2Error);
    assert_eq!(fmu.serialize(live), before);
    // Serializing into a buffer of the wrong size is refused too.
    let mut small = vec![0u8; 10];
    // SAFETY: buffer of 10 bytes, declared as 10.
    let status = unsafe {
        flyloop_fmu::exports::fmi2SerializeFMUstate(fmu.c, live, small.as_mut_ptr().cast(), 10)
    };
    assert_eq!(status, fmi2Error);
    assert!(
        fmu.last_message()
            .contains("ask fmi2SerializedFMUstateSize")
    );
}

#[test]
fn a_second_free_of_the_same_state_is_refused() {
    let fmu = started(Model::Quadrotor);
    let mut state = fmu.get_state();
    let copy = state;
    assert_eq!(fmu.free_state(&mut state), fmi2OK);
    assert!(state.is_null(), "the FMU clears the caller's pointer");
    assert_eq!(
        fmu.free_state(&mut state),
        fmi2OK,
        "NULL is ignored, as the standard says"
    );
    let mut stale = copy;
    assert_eq!(fmu.free_state(&mut stale), fmi2Error);
    assert!(
        fmu.last_message()
            .contains("not a live state of this instance")
    );
    assert_eq!(
        fmu.set_state(copy),
        fmi2Error,
        "a freed state cannot be set either"
    );
    let mut size = 0;
    // SAFETY: the pointer is looked up, never dereferenced.
    let status =
        unsafe { flyloop_fmu::exports::fmi2SerializedFMUstateSize(fmu.c, copy, &mut size) };
    assert_eq!(status, fmi2Error);
    assert_eq!(fmu.do_step(0.0, 0.01), fmi2OK, "still usable");
}

#[test]
fn a_state_saved_before_initialisation_brings_its_stage_back() {
    let fmu = Fmu::new(Model::Quadrotor);
    assert_eq!(fmu.set("initial_z", 4.0), fmi2OK);
    let state = fmu.get_state();
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(fmu.exit_init(), fmi2OK);
    assert_eq!(fmu.do_step(0.0, 1.0), fmi2OK);
    assert_eq!(fmu.set_state(state), fmi2OK);
    assert_eq!(fmu.do_step(0.0, 1.0), fmi2Error, "Instantiated again");
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(fmu.get("z"), 4.0);
}
