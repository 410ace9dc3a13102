//! Model Exchange of Quadrotor.fmu through the exported functions: the state machine, the
//! derivatives bit for bit against the core, events, FMU states, and the misuse matrix.
// Test code: a failed unwrap is a failed test.

use crate::support;

use flyloop_core::quadrotor::dynamics::{derivative_vector, state_len};

/// The quad's continuous states: 13 rigid-body values, 4 motors, 8 bristles.
const STATE_LEN: usize = 25;
use flyloop_core::quadrotor::{Frame, Quadrotor, QuadrotorInitial, QuadrotorParams};
use flyloop_fmu::exports::*;
use flyloop_fmu::fmi2_types::fmi2Status::{fmi2Error, fmi2OK};
use flyloop_fmu::fmi2_types::*;
use support::{Fmu, Model};

fn event_info() -> fmi2EventInfo {
    fmi2EventInfo {
        newDiscreteStatesNeeded: fmi2True,
        terminateSimulation: fmi2True,
        nominalsOfContinuousStatesChanged: fmi2True,
        valuesOfContinuousStatesChanged: fmi2True,
        nextEventTimeDefined: fmi2False,
        nextEventTime: -1.0,
    }
}

/// A Model Exchange instance through initialisation and the first event, in continuous time.
fn running(values: &[(&str, f64)]) -> (Fmu, fmi2EventInfo) {
    running_model(Model::Quadrotor, values)
}

fn running_model(model: Model, values: &[(&str, f64)]) -> (Fmu, fmi2EventInfo) {
    let fmu = Fmu::model_exchange(model);
    assert_eq!(fmu.setup(0.0, None), fmi2OK);
    assert_eq!(fmu.enter_init(), fmi2OK);
    for &(name, value) in values {
        assert_eq!(fmu.set(name, value), fmi2OK, "{name}");
    }
    assert_eq!(fmu.exit_init(), fmi2OK);
    let mut info = event_info();
    // SAFETY: live instance, writable event info.
    unsafe {
        assert_eq!(fmi2NewDiscreteStates(fmu.c, &mut info), fmi2OK);
        assert_eq!(fmi2EnterContinuousTimeMode(fmu.c), fmi2OK);
    }
    (fmu, info)
}

/// The number of continuous states of `fmu`'s model.
fn state_len_of(fmu: &Fmu) -> usize {
    let me = fmu.model.table().model_exchange.as_ref();
    me.map_or(0, |me| me.states.len())
}

fn states(fmu: &Fmu) -> Vec<f64> {
    let mut x = vec![0.0; state_len_of(fmu)];
    // SAFETY: live instance, as many writable values as it has states.
    assert_eq!(
        unsafe { fmi2GetContinuousStates(fmu.c, x.as_mut_ptr(), x.len()) },
        fmi2OK
    );
    x
}

fn derivatives(fmu: &Fmu) -> Vec<f64> {
    let mut dx = vec![0.0; state_len_of(fmu)];
    // SAFETY: live instance, as many writable values as it has states.
    assert_eq!(
        unsafe { fmi2GetDerivatives(fmu.c, dx.as_mut_ptr(), dx.len()) },
        fmi2OK
    );
    dx
}

const FLYING: &[(&str, f64)] = &[
    ("initial_z", 2.0),
    ("initial_roll", 0.2),
    ("initial_vx", 0.5),
    ("initial_wy", -0.4),
    ("initial_motor", 0.5),
    ("motor_command_0", 0.6),
    ("motor_command_1", 0.45),
    ("wind_input_x", 1.5),
    ("seed", 11.0),
];

