//! fmi2DoStep: the communication-point check, h <= 0, the stop time, the time grid
//! t0 + n·h, divergence; and that the FMU's outputs are exactly the core's state after the
//! same steps (bit for bit), for any communication step size.
// Test code: a failed unwrap is a failed test.

use crate::support;

use flyloop_core::lander2d::{Lander2d, Lander2dInitial, Lander2dParams};
use flyloop_core::quadrotor::{Frame, Quadrotor, QuadrotorInitial, QuadrotorParams};
use flyloop_core::variables::{Causality, Rows};
use flyloop_fmu::fmi2_types::fmi2Status::{fmi2Error, fmi2OK};
use support::{Fmu, Model};

fn output_vrs(model: Model) -> Vec<u32> {
    model
        .table()
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| v.value_reference)
        .collect()
}

#[test]
fn a_mismatched_communication_point_is_refused_and_changes_nothing() {
    let fmu = Fmu::started(Model::Quadrotor, 0.0, &[("initial_motor", 0.6)]);
    assert_eq!(fmu.do_step(0.0, 0.1), fmi2OK);
    let before = fmu.output_bits();
    assert_eq!(fmu.do_step(0.2, 0.1), fmi2Error);
    let message = fmu.last_message();
    assert!(
        message.contains("currentCommunicationPoint 0.2 does not match the instance's time 0.1"),
        "{message}"
    );
    assert_eq!(
        fmu.do_step(0.0, 0.1),
        fmi2Error,
        "no going back without an FMU state"
    );
    assert_eq!(fmu.output_bits(), before);
    assert_eq!(fmu.time(), 0.1);
    // Within the tolerance (an importer that sums its steps) is accepted.
    assert_eq!(fmu.do_step(0.1 + 1e-12, 0.1), fmi2OK);
}

#[test]
fn step_sizes_that_are_not_positive_finite_numbers_are_refused() {
    let fmu = Fmu::started(Model::Lander2D, 0.0, &[]);
    for h in [0.0, -0.01, f64::NAN, f64::INFINITY, -0.0] {
        assert_eq!(fmu.do_step(0.0, h), fmi2Error, "h = {h}");
        assert!(
            fmu.last_message()
                .contains("communicationStepSize must be a positive finite number")
        );
    }
    assert_eq!(fmu.do_step(f64::NAN, 0.1), fmi2Error);
    assert_eq!(fmu.time(), 0.0);
}

#[test]
fn steps_may_reach_the_stop_time_but_not_pass_it() {
    let fmu = Fmu::new(Model::Quadrotor);
    assert_eq!(fmu.setup(1.0, Some(1.3)), fmi2OK);
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(fmu.exit_init(), fmi2OK);
    assert_eq!(fmu.do_step(1.0, 0.25), fmi2OK);
    assert_eq!(fmu.do_step(1.25, 0.1), fmi2Error);
    assert!(
        fmu.last_message().contains("after the stop time 1.3"),
        "{}",
        fmu.last_message()
    );
    for n in 0..5 {
        assert_eq!(fmu.do_step(1.25 + f64::from(n) * 0.01, 0.01), fmi2OK);
    }
    assert_eq!(fmu.do_step(1.3, 0.01), fmi2Error);
    let bad = Fmu::new(Model::Quadrotor);
    assert_eq!(bad.setup(2.0, Some(1.0)), fmi2Error);
    assert!(
        bad.last_message()
            .contains("stopTime 1 must not be before startTime 2")
    );
}

#[test]
fn time_is_t0_plus_n_h_never_a_running_sum() {
    let fmu = Fmu::started(Model::Quadrotor, 0.5, &[]);
    let mut summed = 0.5;
    for n in 0..1000u32 {
        // The importer's own time, computed the same way.
        assert_eq!(fmu.do_step(0.5 + f64::from(n) * 0.001, 0.001), fmi2OK);
        summed += 0.001;
    }
    assert_eq!(fmu.time(), 0.5 + 1000.0 * 0.001);
    assert_ne!(summed, fmu.time(), "a running sum would have drifted");
    // An importer that sums is still within the tolerance.
    assert_eq!(fmu.do_step(summed, 0.001), fmi2OK);
}

#[test]
fn step_sizes_computed_as_differences_of_grid_times_give_the_clean_grids_outputs() {
    // fmpy and most importers pass h = t(n+1) - t(n), which jitters by ulps around 0.01;
    // jitter above 0.01 would double the RK4 substeps and change the trajectory.
    let clean = Fmu::started(
        Model::Quadrotor,
        0.0,
        &[("seed", 2.0), ("initial_motor", 0.5)],
    );
    let jittered = Fmu::started(
        Model::Quadrotor,
        0.0,
        &[("seed", 2.0), ("initial_motor", 0.5)],
    );
    let mut jitter_seen = false;
    for n in 0..300u32 {
        let (t, next) = (f64::from(n) * 0.01, f64::from(n + 1) * 0.01);
        jitter_seen |= next - t > 0.01;
        assert_eq!(clean.do_step(t, 0.01), fmi2OK);
        assert_eq!(jittered.do_step(t, next - t), fmi2OK);
    }
    assert!(
        jitter_seen,
        "the test needs steps longer than 0.01 by an ulp"
    );
    assert_eq!(jittered.output_bits(), clean.output_bits());
    assert_eq!(jittered.time(), 300.0 * 0.01);
}

