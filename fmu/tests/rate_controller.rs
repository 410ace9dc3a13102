//! RateController.fmu: wired by name to Quadrotor.fmu (the plant's `wx wy wz` in, its
//! `motor_command_i` out) and driven on the loop's 4 ms grid, the two FMUs fly exactly the
//! gym's rates interface (the core's `FlightVehicle` with `rates_action`) — every state bit
//! at every policy step. The controller's commands are direct feedthrough at a tick, its
//! grid is its own, and bad inputs are refused naming the input.
// Test code: a failed unwrap is a failed test.

use crate::support;

use flyloop_core::SimRng;
use flyloop_core::quadrotor::BodyState;
use flyloop_core::tasks::flight_vehicle::FlightVehicle;
use flyloop_core::tasks::randomization::{Randomization, VehicleParams};
use flyloop_core::vehicle::AirVehicle;
use flyloop_fmu::fmi2_types::fmi2Status::{fmi2Error, fmi2OK};
use nalgebra::Vector3;
use support::{Fmu, Model};

const TICK: f64 = 0.004;
const SETPOINT: [&str; 4] = ["thrust", "roll_rate", "pitch_rate", "yaw_rate"];
const RATES: [&str; 3] = ["wx", "wy", "wz"];
const MOTORS: [&str; 4] = [
    "motor_command_0",
    "motor_command_1",
    "motor_command_2",
    "motor_command_3",
];

/// A policy's action at step k: thrust near hover and rates that swing the vehicle around.
fn action(k: usize, hover: f64) -> [f64; 4] {
    let t = k as f64 * 0.02;
    [
        hover + 0.08 * (3.0 * t).sin(),
        0.8 * (2.0 * t).sin(),
        -0.6 * (1.3 * t).cos(),
        0.5 * (0.7 * t).sin(),
    ]
}

/// One communication step of the two FMUs as a master that respects direct feedthrough
/// does it: plant outputs to controller inputs, controller outputs to plant inputs, step.
fn co_step(plant: &Fmu, controller: &Fmu, setpoint: &[f64; 4], t: f64) {
    for (name, value) in SETPOINT.iter().zip(setpoint) {
        assert_eq!(controller.set(name, *value), fmi2OK);
    }
    for name in RATES {
        assert_eq!(controller.set(name, plant.get(name)), fmi2OK);
    }
    for name in MOTORS {
        assert_eq!(plant.set(name, controller.get(name)), fmi2OK);
    }
    assert_eq!(plant.do_step(t, TICK), fmi2OK);
    assert_eq!(controller.do_step(t, TICK), fmi2OK);
}

/// The gym's rates interface at 50 Hz policy steps (five ticks each), started at `start`.
fn gym(seed: u64) -> (FlightVehicle, f64) {
    let mut nominal = VehicleParams::default();
    nominal.flight.rates_action = true;
    // 50 Hz policy steps: five ticks each (the policies in policies/ act at 50 Hz).
    nominal.flight.dt = DT;
    let mut gym = FlightVehicle::new(nominal, Randomization::none()).unwrap();
    let hover = gym.draw(seed);
    let start = BodyState::at_rest(Vector3::new(0.5, -1.0, 1.5), 0.0, 0.0, 0.3, hover);
    gym.restart(start, SimRng::new(seed), seed);
    (gym, hover)
}

const DT: f64 = 0.02;
const TICKS_PER_STEP: usize = 5;
const POLICY_STEPS: usize = 400;

/// Position, velocity, attitude and body rates of a quadrotor.
fn state_bits(q: &dyn AirVehicle) -> Vec<u64> {
    let (b, att) = (q.body(), q.attitude());
    let values = [b.position, b.velocity, b.body_rates];
    let mut bits: Vec<u64> = values
        .iter()
        .flat_map(|v| v.iter().map(|x| x.to_bits()))
        .collect();
    bits.extend([att.w, att.i, att.j, att.k].map(f64::to_bits));
    bits
}

