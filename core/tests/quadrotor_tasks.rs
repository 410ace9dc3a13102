//! Hover and Waypoints: rewards and terminations on hand-built states, reset sampling,
//! observation layout and bounds, truncation, determinism. "The reference" below is seed
//! 001's environment (docs/reference/quadrotor.md).

// Helpers are test code too: a failed setup is a failed test.

use flyloop_core::SimRng;
use flyloop_core::params::Parameters;
use flyloop_core::quadrotor::{BodyState, QuadrotorParams};
use flyloop_core::tasks::flight::FlightParams;
use flyloop_core::tasks::hover::{Hover, hover_reward, out_of_bounds_distance};
use flyloop_core::tasks::waypoints::{WaypointParams, Waypoints};
use flyloop_core::tasks::{ActionError, InfoValue, Task};
use nalgebra::Vector3;

fn hover_task(flight: FlightParams) -> Hover {
    Hover::new(QuadrotorParams::default(), flight).unwrap()
}

fn info_flag(task: &dyn Task, name: &str) -> bool {
    match task.info().into_iter().find(|(n, _)| *n == name) {
        Some((_, InfoValue::Flag(f))) => f,
        other => panic!("{name}: {other:?}"),
    }
}

fn hover_command(task: &Hover) -> [f64; 4] {
    [task.air_vehicle().params().hover_motor_state().unwrap(); 4]
}

#[test]
fn hover_reward_matches_the_formula_on_hand_built_states() {
    let flight = FlightParams::default();
    let target = Vector3::new(1.0, 2.0, 1.0);
    // On the target at rest: e^0 = 1.
    let mut body = BodyState::at_rest(target, 0.0, 0.0, 0.0, 0.5);
    assert_eq!(hover_reward(&flight, &body, &target), 1.0);
    // 2 m away, closing at 3 m/s: e^-2 + ½(1 − e^-2) tanh(1).
    body.position = target - Vector3::new(2.0, 0.0, 0.0);
    body.velocity = Vector3::new(3.0, 0.0, 0.0);
    let expected = (-2.0f64).exp() + 0.5 * (1.0 - (-2.0f64).exp()) * 1.0f64.tanh();
    assert!((hover_reward(&flight, &body, &target) - expected).abs() < 1e-8);
    // Moving away at 6 m/s: the velocity term is negative, tanh(−2).
    body.velocity = Vector3::new(-6.0, 0.0, 0.0);
    let expected = (-2.0f64).exp() + 0.5 * (1.0 - (-2.0f64).exp()) * (-2.0f64).tanh();
    assert!((hover_reward(&flight, &body, &target) - expected).abs() < 1e-8);
}

#[test]
fn a_step_pays_the_reward_of_the_state_it_ends_in() {
    let mut task = hover_task(FlightParams::default());
    task.reset(3);
    let outcome = task.step(&hover_command(&task)).unwrap();
    let expected = hover_reward(task.params(), task.air_vehicle().body(), &task.target());
    assert_eq!(outcome.reward, expected);
    assert!(!outcome.terminated && !outcome.truncated);
}

#[test]
fn reset_samples_the_documented_start_and_target() {
    let mut task = hover_task(FlightParams::default());
    for seed in 0..200 {
        task.reset(seed);
        let body = *task.air_vehicle().body();
        assert_eq!(body.position, Vector3::new(0.0, 0.0, 1.5));
        assert_eq!(body.velocity, Vector3::zeros());
        let (roll, pitch, yaw) = body.euler_angles();
        assert!(
            roll.abs() <= 0.1 + 1e-12 && pitch.abs() <= 0.1 + 1e-12 && yaw.abs() <= 0.1 + 1e-12
        );
        let hover = task.air_vehicle().params().hover_motor_state().unwrap();
        assert_eq!(body.motors, [hover; 4]);
        assert_eq!(task.air_vehicle().motor_command(), [hover; 4]);
        let t = task.target();
        assert!(t.x.abs() <= 1.5 && t.y.abs() <= 1.5 && (0.0..=3.0).contains(&t.z));
        assert!((t - body.position).norm() >= 1.0);
        assert_eq!(task.step_count(), 0);
        assert!(!info_flag(&task, "crashed") && !info_flag(&task, "out_of_bounds"));
    }
}