/// Quadrotor.fmu is the core's quad X and Hexacopter.fmu the core's hexa X
/// (`Quadrotor::with_frame`): every output equal to the last bit after the same commands.
#[test]
fn multirotor_outputs_are_the_cores_after_the_same_steps_bit_for_bit() {
    for (model, frame) in [(Model::Quadrotor, "quad_x"), (Model::Hexacopter, "hexa_x")] {
        let seed = 5;
        let fmu = Fmu::started(
            model,
            0.0,
            &[("seed", f64::from(seed)), ("initial_motor", 0.5)],
        );
        let initial = QuadrotorInitial {
            seed,
            initial_motor: 0.5,
            ..Default::default()
        };
        let core = Quadrotor::from_initial(QuadrotorParams::default(), &initial).unwrap();
        let mut core = core.with_frame(Frame::named(frame).unwrap());
        let rows = Rows::of_model(&core);
        let vrs = output_vrs(model);
        let rotors = core.frame().rotor_count();
        let inputs: Vec<String> = (0..rotors).map(|i| format!("motor_command_{i}")).collect();
        let schedule = [
            (0.01, 0.5),
            (0.013, 0.52),
            (0.25, 0.55),
            (0.01, 0.4),
            (0.001, 0.6),
            (0.5, 0.49),
        ];
        let mut t = 0.0;
        for (round, &(h, command)) in schedule.iter().cycle().take(60).enumerate() {
            let skew = if round % 3 == 0 { 0.01 } else { 0.0 };
            // +skew, 0, -skew, 0, ...: a moment about some axis, the same total thrust.
            let commands: Vec<f64> = (0..rotors)
                .map(|i| command + [skew, 0.0, -skew, 0.0][i % 4])
                .collect();
            for (name, &c) in inputs.iter().zip(&commands) {
                assert_eq!(fmu.set(name, c), fmi2OK);
            }
            core.set_command(&commands).unwrap();
            assert_eq!(fmu.do_step(t, h), fmi2OK);
            core.step(h);
            t = fmu.time();
            let (status, values) = fmu.get_reals(&vrs);
            assert_eq!(status, fmi2OK);
            for (&vr, value) in vrs.iter().zip(values) {
                let expected = rows.get(&core, &initial, vr).unwrap();
                assert_eq!(
                    value.to_bits(),
                    expected.to_bits(),
                    "{model:?} vr {vr} at t = {t}"
                );
            }
        }
        // 25 body, wind and angular-acceleration outputs and one motor state per rotor.
        assert_eq!(vrs.len(), 25 + rotors, "{model:?}: every output compared");
        assert!(fmu.get("z") != 1.5, "the vehicle moved");
    }
}

#[test]
fn lander_steps_on_its_period_grid_match_the_core_bit_for_bit() {
    let seed = 11;
    // Start at 1.0: the grid is 1.0 + k·dt. Communication steps of 0.04 with dt = 0.02
    // are two whole periods each, the same physics steps as the core's own.
    let fmu = Fmu::started(Model::Lander2D, 1.0, &[("seed", f64::from(seed))]);
    let initial = Lander2dInitial {
        seed,
        ..Default::default()
    };
    let mut core = Lander2d::from_initial(Lander2dParams::default(), &initial).unwrap();
    for n in 0..30u32 {
        let command = [0.2 * f64::from(n % 5) - 0.4, 0.1];
        assert_eq!(fmu.set("motor_command_left", command[0]), fmi2OK);
        assert_eq!(fmu.set("motor_command_right", command[1]), fmi2OK);
        core.set_command(command).unwrap();
        assert_eq!(fmu.do_step(1.0 + f64::from(n) * 0.04, 0.04), fmi2OK);
        core.step();
        core.step();
        // Every output, Boolean flags included, through the function of its type.
        for variable in Model::Lander2D.table().variables.iter() {
            if variable.causality != Causality::Output {
                continue;
            }
            let vr = variable.value_reference;
            let expected = flyloop_core::variables::get(&core, &initial, vr).unwrap();
            let value = fmu.get(variable.name);
            assert_eq!(
                value.to_bits(),
                expected.to_bits(),
                "{} after step {n}",
                variable.name
            );
        }
    }
    assert_eq!(core.steps(), 60);
}