#[test]
fn rate_controller_fmu_flies_the_gym_rates_interface_bit_for_bit() {
    // The plant is the gym's own quadrotor, stepped from tick to tick as the gym steps it
    // (k·T − (k−1)·T); the rate loop is RateController.fmu's, wired by name.
    let seed = 7;
    let (mut gym, hover) = gym(seed);
    let mut plant = gym.air_vehicle().clone_boxed();
    let controller = Fmu::started(Model::RateController, 0.0, &[]);
    let mut moved = 0.0_f64;
    for k in 0..POLICY_STEPS {
        let a = action(k, hover);
        gym.apply(&a, DT).unwrap();
        for (name, value) in SETPOINT.iter().zip(&a) {
            assert_eq!(controller.set(name, *value), fmi2OK);
        }
        for j in 0..TICKS_PER_STEP {
            let tick = (k * TICKS_PER_STEP + j) as f64;
            for (i, name) in RATES.iter().enumerate() {
                assert_eq!(controller.set(name, plant.body().body_rates[i]), fmi2OK);
            }
            let motors = MOTORS.map(|m| controller.get(m));
            plant.set_actuators(&motors).unwrap();
            plant.advance((tick + 1.0) * TICK - tick * TICK);
            assert_eq!(controller.do_step(tick * TICK, TICK), fmi2OK);
        }
        assert_eq!(
            state_bits(plant.as_ref()),
            state_bits(gym.air_vehicle()),
            "policy step {k}"
        );
        moved = moved.max(plant.body().body_rates.norm());
    }
    assert!(moved > 0.3, "the swings turned the vehicle: {moved} rad/s");
}

#[test]
fn rate_controller_and_quadrotor_fmus_fly_the_gym_rates_interface_closely() {
    // Both FMUs on a 4 ms communication grid: the plant steps exactly 0.004 s where the gym
    // steps k·T − (k−1)·T (a few ulps apart), so the two flights part by rounding only.
    let seed = 7;
    let (mut gym, hover) = gym(seed);
    let plant = Fmu::started(
        Model::Quadrotor,
        0.0,
        &[
            ("seed", seed as f64),
            ("initial_x", 0.5),
            ("initial_y", -1.0),
            ("initial_z", 1.5),
            ("initial_yaw", 0.3),
            ("initial_motor", hover),
        ],
    );
    let controller = Fmu::started(Model::RateController, 0.0, &[]);
    let mut t = 0.0;
    let mut worst = 0.0_f64;
    for k in 0..POLICY_STEPS {
        let a = action(k, hover);
        gym.apply(&a, DT).unwrap();
        for _ in 0..TICKS_PER_STEP {
            co_step(&plant, &controller, &a, t);
            t = plant.time();
        }
        let b = gym.air_vehicle().body();
        let fmu = Vector3::new(plant.get("x"), plant.get("y"), plant.get("z"));
        worst = worst.max((fmu - b.position).norm());
    }
    assert!(worst < 1e-9, "largest position gap {worst:e} m");
    eprintln!("FMU pair vs gym over {POLICY_STEPS} policy steps: largest gap {worst:e} m");
}

#[test]
fn motor_commands_follow_the_inputs_at_a_tick_and_hold_between_ticks() {
    let controller = Fmu::started(Model::RateController, 0.0, &[("thrust", 0.5)]);
    let level: Vec<f64> = MOTORS.iter().map(|m| controller.get(m)).collect();
    assert!(level.iter().all(|&m| (m - 0.5).abs() < 1e-12), "{level:?}");
    // A roll rate asked at the tick moves the commands now (direct feedthrough).
    assert_eq!(controller.set("roll_rate", 1.0), fmi2OK);
    let rolling: Vec<f64> = MOTORS.iter().map(|m| controller.get(m)).collect();
    assert_ne!(rolling, level);
    // 0.006 s: one tick at 0 done, the next (0.004) inside the step, none at 0.006.
    assert_eq!(controller.do_step(0.0, 0.006), fmi2OK);
    let held: Vec<f64> = MOTORS.iter().map(|m| controller.get(m)).collect();
    assert_eq!(controller.set("roll_rate", -1.0), fmi2OK);
    let after: Vec<f64> = MOTORS.iter().map(|m| controller.get(m)).collect();
    assert_eq!(after, held, "no tick at 0.006: the commands hold");
}

#[test]
fn the_loop_keeps_its_own_grid_whatever_the_communication_step() {
    // 0.02 s steps and 0.004 s steps with the same held inputs: the same commands at 0.02 k.
    let run = |h: f64| {
        let c = Fmu::started(Model::RateController, 0.0, &[("thrust", 0.6), ("wx", 0.2)]);
        assert_eq!(c.set("pitch_rate", 0.7), fmi2OK);
        let mut out = Vec::new();
        let mut t = 0.0;
        for _ in 0..50 {
            let n = (0.02 / h).round() as usize;
            for _ in 0..n {
                assert_eq!(c.do_step(t, h), fmi2OK);
                t = c.time();
            }
            out.push(MOTORS.map(|m| c.get(m).to_bits()));
        }
        out
    };
    assert_eq!(run(0.004), run(0.02));
}