#[test]
fn same_seed_same_episode_bit_for_bit() {
    let rollout = |seed: u64| {
        let mut task = hover_task(FlightParams::default());
        task.reset(seed);
        let mut actions = SimRng::new(1234);
        let mut trace: Vec<u32> = task.observation().iter().map(|x| x.to_bits()).collect();
        for _ in 0..300 {
            let a = [0.0; 4].map(|_: f64| actions.uniform(0.4, 0.6));
            let out = task.step(&a).unwrap();
            trace.extend(task.observation().iter().map(|x| x.to_bits()));
            trace.push((out.reward as f32).to_bits());
        }
        trace
    };
    assert_eq!(rollout(11), rollout(11));
    assert_ne!(rollout(11), rollout(12));
}

#[test]
fn observation_layout_of_a_hand_built_state() {
    let mut task = hover_task(FlightParams::default());
    task.reset(0);
    task.set_target(Vector3::new(1.0, -1.0, 2.0));
    {
        let quad = task.air_vehicle_mut();
        *quad.body_mut() = BodyState::at_rest(Vector3::new(0.5, 0.5, 1.0), 0.0, 0.0, 0.0, 0.3);
        quad.body_mut().velocity = Vector3::new(1.0, 2.0, -3.0);
        quad.body_mut().body_rates = Vector3::new(0.1, -0.2, 0.3);
        // No external wind after a reset: the total is the vehicle's own.
        let own = quad.wind_velocity();
        quad.set_external_wind(-own + Vector3::new(2.0, -1.0, 0.5));
        quad.set_actuators(&[0.1, 0.2, 0.3, 0.4]).unwrap();
    }
    let obs = task.observation();
    assert_eq!(obs.len(), 33);
    let close = |got: &[f32], want: &[f64]| {
        for (g, w) in got.iter().zip(want) {
            assert!((f64::from(*g) - w).abs() < 1e-6, "{got:?} vs {want:?}");
        }
    };
    close(&obs[0..3], &[0.5, -1.5, 1.0]);
    close(&obs[3..6], &[1.0, 2.0, -3.0]);
    let (acc, ang) = task.air_vehicle().accelerations();
    close(&obs[6..9], acc.as_slice());
    close(&obs[9..13], &[1.0, 0.0, 0.0, 0.0]);
    close(&obs[13..16], &[0.1, -0.2, 0.3]);
    close(&obs[16..19], ang.as_slice());
    close(&obs[19..22], &[0.0, 0.0, 1.0]);
    close(&obs[22..25], &[2.0, -1.0, 0.5]);
    close(&obs[25..29], &[0.3; 4]);
    close(&obs[29..33], &[0.1, 0.2, 0.3, 0.4]);
}

#[test]
fn observations_stay_inside_their_declared_bounds() {
    // Regression: the reference declared ±1.5 m for target − position and left it in 10–24 %
    // of steps. Random and extreme actions, crashes and out-of-bounds flights included.
    let flight = FlightParams {
        enable_crash_detection: false,
        enable_out_of_bounds_detection: false,
        max_steps: 400,
        ..Default::default()
    };
    let mut hover = hover_task(flight.clone());
    let mut waypoints = Waypoints::new(
        QuadrotorParams::default(),
        flight,
        WaypointParams::default(),
    )
    .unwrap();
    let mut actions = SimRng::new(5);
    for task in [&mut hover as &mut dyn Task, &mut waypoints] {
        let (lo, hi) = task.observation_bounds();
        assert_eq!(lo.len(), task.observation_size());
        for seed in 0..8 {
            task.reset(seed);
            for _ in 0..400 {
                let a: Vec<f64> = (0..4).map(|_| actions.uniform(-0.5, 1.5)).collect();
                task.step(&a).unwrap();
                let obs = task.observation();
                for (i, v) in obs.iter().enumerate() {
                    assert!(
                        lo[i] <= *v && *v <= hi[i],
                        "obs[{i}] = {v} outside [{}, {}]",
                        lo[i],
                        hi[i]
                    );
                }
            }
        }
    }
}