#[test]
fn derivatives_are_the_cores_right_hand_side_bit_for_bit() {
    let (fmu, info) = running(FLYING);
    // The turbulence grid is the only time event: the first sample at 0.01 s.
    assert_eq!(info.nextEventTimeDefined, fmi2True);
    assert_eq!(info.nextEventTime, 0.01);
    assert_eq!(info.newDiscreteStatesNeeded, fmi2False);
    let initial = QuadrotorInitial {
        initial_z: 2.0,
        initial_roll: 0.2,
        initial_vx: 0.5,
        initial_wy: -0.4,
        initial_motor: 0.5,
        seed: 11,
        ..Default::default()
    };
    let mut quad = Quadrotor::from_initial(QuadrotorParams::default(), &initial).unwrap();
    quad.set_command([0.6, 0.45, 0.5, 0.5]).unwrap();
    quad.external_wind.x = 1.5;
    assert_eq!(states(&fmu), quad.continuous_state().to_vec());
    // Any state the solver tries: the derivative is the core's, bit for bit.
    let mut x = quad.continuous_state();
    x[2] = 0.04; // feet in the ground: the contact forces count
    x[17] = 1e-4; // a stretched bristle
    x[4] = -0.3;
    // SAFETY: live instance, STATE_LEN readable values.
    unsafe {
        assert_eq!(fmi2SetTime(fmu.c, 0.004), fmi2OK);
        assert_eq!(fmi2SetContinuousStates(fmu.c, x.as_ptr(), x.len()), fmi2OK);
    }
    quad.set_continuous_state(&x).unwrap();
    assert_eq!(state_len(quad.frame().rotor_count()), STATE_LEN);
    let core = derivative_vector(
        &quad.params,
        quad.frame(),
        &quad.body,
        &quad.command(),
        &quad.surroundings(),
    );
    let fmu_dx = derivatives(&fmu);
    assert_eq!(
        fmu_dx.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        core.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    // The derivative variables read the same numbers; the foot heights are the indicators.
    assert_eq!(fmu.get("der(vz)"), core[5]);
    assert_eq!(fmu.get("gear_stretch_0_x"), 1e-4);
    let mut z = [0.0; 4];
    // SAFETY: live instance, 4 writable values.
    assert_eq!(
        unsafe { fmi2GetEventIndicators(fmu.c, z.as_mut_ptr(), 4) },
        fmi2OK
    );
    assert_eq!(z, quad.foot_heights());
    assert!(z.iter().any(|&h| h < 0.0), "{z:?}");
}

/// Hexacopter.fmu's Model Exchange is the core hexa's right-hand side: 27 states (six
/// motors), the derivative equal to the last bit in the air and with feet in the ground.
#[test]
fn hexacopter_derivatives_are_the_core_hexas_bit_for_bit() {
    let (fmu, _) = running_model(Model::Hexacopter, FLYING);
    let initial = QuadrotorInitial {
        initial_z: 2.0,
        initial_roll: 0.2,
        initial_vx: 0.5,
        initial_wy: -0.4,
        initial_motor: 0.5,
        seed: 11,
        ..Default::default()
    };
    let quad = Quadrotor::from_initial(QuadrotorParams::default(), &initial).unwrap();
    let mut quad = quad.with_frame(Frame::named("hexa_x").unwrap());
    quad.set_command([0.6, 0.45, 0.5, 0.5, 0.5, 0.5]).unwrap();
    quad.external_wind.x = 1.5;
    assert_eq!(states(&fmu), quad.continuous_state());
    assert_eq!(states(&fmu).len(), 27);
    let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    for z in [2.0, 0.04] {
        let mut x = quad.continuous_state();
        x[2] = z; // 0.04: feet in the ground, the contact forces count
        x[20] = 1e-4; // a stretched bristle (after the six motors)
        // SAFETY: live instance, 27 readable values.
        let status = unsafe { fmi2SetContinuousStates(fmu.c, x.as_ptr(), x.len()) };
        assert_eq!(status, fmi2OK);
        quad.set_continuous_state(&x).unwrap();
        assert_eq!(
            bits(&derivatives(&fmu)),
            bits(&quad.state_derivative()),
            "z = {z}"
        );
    }
    assert_eq!(fmu.get("der(motor_state_5)"), (0.5 - 0.5) / 0.08);
    assert_eq!(fmu.get("der(motor_state_0)"), (0.6 - 0.5) / 0.08);
}

#[test]
fn a_time_event_draws_the_turbulence_sample_the_stepper_draws() {
    let (fmu, _) = running(FLYING);
    let cs = Fmu::started(Model::Quadrotor, 0.0, FLYING);
    assert_eq!(cs.do_step(0.0, 0.01), fmi2OK);
    let mut info = event_info();
    // SAFETY: live instance, writable flags and event info.
    unsafe {
        let (mut enter, mut terminate) = (fmi2True, fmi2True);
        assert_eq!(fmi2SetTime(fmu.c, 0.01), fmi2OK);
        assert_eq!(
            fmi2CompletedIntegratorStep(fmu.c, fmi2True, &mut enter, &mut terminate),
            fmi2OK
        );
        assert_eq!((enter, terminate), (fmi2False, fmi2False));
        assert_eq!(fmi2EnterEventMode(fmu.c), fmi2OK);
        assert_eq!(fmi2NewDiscreteStates(fmu.c, &mut info), fmi2OK);
    }
    assert_eq!(info.nextEventTime, 0.02);
    for name in ["wind_x", "wind_y", "wind_z"] {
        assert_eq!(fmu.get(name), cs.get(name), "{name}");
    }
}

#[test]
fn fmu_states_round_trip_exactly_in_event_and_continuous_time_mode() {
    let (fmu, _) = running(FLYING);
    let mut x = states(&fmu);
    x[0] = 0.25;
    // SAFETY: live instance, STATE_LEN readable values.
    unsafe {
        assert_eq!(fmi2SetTime(fmu.c, 0.005), fmi2OK);
        assert_eq!(fmi2SetContinuousStates(fmu.c, x.as_ptr(), x.len()), fmi2OK);
    }
    let mut saved = fmu.get_state();
    let bytes = fmu.serialize(saved);
    let before = (states(&fmu), derivatives(&fmu));
    x[0] = 9.0;
    // SAFETY: as above.
    unsafe {
        assert_eq!(fmi2SetTime(fmu.c, 0.008), fmi2OK);
        assert_eq!(fmi2SetContinuousStates(fmu.c, x.as_ptr(), x.len()), fmi2OK);
        assert_eq!(fmi2EnterEventMode(fmu.c), fmi2OK);
    }
    assert_eq!(fmu.set_state(saved), fmi2OK);
    assert_eq!((states(&fmu), derivatives(&fmu)), before);
    // Back in continuous-time mode, where it was saved: states can be set again.
    // SAFETY: as above.
    assert_eq!(
        unsafe { fmi2SetContinuousStates(fmu.c, x.as_ptr(), x.len()) },
        fmi2OK
    );
    let mut copy = std::ptr::null_mut();
    assert_eq!(fmu.deserialize(&bytes, &mut copy), fmi2OK);
    assert_eq!(fmu.set_state(copy), fmi2OK);
    assert_eq!((states(&fmu), derivatives(&fmu)), before);
    assert_eq!(fmu.free_state(&mut copy), fmi2OK);
    assert_eq!(fmu.free_state(&mut saved), fmi2OK);
    // A Co-Simulation state does not fit a Model Exchange instance.
    let cs = Fmu::started(Model::Quadrotor, 0.0, &[]);
    let cs_bytes = cs.serialize(cs.get_state());
    let mut foreign = std::ptr::null_mut();
    assert_eq!(fmu.deserialize(&cs_bytes, &mut foreign), fmi2Error);
    assert!(
        fmu.last_message().contains("stage StepComplete"),
        "{}",
        fmu.last_message()
    );
}

#[test]
fn misuse_is_an_error_with_a_log_line_never_a_crash() {
    let (fmu, _) = running(FLYING);
    let x = states(&fmu);
    let mut buffer = vec![0.0; STATE_LEN];
    let mut flag = fmi2False;
    // SAFETY: live instance; NULL and short arrays are what is being refused.
    unsafe {
        // Wrong order: no discrete states in continuous time, no doStep in Model Exchange.
        assert_eq!(fmi2NewDiscreteStates(fmu.c, &mut event_info()), fmi2Error);
        assert!(fmu.last_message().contains("Illegal call sequence"));
        assert_eq!(fmi2DoStep(fmu.c, 0.0, 0.01, fmi2True), fmi2Error);
        assert!(fmu.last_message().contains("stage ContinuousTimeMode"));
        // Wrong lengths, NULL pointers.
        assert_eq!(fmi2GetDerivatives(fmu.c, buffer.as_mut_ptr(), 3), fmi2Error);
        assert_eq!(
            fmu.last_message(),
            "fmi2GetDerivatives: nx = 3, but Quadrotor has 25 continuous states"
        );
        assert_eq!(
            fmi2GetEventIndicators(fmu.c, buffer.as_mut_ptr(), 25),
            fmi2Error
        );
        assert!(fmu.last_message().contains("4 event indicators"));
        assert_eq!(
            fmi2GetDerivatives(fmu.c, std::ptr::null_mut(), 25),
            fmi2Error
        );
        assert!(fmu.last_message().contains("`derivatives` is NULL"));
        assert_eq!(
            fmi2CompletedIntegratorStep(fmu.c, fmi2True, std::ptr::null_mut(), &mut flag),
            fmi2Error
        );
        assert!(fmu.last_message().contains("`enterEventMode` is NULL"));
        // NaN: named, nothing changes.
        let mut bad = x.clone();
        bad[5] = f64::NAN;
        assert_eq!(fmi2SetContinuousStates(fmu.c, bad.as_ptr(), 25), fmi2Error);
        assert_eq!(
            fmu.last_message(),
            "fmi2SetContinuousStates: x[5] (state `vz`) is NaN, not a finite number; nothing was set"
        );
        assert_eq!(fmi2SetTime(fmu.c, f64::NAN), fmi2Error);
        assert!(fmu.last_message().contains("time NaN"));
        assert_eq!(fmi2SetTime(fmu.c, -1.0), fmi2Error);
        // Unknown references, outputs and locals are not settable.
        let (status, _) = fmu.get_reals(&[99_999]);
        assert_eq!(status, fmi2Error);
        assert_eq!(fmu.set("der(x)", 1.0), fmi2Error);
        // Bad state bytes.
        let mut state = std::ptr::null_mut();
        assert_eq!(fmu.deserialize(&[1, 2, 3], &mut state), fmi2Error);
        // NULL instance.
        assert_eq!(fmi2SetTime(std::ptr::null_mut(), 0.0), fmi2Error);
    }
    assert_eq!(states(&fmu), x, "nothing changed");
    // Model Exchange functions on a Co-Simulation instance (in a stage both share).
    let cs = Fmu::new(Model::Quadrotor);
    assert_eq!(cs.setup(0.0, None), fmi2OK);
    assert_eq!(cs.enter_init(), fmi2OK);
    // SAFETY: live instance, writable buffer.
    let status = unsafe { fmi2GetEventIndicators(cs.c, buffer.as_mut_ptr(), 4) };
    assert_eq!(status, fmi2Error);
    assert!(
        cs.last_message().contains("Co-Simulation instance"),
        "{}",
        cs.last_message()
    );
}

#[test]
fn lander2d_refuses_model_exchange_with_the_reason() {
    let recorder = Box::<support::Recorder>::default();
    let callbacks = support::callbacks_for(&recorder);
    // SAFETY: valid strings and callbacks.
    let c = unsafe {
        fmi2Instantiate(
            c"lander".as_ptr(),
            fmi2ModelExchange,
            Model::Lander2D.table().guid.as_ptr(),
            std::ptr::null(),
            &*callbacks,
            fmi2False,
            fmi2True,
        )
    };
    assert!(c.is_null());
    let entries = recorder.entries.lock().unwrap();
    assert!(
        entries[0]
            .message
            .contains("Lander2D is Co-Simulation only"),
        "{entries:?}"
    );
}