/// A lander in free fall (no wind, motors at -1 = no thrust, no noise) stepped at `h` for `steps` steps:
/// (t, y, vy) at every communication point.
fn lander_free_fall(h: f64, steps: u32) -> Vec<(f64, f64, f64)> {
    let fmu = Fmu::new(Model::Lander2D);
    for (name, value) in [
        ("wind_enabled", 0.0),
        ("thrust_noise_std", 0.0),
        ("initial_y", 30.0),
    ] {
        assert_eq!(fmu.set(name, value), fmi2OK, "{name}");
    }
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(fmu.exit_init(), fmi2OK);
    assert_eq!(fmu.set("motor_command_left", -1.0), fmi2OK);
    assert_eq!(fmu.set("motor_command_right", -1.0), fmi2OK);
    let mut out = vec![(0.0, fmu.get("y"), fmu.get("vy"))];
    for n in 0..steps {
        let t = f64::from(n) * h;
        assert_eq!(fmu.do_step(t, h), fmi2OK);
        out.push((t + h, fmu.get("y"), fmu.get("vy")));
    }
    out
}

#[test]
fn lander_outputs_at_points_off_its_period_grid_are_the_state_there() {
    let g = Lander2dParams::default().gravity;
    // h = 0.0123 s and 0.01 s against dt = 0.02 s: every output is the state at t, not
    // the one of the last period boundary.
    for h in [0.0123, 0.01] {
        let run = lander_free_fall(h, 40);
        for &(t, y, vy) in &run[1..] {
            // Semi-implicit Euler keeps v exact under constant gravity; y lags by at most
            // g·t·(longest physics step)/2.
            assert!((vy + g * t).abs() < 1e-9, "h = {h}, t = {t}: vy = {vy}");
            let exact = 30.0 - 0.5 * g * t * t;
            assert!(
                (y - exact).abs() <= 0.5 * g * t * 0.02 + 1e-9,
                "h = {h}, t = {t}: y = {y}, exact {exact}"
            );
        }
    }
    // At a point both grids share, the paths agree to the integrator's accuracy.
    let on_grid = lander_free_fall(0.02, 10);
    let off_grid = lander_free_fall(0.01, 20);
    assert!((on_grid[10].2 - off_grid[20].2).abs() < 1e-9, "vy at 0.2 s");
    assert!(
        (on_grid[10].1 - off_grid[20].1).abs() < 0.5 * g * 0.2 * 0.02,
        "y at 0.2 s"
    );
}

#[test]
fn a_step_that_would_run_for_hours_is_refused() {
    let fmu = Fmu::started(Model::Quadrotor, 0.0, &[]);
    assert_eq!(fmu.do_step(0.0, 1e7), fmi2Error);
    assert!(
        fmu.last_message().contains("internal steps (limit"),
        "{}",
        fmu.last_message()
    );
    assert_eq!(fmu.do_step(0.0, 1.0), fmi2OK);
}

#[test]
fn a_diverging_model_stops_in_the_error_stage_and_a_saved_state_brings_it_back() {
    // RK4 with a step 10^4 times the motor time constant is unstable: the motor states grow
    // without bound until they are no longer finite.
    let fmu = Fmu::new(Model::Quadrotor);
    for (name, value) in [
        ("motor_time_constant", 1e-4),
        ("max_substep", 1.0),
        // One substep per step even where a foot may touch the ground, so the first step
        // from the saved state is still finite (the divergence takes a few steps).
        ("contact_substep", 1.0),
        ("wind_enabled", 0.0),
    ] {
        assert_eq!(fmu.set(name, value), fmi2OK);
    }
    assert_eq!(fmu.enter_init(), fmi2OK);
    assert_eq!(fmu.exit_init(), fmi2OK);
    assert_eq!(fmu.set("motor_command_0", 1.0), fmi2OK);
    let state = fmu.get_state();
    let mut n = 0;
    while fmu.do_step(f64::from(n), 1.0) == fmi2OK {
        n += 1;
        assert!(n < 100, "never diverged");
    }
    let message = fmu.last_message();
    assert!(
        message.contains("became non-finite") && message.contains("Error stage"),
        "{message}"
    );
    assert_eq!(fmu.do_step(f64::from(n + 1), 1.0), fmi2Error);
    assert!(
        fmu.last_message()
            .contains("Illegal call sequence: the instance is in stage Error")
    );
    let (status, _) = fmu.get_reals(&[fmu.vr("motor_state_0")]);
    assert_eq!(status, fmi2OK, "outputs stay readable for diagnosis");
    assert_eq!(fmu.set_state(state), fmi2OK);
    assert_eq!(fmu.time(), 0.0);
    assert_eq!(
        fmu.do_step(0.0, 1.0),
        fmi2OK,
        "stepping again from the saved state"
    );
}