#[test]
fn crash_terminates_on_tilt_fall_speed_and_ground() {
    let mut task = hover_task(FlightParams::default());
    let h = hover_command(&task);
    type Mutation = fn(&mut BodyState);
    let cases: [(&str, Mutation); 3] = [
        ("tilt", |b| {
            *b = BodyState::at_rest(b.position, 81f64.to_radians(), 0.0, 0.0, b.motors[0])
        }),
        ("fall", |b| b.velocity.z = -25.0),
        ("ground", |b| b.position.z = 0.001),
    ];
    for (name, mutate) in cases {
        task.reset(1);
        task.set_target(Vector3::new(0.0, 0.0, 1.5));
        mutate(task.air_vehicle_mut().body_mut());
        let mut outcome = task.step(&h).unwrap();
        for _ in 0..20 {
            if outcome.terminated {
                break;
            }
            outcome = task.step(&[0.0; 4]).unwrap();
        }
        assert!(outcome.terminated, "{name}");
        assert!(info_flag(&task, "crashed"), "{name}");
        assert!(!info_flag(&task, "out_of_bounds"), "{name}");
    }
    // 79° is not a crash.
    task.reset(1);
    *task.air_vehicle_mut().body_mut() = BodyState::at_rest(
        Vector3::new(0.0, 0.0, 1.5),
        79f64.to_radians(),
        0.0,
        0.0,
        h[0],
    );
    assert!(!task.step(&h).unwrap().terminated);
    // With detection off the same fall goes on.
    let mut lenient = hover_task(FlightParams {
        enable_crash_detection: false,
        ..Default::default()
    });
    lenient.air_vehicle_mut().body_mut().velocity.z = -25.0;
    assert!(!lenient.step(&h).unwrap().terminated);
    assert!(!info_flag(&lenient, "crashed"));
}

#[test]
fn out_of_bounds_beyond_root_3_times_the_side() {
    let mut task = hover_task(FlightParams::default());
    let h = hover_command(&task);
    let limit = out_of_bounds_distance(task.params());
    assert!((limit - 5.196152422706632).abs() < 1e-12);
    task.set_target(Vector3::new(0.0, 0.0, 1.5 + limit - 0.01));
    assert!(!task.step(&h).unwrap().terminated);
    task.set_target(Vector3::new(0.0, 0.0, 1.5 + limit + 0.05));
    let out = task.step(&h).unwrap();
    assert!(out.terminated && info_flag(&task, "out_of_bounds") && !info_flag(&task, "crashed"));
}

#[test]
fn truncation_fires_at_max_steps_exactly() {
    let mut task = hover_task(FlightParams {
        max_steps: 5,
        ..Default::default()
    });
    let h = hover_command(&task);
    for step in 1..=5 {
        let out = task.step(&h).unwrap();
        assert_eq!(out.truncated, step == 5, "step {step}");
    }
}

#[test]
fn target_changes_every_interval() {
    let mut task = hover_task(FlightParams {
        target_change_interval: 10,
        ..Default::default()
    });
    task.reset(4);
    let h = hover_command(&task);
    let first = task.target();
    for _ in 0..9 {
        task.step(&h).unwrap();
        assert_eq!(task.target(), first);
    }
    task.step(&h).unwrap();
    let second = task.target();
    assert_ne!(second, first);
    assert!((second - task.air_vehicle().body().position).norm() >= 1.0);
}

#[test]
fn bad_actions_are_refused_with_their_index() {
    let mut task = hover_task(FlightParams::default());
    assert_eq!(
        task.step(&[0.5; 3]),
        Err(ActionError::WrongLength {
            expected: 4,
            got: 3
        })
    );
    let err = task.step(&[0.5, 0.5, f64::NAN, 0.5]).unwrap_err();
    assert!(matches!(err, ActionError::NotFinite { index: 2, .. }));
    assert_eq!(
        task.step_count(),
        0,
        "a refused action must not advance the episode"
    );
}

