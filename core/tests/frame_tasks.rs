//! The flight tasks on any frame: the motor interface takes one command per rotor and
//! observes every motor, the rates interface keeps its four values and flies the frame
//! through PX4's rate loop mixing for that frame, randomisation draws the same vehicles, and
//! the quad X named explicitly is the default task bit for bit.

use flyloop_core::frames::flu_to_frd;
use flyloop_core::params::Parameters;
use flyloop_core::quadrotor::{Frame, QuadrotorParams};
use flyloop_core::tasks::randomization::ParamRange;
use flyloop_core::tasks::registry::{TaskConfig, TaskInstance, TaskKind, from_values_and_ranges};
use flyloop_core::tasks::{ActionError, InfoValue};

/// The PX4 hexa preset's vehicle: 2 kg on six 10 N rotors (hovers at √(2·9.81/60) = 0.572).
fn hexa_preset() -> QuadrotorParams {
    let text = include_str!("../../sitl/presets/px4_hexa_x.toml");
    let mut table: toml::Table = toml::from_str(text).unwrap();
    table.remove("frame");
    QuadrotorParams::from_toml_str(&toml::to_string(&table).unwrap()).unwrap()
}

fn task(kind: TaskKind, frame: &str, edit: impl FnOnce(&mut TaskConfig)) -> TaskInstance {
    let mut config = TaskConfig {
        frame: Frame::named(frame).unwrap(),
        ..TaskConfig::default()
    };
    edit(&mut config);
    TaskInstance::build(kind, &config).unwrap()
}

fn rates(config: &mut TaskConfig) {
    config.quadrotor = hexa_preset();
    config.flight.rates_action = true;
    config.flight.dt = 0.02;
    config.flight.start_attitude_range = 0.0;
}

#[test]
fn the_motor_interface_has_one_action_and_two_observations_per_rotor() {
    for (frame, rotors) in [
        ("quad_x", 4),
        ("quad_plus", 4),
        ("hexa_x", 6),
        ("octo_x", 8),
    ] {
        for kind in [TaskKind::Hover, TaskKind::Waypoints] {
            let mut t = task(kind, frame, |_| {});
            assert_eq!(t.action_size(), rotors, "{frame}");
            let (lo, hi) = t.action_bounds();
            assert_eq!((lo, hi), (vec![0.0; rotors], vec![1.0; rotors]));
            let layout = t.observation_layout();
            let motors: Vec<usize> = (layout.iter())
                .filter(|g| g.0.starts_with("motor_"))
                .map(|g| g.1)
                .collect();
            assert_eq!(motors, vec![rotors, rotors], "{frame}");
            let extra = if kind == TaskKind::Waypoints { 4 } else { 0 };
            assert_eq!(t.observation_size(), 25 + 2 * rotors + extra, "{frame}");
            assert_eq!(t.observation_bounds().0.len(), t.observation_size());
            t.reset(5);
            let mut command = vec![0.3; rotors];
            command[rotors - 1] = 0.9;
            t.step(&command).unwrap();
            let obs = t.observation();
            // The commands in effect are the last group of the base observation.
            let at = 25 + rotors;
            let expected: Vec<f32> = command.iter().map(|&v| v as f32).collect();
            assert_eq!(&obs[at..at + rotors], &expected[..], "{frame}");
        }
    }
}

#[test]
fn a_wrong_length_action_is_refused_naming_both_lengths() {
    let mut t = task(TaskKind::Hover, "hexa_x", |_| {});
    let err = t.step(&[0.5; 4]).unwrap_err();
    assert_eq!(
        err,
        ActionError::WrongLength {
            expected: 6,
            got: 4
        }
    );
    assert_eq!(err.to_string(), "action has 4 values, the task takes 6");
    // The rates interface stays at four values on any frame.
    let mut t = task(TaskKind::Hover, "hexa_x", rates);
    assert_eq!(t.action_size(), 4);
    assert_eq!(t.observation_size(), 16);
    assert!(t.step(&[0.5; 6]).is_err());
}

