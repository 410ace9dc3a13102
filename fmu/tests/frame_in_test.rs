//! Issue 33's proof on the FMU side: a frame defined in this test only (five rotors) gets an
//! FMU table — inputs, outputs, Model Exchange states, FMI 3.0 arrays, GUID — from its rotor
//! table, and the model-independent engine behind every instance flies it: it hovers at the
//! analytic motor state √(m g / Σk), yaws the way its odd spin count says and lifts at
//! Σk/m − g at full command.

use flyloop_core::quadrotor::{Frame, FrameTable, Quadrotor, Rotor, Spin};
use flyloop_fmu::api::Api;
use flyloop_fmu::engine::{Engine, Simulation};
use flyloop_fmu::model::Table;
use flyloop_fmu::model_description::generate;
use flyloop_fmu::models::{Multirotor, tables};

/// Five rotors on a circle at 72°, three clockwise and two counter-clockwise, all with the
/// vehicle's coefficients.
fn pentacopter() -> Frame {
    let rotors = (0..5)
        .map(|i| {
            let a = std::f64::consts::TAU * f64::from(i) / 5.0;
            let spin = if i % 2 == 0 { Spin::Cw } else { Spin::Ccw };
            Rotor::at(a.cos(), a.sin(), spin)
        })
        .collect();
    let table = FrameTable {
        name: "penta".into(),
        rotors,
    };
    Frame::new(table).unwrap()
}

fn table() -> &'static Table<Quadrotor> {
    let fmu = Multirotor {
        identifier: "Pentacopter",
        noun: "pentacopter",
        frame: pentacopter(),
    };
    // An engine holds its table for the life of the process, as the library's own do.
    Box::leak(Box::new(fmu.table()))
}

fn index(table: &Table<Quadrotor>, name: &str) -> usize {
    let variables = &table.table.variables;
    (variables.iter().position(|v| v.name == name)).unwrap_or_else(|| panic!("no {name}"))
}

/// An instance at 10 m with the ground and the wind off, its motors at `motor`, every motor
/// commanded to `motor`.
fn flying(table: &'static Table<Quadrotor>, motor: f64) -> Box<dyn Simulation> {
    let mut sim = Engine::start(table).unwrap();
    let start = [
        ("ground_enabled", 0.0),
        ("wind_enabled", 0.0),
        ("initial_z", 10.0),
        ("initial_motor", motor),
    ];
    for (name, value) in start {
        sim.set(index(table, name), value, false).unwrap();
    }
    sim.setup_experiment(0.0, None).unwrap();
    for i in 0..5 {
        let command = index(table, &format!("motor_command_{i}"));
        sim.set(command, motor, true).unwrap();
    }
    sim
}

#[test]
fn a_frame_defined_in_the_test_gets_its_fmu_table_from_its_rotors() {
    let table = table();
    let t = &table.table;
    let vr = |name: &str| t.by_name(name).map(|v| v.value_reference);
    assert_eq!(vr("motor_command_4"), Some(4));
    assert_eq!(vr("motor_command_5"), None);
    assert_eq!(vr("wind_input_x"), Some(5));
    assert_eq!(vr("motor_state_4"), Some(123));
    assert_eq!(vr("wind_x"), Some(124));
    assert_eq!(vr("der(motor_state_4)"), Some(817));
    let me = t.model_exchange.as_ref().unwrap();
    assert_eq!((me.states.len(), me.derivatives.len()), (13 + 5 + 8, 26));
    let command = t.fmi3.iter().find(|v| v.name == "motor_command").unwrap();
    assert_eq!(command.dimension, Some(5));
    let text = |name| t.by_name(name).unwrap().description.to_string();
    assert_eq!(text("motor_command_0"), "Command of motor 0 (front, CW)");
    assert_eq!(
        text("motor_state_1"),
        "Lagged state of motor 1 (72° left of forward, CCW)"
    );
    assert_eq!(text("initial_motor"), "Initial state of all five motors");
    let xml = generate(t, Api::Fmi2);
    assert!(xml.contains("modelName=\"Pentacopter\""));
    assert!(xml.contains("five lagged motors"));
    // Its own interface, so its own GUID: no instance of a shipped FMU takes its states.
    for shipped in tables() {
        assert_ne!(t.token(Api::Fmi2), shipped.token(Api::Fmi2));
    }
}

#[test]
fn the_engine_flies_a_frame_defined_in_the_test() {
    let table = table();
    let (mass, gravity, k) = (1.0f64, 9.81, 10.0);
    let hover = (mass * gravity / (5.0 * k)).sqrt();
    let mut sim = flying(table, hover);
    let get = |sim: &dyn Simulation, name: &str| sim.get(index(table, name));
    assert!(get(&*sim, "az").abs() < 1e-12, "{}", get(&*sim, "az"));
    for n in 0..200 {
        sim.do_step(f64::from(n) * 0.01, 0.01).unwrap();
    }
    let z = get(&*sim, "z");
    assert!((z - 10.0).abs() < 1e-9, "hovers: z = {z}");
    assert_eq!(get(&*sim, "motor_state_4"), hover);
    // Three clockwise rotors against two: the reaction torque turns it toward +z.
    let wz = get(&*sim, "wz");
    assert!(wz > 0.01, "yaws: wz = {wz}");

    let mut sim = flying(table, 1.0);
    let az = get(&*sim, "az");
    let lift = 5.0 * k / mass - gravity;
    assert!((az - lift).abs() < 1e-12, "az = {az}, Σk/m − g = {lift}");
    for n in 0..50 {
        sim.do_step(f64::from(n) * 0.01, 0.01).unwrap();
    }
    // Below ½·a·t² = 5.02 m only by what the drag takes.
    let climb = get(&*sim, "z") - 10.0;
    assert!(climb > 4.5 && climb < 0.5 * lift * 0.25, "climb {climb}");
}