#[test]
fn bad_task_parameters_are_named() {
    let err = Hover::new(
        QuadrotorParams::default(),
        FlightParams {
            dt: 0.0,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(err.to_string().contains("`dt` = 0 s"), "{err}");
    let err = Hover::new(
        QuadrotorParams::default(),
        FlightParams {
            max_steps: 0,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(err.to_string().contains("`max_steps` = 0"), "{err}");
    let err = Hover::new(
        QuadrotorParams {
            mass: -1.0,
            ..Default::default()
        },
        FlightParams::default(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("`mass`"), "{err}");
    let err = FlightParams::from_toml_str("min_target_distance = 100").unwrap_err();
    assert!(err.to_string().contains("min_target_distance"), "{err}");
    let err = WaypointParams::from_toml_str("max_num_waypoints = 0").unwrap_err();
    assert!(err.to_string().contains("`max_num_waypoints` = 0"), "{err}");
}

fn waypoint_task(params: WaypointParams) -> Waypoints {
    Waypoints::new(QuadrotorParams::default(), FlightParams::default(), params).unwrap()
}

/// Puts the vehicle on `position` at rest, motors at hover.
fn place(task: &mut Waypoints, position: Vector3<f64>) -> [f64; 4] {
    let h = task.air_vehicle().params().hover_motor_state().unwrap();
    *task.air_vehicle_mut().body_mut() = BodyState::at_rest(position, 0.0, 0.0, 0.0, h);
    [h; 4]
}

#[test]
fn checkpoint_bonus_is_paid_on_the_reaching_step() {
    // Regression: the reference recomputed the reward against the next waypoint after
    // switching, so the bonus was never paid.
    let mut task = waypoint_task(WaypointParams::default());
    task.reset(2);
    let first = task.waypoints()[0];
    let h = place(&mut task, first);
    let out = task.step(&h).unwrap();
    let mean_motor = task.air_vehicle().body().motors.iter().sum::<f64>() / 4.0;
    let expected = (10.0 - 2.0 * 0.01) + 0.5 * mean_motor;
    assert!(
        (out.reward - expected).abs() < 1e-12,
        "{} vs {expected}",
        out.reward
    );
    assert_eq!(task.waypoints_reached(), 1);
    assert_eq!(task.current_waypoint(), task.waypoints()[1]);
    assert_eq!(task.time_since_checkpoint(), 0.0);
}

#[test]
fn the_bonus_decays_with_time_but_never_below_one() {
    let mut task = waypoint_task(WaypointParams::default());
    task.reset(2);
    let h = place(&mut task, Vector3::new(0.0, 0.0, 1.5));
    for _ in 0..299 {
        task.step(&h).unwrap();
    }
    let first = task.waypoints()[0];
    place(&mut task, first);
    let out = task.step(&h).unwrap();
    // 3 s since the start: 10 − 2·3 = 4.
    let mean_motor = task.air_vehicle().body().motors.iter().sum::<f64>() / 4.0;
    assert!(
        (out.reward - (4.0 + 0.5 * mean_motor)).abs() < 1e-9,
        "{}",
        out.reward
    );
    // 5 s later the bonus 10 − 2·5 = 0 is floored at 1.
    for _ in 0..499 {
        let second = task.waypoints()[1];
        place(&mut task, second + Vector3::new(0.5, 0.0, 0.0));
        task.step(&h).unwrap();
    }
    let second = task.waypoints()[1];
    place(&mut task, second);
    let out = task.step(&h).unwrap();
    assert_eq!(task.waypoints_reached(), 2);
    let mean_motor = task.air_vehicle().body().motors.iter().sum::<f64>() / 4.0;
    assert!(
        (out.reward - (1.0 + 0.5 * mean_motor)).abs() < 1e-12,
        "{}",
        out.reward
    );
}

#[test]
fn far_from_the_waypoint_the_reward_is_the_closing_speed_plus_the_motor_bonus() {
    let mut task = waypoint_task(WaypointParams::default());
    task.reset(6);
    let wp = task.waypoints()[0];
    // Horizontal offsets keep the vehicle clear of the ground whatever the waypoint's height.
    let h = place(&mut task, wp - Vector3::new(2.0, 0.0, 0.0));
    task.air_vehicle_mut().body_mut().velocity = Vector3::new(3.0, 0.0, 0.0);
    let out = task.step(&h).unwrap();
    let b = *task.air_vehicle().body();
    let d = wp - b.position;
    let closing = b.velocity.dot(&(d / (d.norm() + 1e-8)));
    let mean_motor = b.motors.iter().sum::<f64>() / 4.0;
    assert!((out.reward - ((closing / 3.0).tanh() + 0.5 * mean_motor)).abs() < 1e-12);
    // Flying away: negative, no motor bonus.
    let h = place(&mut task, wp - Vector3::new(2.0, 0.0, 0.0));
    task.air_vehicle_mut().body_mut().velocity = Vector3::new(-3.0, 0.0, 0.0);
    let out = task.step(&h).unwrap();
    assert!(out.reward < 0.0 && out.reward > -1.0);
}

#[test]
fn waypoint_info_keeps_crashed_and_out_of_bounds() {
    // Regression: the reference's waypoint info dropped both flags.
    let task = waypoint_task(WaypointParams::default());
    let names: Vec<&str> = task.info().iter().map(|(n, _)| *n).collect();
    for key in [
        "distance_to_target",
        "position",
        "target_position",
        "step_count",
        "episode_time",
        "distance_progress",
        "crashed",
        "out_of_bounds",
        "waypoints_reached",
        "current_waypoint_pos",
        "next_waypoint_pos",
        "steps_since_checkpoint",
    ] {
        assert!(names.contains(&key), "{key} missing from {names:?}");
    }
}

#[test]
fn reaching_every_waypoint_truncates() {
    let mut task = waypoint_task(WaypointParams {
        max_num_waypoints: 2,
        ..Default::default()
    });
    task.reset(9);
    let wps = task.waypoints().to_vec();
    let h = place(&mut task, wps[0]);
    let first = task.step(&h).unwrap();
    assert!(!first.truncated);
    place(&mut task, wps[1]);
    let second = task.step(&h).unwrap();
    assert!(second.truncated && !second.terminated);
    assert_eq!(task.waypoints_reached(), 2);
}

#[test]
fn waypoint_observation_appends_next_waypoint_and_time() {
    let mut task = waypoint_task(WaypointParams::default());
    task.reset(4);
    let h = place(&mut task, Vector3::new(0.0, 0.0, 1.5));
    for _ in 0..50 {
        task.step(&h).unwrap();
    }
    let obs = task.observation();
    assert_eq!(obs.len(), 37);
    let p = task.air_vehicle().body().position;
    let current = task.waypoints()[0] - p;
    let next = task.waypoints()[1] - p;
    for i in 0..3 {
        assert!((f64::from(obs[i]) - current[i]).abs() < 1e-6);
        assert!((f64::from(obs[33 + i]) - next[i]).abs() < 1e-6);
    }
    assert!((obs[36] - 0.5).abs() < 1e-6, "{}", obs[36]);
}

#[test]
fn waypoints_are_spaced_and_reproducible() {
    let mut a = waypoint_task(WaypointParams::default());
    let mut b = waypoint_task(WaypointParams::default());
    a.reset(21);
    b.reset(21);
    assert_eq!(a.waypoints(), b.waypoints());
    assert_eq!(a.waypoints().len(), 15);
    let mut from = Vector3::new(0.0, 0.0, 1.5);
    for wp in a.waypoints() {
        assert!((wp - from).norm() >= 1.0);
        from = *wp;
    }
    b.reset(22);
    assert_ne!(a.waypoints(), b.waypoints());
}