#[test]
fn the_hexa_starts_at_its_own_hover_state_and_holds_with_it() {
    let mut t = task(TaskKind::Hover, "hexa_x", |c| {
        c.quadrotor.wind_enabled = false;
        c.flight.start_attitude_range = 0.0;
    });
    t.reset(1);
    let hover = (9.81f64 / 60.0).sqrt();
    let obs = t.observation();
    assert!(obs[25..31].iter().all(|&m| m == hover as f32), "{obs:?}");
    let start = t.kinematics().position;
    for _ in 0..100 {
        t.step(&[hover; 6]).unwrap();
    }
    let moved = (t.kinematics().position - start).norm();
    assert!(moved < 1e-9, "moved {moved} m at the hover state");
}

#[test]
fn the_rates_interface_holds_and_steers_a_hexa_through_px4s_mixer() {
    let hover = (2.0f64 * 9.81 / 60.0).sqrt();
    let mut t = task(TaskKind::Hover, "hexa_x", rates);
    t.reset(3);
    let start = t.kinematics().position;
    for _ in 0..100 {
        assert!(!t.step(&[hover, 0.0, 0.0, 0.0]).unwrap().terminated);
    }
    let k = t.kinematics();
    assert!(
        (k.position - start).norm() < 0.05,
        "drifted to {}",
        k.position
    );
    assert!(k.body_rates.norm() < 0.01, "{}", k.body_rates);
    // A rate step on each axis is followed with PX4's sign within 0.2 s (FRD).
    for axis in 0..3 {
        t.reset(3);
        let mut action = [hover, 0.0, 0.0, 0.0];
        action[axis + 1] = 1.0;
        for _ in 0..10 {
            t.step(&action).unwrap();
        }
        let r = flu_to_frd(&t.kinematics().body_rates);
        assert!((r[axis] - 1.0).abs() < 0.25, "axis {axis}: {r}");
        for other in (0..3).filter(|&o| o != axis) {
            assert!(r[other].abs() < 0.15, "axis {axis} moved {other}: {r}");
        }
    }
}

#[test]
fn the_quad_x_named_is_the_default_task_bit_for_bit() {
    for rates_action in [false, true] {
        let config = |frame: Option<Frame>| {
            let mut c = TaskConfig {
                frame: frame.unwrap_or_default(),
                ..TaskConfig::default()
            };
            c.flight.rates_action = rates_action;
            c
        };
        let mut named =
            TaskInstance::build(TaskKind::Hover, &config(Frame::named("quad_x").ok())).unwrap();
        let mut default = TaskInstance::build(TaskKind::Hover, &config(None)).unwrap();
        named.reset(11);
        default.reset(11);
        let action = if rates_action {
            vec![0.55, 0.3, -0.2, 0.1]
        } else {
            vec![0.5, 0.52, 0.49, 0.51]
        };
        for _ in 0..50 {
            named.step(&action).unwrap();
            default.step(&action).unwrap();
        }
        let bits = |t: &TaskInstance| -> Vec<u32> {
            t.observation().iter().map(|v| v.to_bits()).collect()
        };
        assert_eq!(bits(&named), bits(&default));
    }
}

#[test]
fn randomisation_draws_the_same_hexa_for_the_same_seed() {
    let range = |name: &str, low, high| ParamRange {
        name: name.to_string(),
        low,
        high,
    };
    let build = || {
        let ranges = vec![
            range("mass", 0.8, 1.4),
            range("motor_time_constant", 0.05, 0.1),
        ];
        let hexa = Some(Frame::named("hexa_x").unwrap());
        let config = from_values_and_ranges(TaskKind::Hover, [], ranges, hexa).unwrap();
        TaskInstance::build(TaskKind::Hover, &config).unwrap()
    };
    let (mut a, mut b) = (build(), build());
    let drawn = |t: &TaskInstance| {
        t.info()
            .into_iter()
            .find(|(n, _)| *n == "randomized")
            .map(|(_, v)| v)
    };
    let mut seen = Vec::new();
    for seed in [1, 2, 1] {
        a.reset(seed);
        b.reset(seed);
        for _ in 0..20 {
            a.step(&[0.45; 6]).unwrap();
            b.step(&[0.45; 6]).unwrap();
        }
        assert_eq!(a.observation(), b.observation());
        let Some(InfoValue::Vector(v)) = drawn(&a) else {
            panic!("no randomised values in the info");
        };
        assert_eq!(v.len(), 2);
        seen.push(v);
    }
    assert_ne!(seen[0], seen[1]);
    assert_eq!(seen[0], seen[2]);
}
