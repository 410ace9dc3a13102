//! The rates interface (thrust + body rates through PX4's rate loop), its observation,
//! latency, noise and the per-episode randomisation, on the Iris of the PX4 preset.

// Helpers are test code too: a failed setup is a failed test.

use flyloop_core::frames::flu_to_frd;
use flyloop_core::params::Parameters;
use flyloop_core::quadrotor::QuadrotorParams;
use flyloop_core::tasks::flight::FlightParams;
use flyloop_core::tasks::hover::Hover;
use flyloop_core::tasks::randomization::{ParamRange, Randomization, VehicleParams};
use flyloop_core::tasks::waypoints::{WaypointParams, Waypoints};
use flyloop_core::tasks::{InfoValue, Task};

fn iris() -> QuadrotorParams {
    QuadrotorParams::from_toml_str(include_str!("../../sitl/presets/px4_iris.toml")).unwrap()
}

fn rates_flight() -> FlightParams {
    FlightParams {
        dt: 0.02,
        rates_action: true,
        start_attitude_range: 0.0,
        ..FlightParams::default()
    }
}

fn hover_task(flight: FlightParams, randomize: Vec<ParamRange>) -> Hover {
    let nominal = VehicleParams {
        quadrotor: iris(),
        flight,
        ..VehicleParams::default()
    };
    Hover::with_vehicle(nominal, Randomization::new(randomize).unwrap()).unwrap()
}

fn hover_thrust() -> f64 {
    iris().hover_motor_state().unwrap()
}

#[test]
fn rates_interface_declares_px4s_action_and_16_observations() {
    let task = hover_task(rates_flight(), vec![]);
    let (lo, hi) = task.action_bounds();
    let max = 220f64.to_radians();
    assert_eq!(lo, vec![0.0, -max, -max, -200f64.to_radians()]);
    assert_eq!(hi, vec![1.0, max, max, 200f64.to_radians()]);
    assert_eq!(task.observation_size(), 16);
    let sizes: Vec<usize> = task.observation_layout().iter().map(|g| g.1).collect();
    assert_eq!(sizes, vec![3, 3, 3, 3, 4]);
    let obs = task.observation();
    let (olo, ohi) = task.observation_bounds();
    for i in 0..16 {
        assert!(olo[i] <= obs[i] && obs[i] <= ohi[i], "{i}: {}", obs[i]);
    }
    // Level at the start: the body's down axis is the heading frame's z; the previous
    // action is hover thrust with no rates.
    assert_eq!(&obs[6..9], &[0.0, 0.0, 1.0]);
    assert_eq!(obs[12], hover_thrust() as f32);
}

#[test]
fn hover_thrust_and_zero_rates_hold_the_vehicle() {
    let mut task = hover_task(rates_flight(), vec![]);
    task.reset(3);
    let start = task.air_vehicle().body().position;
    for _ in 0..100 {
        let out = task.step(&[hover_thrust(), 0.0, 0.0, 0.0]).unwrap();
        assert!(!out.terminated);
    }
    let b = task.air_vehicle().body();
    assert!(
        (b.position - start).norm() < 0.05,
        "drifted to {}",
        b.position
    );
    assert!(b.body_rates.norm() < 0.01, "{}", b.body_rates);
}

#[test]
fn a_roll_rate_step_is_followed_with_px4s_sign() {
    // FRD roll rate +1 rad/s: right side down, i.e. FLU x rate +1 as well (x is shared).
    let mut task = hover_task(rates_flight(), vec![]);
    task.reset(3);
    let mut rates = Vec::new();
    for _ in 0..10 {
        task.step(&[hover_thrust(), 1.0, 0.0, 0.0]).unwrap();
        rates.push(flu_to_frd(&task.air_vehicle().body().body_rates));
    }
    let after_100ms = rates[4];
    let after_200ms = rates[9];
    assert!(after_100ms.x > 0.5, "{after_100ms}");
    assert!((after_200ms.x - 1.0).abs() < 0.15, "{after_200ms}");
    assert!(
        after_200ms.y.abs() < 0.1 && after_200ms.z.abs() < 0.1,
        "{after_200ms}"
    );
    // The observation reports the FRD rates.
    let obs = task.observation();
    assert!((obs[9] as f64 - after_200ms.x).abs() < 1e-6);
    // Pitch and yaw follow with their signs too.
    for (axis, action) in [
        (1, [hover_thrust(), 0.0, 1.0, 0.0]),
        (2, [hover_thrust(), 0.0, 0.0, 1.0]),
    ] {
        task.reset(3);
        for _ in 0..15 {
            task.step(&action).unwrap();
        }
        let r = flu_to_frd(&task.air_vehicle().body().body_rates);
        assert!(r[axis] > 0.6, "axis {axis}: {r}");
    }
}