#[test]
fn bad_inputs_and_parameters_are_refused_naming_them() {
    let c = Fmu::started(Model::RateController, 0.0, &[]);
    assert_eq!(c.set("wx", f64::NAN), fmi2Error);
    assert!(
        c.last_message().contains("`wx` = NaN"),
        "{}",
        c.last_message()
    );
    assert_eq!(c.set("roll_rate", 1e6), fmi2Error);
    assert!(
        c.last_message().contains("`roll_rate`"),
        "{}",
        c.last_message()
    );
    let fresh = Fmu::new(Model::RateController);
    assert_eq!(fresh.set("MC_ROLLRATE_P", -1.0), fmi2Error);
    assert!(
        fresh.last_message().contains("`MC_ROLLRATE_P` = -1"),
        "{}",
        fresh.last_message()
    );
    assert_eq!(fresh.set("rate_loop_period", 0.0), fmi2Error);
    let message = fresh.last_message();
    assert!(message.contains("`rate_loop_period` = 0 s"), "{message}");
    // The core's name is not a variable: PX4's is.
    assert!(
        Model::RateController
            .table()
            .by_name("roll_rate_p")
            .is_none()
    );
    // Rotors that cannot make roll torque: the allocator's refusal names PX4's parameters,
    // and the last rotor keeps its value.
    for name in ["CA_ROTOR0_PY", "CA_ROTOR1_PY", "CA_ROTOR2_PY"] {
        assert_eq!(fresh.set(name, 0.0), fmi2OK, "{name}");
    }
    assert_eq!(fresh.set("CA_ROTOR3_PY", 0.0), fmi2Error);
    let message = fresh.last_message();
    assert!(message.contains("`CA_ROTOR0..3_PX/PY/KM`"), "{message}");
    assert_eq!(fresh.setup(0.0, None), fmi2OK);
    assert_eq!(fresh.enter_init(), fmi2OK);
    assert_eq!(fresh.get("CA_ROTOR3_PY"), 0.1875);
}

/// The PX4 parameter names, their none_iris defaults in PX4's units, and the core field
/// each one sets (rad/s for PX4's deg/s rates).
#[test]
fn parameters_carry_px4s_names_units_and_none_iris_defaults() {
    let c = Fmu::started(Model::RateController, 0.0, &[]);
    let defaults = [
        ("MC_ROLLRATE_P", 0.15),
        ("MC_ROLLRATE_I", 0.2),
        ("MC_ROLLRATE_D", 0.003),
        ("MC_ROLLRATE_K", 1.0),
        ("MC_RR_INT_LIM", 0.3),
        ("MC_PITCHRATE_P", 0.15),
        ("MC_YAWRATE_P", 0.2),
        ("MC_YAWRATE_I", 0.1),
        ("MC_ROLLRATE_MAX", 220.0),
        ("MC_YAWRATE_MAX", 200.0),
        ("IMU_GYRO_CUTOFF", 40.0),
        ("IMU_DGYRO_CUTOFF", 30.0),
        ("MC_YAW_TQ_CUTOFF", 2.0),
        ("THR_MDL_FAC", 0.0),
        ("CA_ROTOR0_PX", 0.1515),
        ("CA_ROTOR0_PY", 0.245),
        ("CA_ROTOR1_PY", -0.1875),
        ("CA_ROTOR3_PY", 0.1875),
        ("CA_ROTOR2_KM", -0.05),
        ("CA_ROTOR3_KM", -0.05),
        ("rate_loop_period", 0.004),
        ("output_quantum", 0.001),
    ];
    for (name, value) in defaults {
        assert!(
            (c.get(name) - value).abs() < 1e-12,
            "{name} = {}",
            c.get(name)
        );
    }
    // MC_ROLLRATE_MAX in deg/s clips the roll rate input in rad/s: 57.29578 deg/s = 1 rad/s.
    let clipped = Fmu::started(
        Model::RateController,
        0.0,
        &[("MC_ROLLRATE_MAX", 180.0 / std::f64::consts::PI)],
    );
    let one = Fmu::started(
        Model::RateController,
        0.0,
        &[("roll_rate", 1.0), ("thrust", 0.5)],
    );
    assert_eq!(clipped.set("thrust", 0.5), fmi2OK);
    assert_eq!(clipped.set("roll_rate", 3.0), fmi2OK);
    assert_eq!(MOTORS.map(|m| clipped.get(m)), MOTORS.map(|m| one.get(m)));
    // A wider front pair mixes roll with less on the front motors than none_iris.
    let wide = Fmu::started(
        Model::RateController,
        0.0,
        &[("CA_ROTOR0_PY", 0.4), ("CA_ROTOR2_PY", -0.4)],
    );
    assert_eq!(wide.set("thrust", 0.5), fmi2OK);
    assert_eq!(wide.set("roll_rate", 1.0), fmi2OK);
    assert_ne!(MOTORS.map(|m| wide.get(m)), MOTORS.map(|m| one.get(m)));
}