#[test]
fn latency_delays_the_setpoint_by_whole_rate_loop_ticks() {
    let mut flight = rates_flight();
    flight.action_latency = 0.04;
    let mut late = hover_task(flight, vec![]);
    let mut now = hover_task(rates_flight(), vec![]);
    late.reset(5);
    now.reset(5);
    // Hold hover for 2 steps, then command a roll rate; the late vehicle sees the command
    // 40 ms (2 steps) later, so its roll rate stays where the prompt one was before.
    let hover = [hover_thrust(), 0.0, 0.0, 0.0];
    let roll = [hover_thrust(), 1.0, 0.0, 0.0];
    for task in [&mut late, &mut now] {
        task.step(&hover).unwrap();
        task.step(&hover).unwrap();
    }
    now.step(&roll).unwrap();
    late.step(&roll).unwrap();
    assert!(now.air_vehicle().body().body_rates.x > 0.05);
    assert!(
        late.air_vehicle().body().body_rates.x.abs() < 1e-3,
        "{}",
        late.air_vehicle().body().body_rates
    );
    late.step(&roll).unwrap();
    late.step(&roll).unwrap();
    assert!(late.air_vehicle().body().body_rates.x > 0.05);
}

#[test]
fn any_control_period_works_on_the_rate_loops_own_grid() {
    // dt = 0.01 is not a multiple of 4 ms: the loop still ticks every 4 ms of episode time.
    let mut flight = rates_flight();
    flight.dt = 0.01;
    let mut task = hover_task(flight, vec![]);
    task.reset(1);
    for _ in 0..200 {
        task.step(&[hover_thrust(), 0.0, 0.0, 0.0]).unwrap();
    }
    assert!(task.air_vehicle().body().body_rates.norm() < 0.01);
    assert!((task.air_vehicle().body().position.z - 1.5).abs() < 0.05);
}

#[test]
fn same_seed_same_randomised_vehicle_noise_and_trajectory_bit_for_bit() {
    let ranges = || {
        vec![
            ParamRange {
                name: "mass".into(),
                low: 1.2,
                high: 1.8,
            },
            ParamRange {
                name: "thrust_coefficient".into(),
                low: 9.0,
                high: 11.0,
            },
            ParamRange {
                name: "motor_time_constant".into(),
                low: 0.015,
                high: 0.03,
            },
            ParamRange {
                name: "roll_rate_p".into(),
                low: 0.12,
                high: 0.18,
            },
            ParamRange {
                name: "action_latency".into(),
                low: 0.0,
                high: 0.02,
            },
        ]
    };
    let mut flight = rates_flight();
    flight.obs_noise_position = 0.02;
    flight.obs_noise_rates = 0.01;
    let run = |seed: u64| {
        let mut task = hover_task(flight.clone(), ranges());
        task.reset(seed);
        let mut trace = task.observation();
        for k in 0..50 {
            let a = [0.6, 0.1 * (k as f64 * 0.3).sin(), 0.0, -0.05];
            task.step(&a).unwrap();
            trace.extend(task.observation());
        }
        let drawn = task
            .info()
            .into_iter()
            .find(|(n, _)| *n == "randomized")
            .unwrap()
            .1;
        (trace, drawn, task.air_vehicle().params().mass)
    };
    let (a, da, ma) = run(11);
    let (b, db, mb) = run(11);
    assert_eq!(
        a.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        b.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    assert_eq!(da, db);
    let InfoValue::Vector(values) = da else {
        panic!("randomized is a vector")
    };
    assert_eq!(values.len(), 5);
    assert_eq!(values[0], ma, "info reports the mass flown");
    assert!((1.2..=1.8).contains(&ma) && ma == mb);
    let (c, dc, _) = run(12);
    assert_ne!(a, c);
    assert_ne!(dc, db);
}

#[test]
fn randomisation_off_leaves_every_episode_as_it_was() {
    // The motor interface with an empty randomisation is the task as before, bit for bit.
    let mut plain = Hover::new(QuadrotorParams::default(), FlightParams::default()).unwrap();
    let nominal = VehicleParams::default();
    let mut with = Hover::with_vehicle(nominal, Randomization::none()).unwrap();
    plain.reset(9);
    with.reset(9);
    for _ in 0..100 {
        plain.step(&[0.5, 0.52, 0.49, 0.5]).unwrap();
        with.step(&[0.5, 0.52, 0.49, 0.5]).unwrap();
    }
    assert_eq!(plain.observation(), with.observation());
    assert!(with.info().iter().all(|(n, _)| *n != "randomized"));
}

#[test]
fn observation_noise_moves_the_observation_not_the_vehicle() {
    let mut noisy_flight = rates_flight();
    noisy_flight.obs_noise_position = 0.1;
    noisy_flight.obs_noise_attitude = 0.01;
    let mut noisy = hover_task(noisy_flight, vec![]);
    let mut clean = hover_task(rates_flight(), vec![]);
    noisy.reset(4);
    clean.reset(4);
    let mut diffs = Vec::new();
    for _ in 0..200 {
        noisy.step(&[hover_thrust(), 0.0, 0.0, 0.0]).unwrap();
        clean.step(&[hover_thrust(), 0.0, 0.0, 0.0]).unwrap();
        let (n, c) = (noisy.observation(), clean.observation());
        diffs.push((n[0] - c[0]) as f64);
    }
    assert_eq!(noisy.air_vehicle().body(), clean.air_vehicle().body());
    let std = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
    assert!((std - 0.1).abs() < 0.03, "position noise std {std}");
}

#[test]
fn waypoints_fly_the_rates_interface_with_its_frame() {
    let nominal = VehicleParams {
        quadrotor: iris(),
        flight: rates_flight(),
        ..VehicleParams::default()
    };
    let mut task =
        Waypoints::with_vehicle(nominal, WaypointParams::default(), Randomization::none()).unwrap();
    task.reset(2);
    assert_eq!(task.observation_size(), 20);
    let sizes: usize = task.observation_layout().iter().map(|g| g.1).sum();
    assert_eq!(sizes, 20);
    task.step(&[hover_thrust(), 0.0, 0.0, 0.0]).unwrap();
    let obs = task.observation();
    // Next waypoint offset in the heading frame has the same length as in the world.
    let next = task.next_waypoint() - task.air_vehicle().body().position;
    let seen = nalgebra::Vector3::new(obs[16] as f64, obs[17] as f64, obs[18] as f64);
    assert!((seen.norm() - next.norm()).abs() < 1e-5, "{seen} vs {next}");
    assert!((seen.z + next.z).abs() < 1e-5, "down is minus up");
}

#[test]
fn a_snapshot_of_a_rates_episode_continues_exactly() {
    let mut flight = rates_flight();
    flight.action_latency = 0.012;
    flight.obs_noise_velocity = 0.05;
    let mut task = hover_task(
        flight,
        vec![ParamRange {
            name: "mass".into(),
            low: 1.4,
            high: 1.6,
        }],
    );
    task.reset(8);
    for _ in 0..20 {
        task.step(&[0.62, 0.2, -0.1, 0.0]).unwrap();
    }
    let bytes = json_roundtrip(&task);
    let mut copy: Hover = bytes;
    for _ in 0..30 {
        task.step(&[0.6, -0.2, 0.1, 0.05]).unwrap();
        copy.step(&[0.6, -0.2, 0.1, 0.05]).unwrap();
    }
    assert_eq!(task, copy);
    assert_eq!(task.observation(), copy.observation());
}

fn json_roundtrip(task: &Hover) -> Hover {
    let json = serde_json::to_string(task).unwrap();
    serde_json::from_str(&json).unwrap()
}
