//! The Landing task: spawn, observation, reward, termination order, truncation, determinism.

// The helpers below are test code too: a failed setup is a failed test.

use flyloop_core::lander2d::{DroneState, Lander2dParams};
use flyloop_core::rng::SimRng;
use flyloop_core::tasks::landing::{Landing, LandingParams, shaping_reward};
use flyloop_core::tasks::{ActionError, InfoValue, Task};

fn quiet() -> Lander2dParams {
    Lander2dParams {
        thrust_noise_std: 0.0,
        wind_enabled: false,
        ..Default::default()
    }
}

fn task(model: Lander2dParams) -> Landing {
    Landing::new(model, LandingParams::default()).unwrap()
}

fn at(x: f64, y: f64) -> DroneState {
    DroneState {
        x,
        y,
        ..Default::default()
    }
}

/// Level descent at `descent` m/s (see the model tests), as an action.
fn descent_action(t: &Landing, descent: f64) -> [f64; 2] {
    let l = t.lander();
    let p = l.params();
    let d = l.drone();
    let collective = p.hover_thrust() + p.drone_mass / 2.0 * 4.0 * (-descent - d.vy);
    let differential = -2.0 * d.angle - 0.5 * d.angular_velocity;
    let command = |thrust: f64| 2.0 * thrust.clamp(0.0, p.max_thrust) / p.max_thrust - 1.0;
    [
        command(collective - differential),
        command(collective + differential),
    ]
}

fn flag(t: &Landing, name: &str) -> bool {
    match t.info().into_iter().find(|(n, _)| *n == name) {
        Some((_, InfoValue::Flag(b))) => b,
        other => panic!("{name}: {other:?}"),
    }
}

/// The terminal or truncation part of the last step's reward.
fn terminal_part(t: &Landing, reward: f64) -> f64 {
    let (n, _) = t.normalised_observation();
    reward - shaping_reward(&n, t.lander().contact().touched_platform)
}

#[test]
fn spaces_are_the_reference_ones() {
    let t = task(Lander2dParams::default());
    assert_eq!(t.action_size(), 2);
    assert_eq!(t.action_bounds(), (vec![-1.0, -1.0], vec![1.0, 1.0]));
    assert_eq!(t.observation_size(), 11);
    let (low, high) = t.observation_bounds();
    assert_eq!(
        low,
        vec![
            -1.0, -1.0, -1.0, -1.0, -1.0, -1.0, 0.0, -1.0, -1.0, -1.0, 0.0
        ]
    );
    assert_eq!(high, vec![1.0; 11]);
    assert_eq!(t.dt(), 0.02);
    let moving = task(Lander2dParams {
        moving_platform: true,
        ..Default::default()
    });
    assert_eq!(moving.observation_size(), 12);
    let layout = |t: &Landing| t.observation_layout().iter().map(|g| g.1).sum::<usize>();
    assert_eq!((layout(&t), layout(&moving)), (11, 12));
    assert_eq!(moving.observation_layout()[8], ("platform_velocity", 1));
    assert_eq!(moving.observation().len(), 12);
    assert_eq!(
        moving.observation()[11].abs(),
        1.0,
        "platform vx / platform_speed"
    );
}

#[test]
fn observation_uses_the_documented_normalisation() {
    let mut t = task(quiet());
    let start = DroneState {
        x: 30.0,
        y: 20.0,
        angle: 0.5,
        vx: 3.0,
        vy: -1.5,
        angular_velocity: 2.0,
    };
    t.reset_to(1, start).unwrap();
    let o = t.observation();
    let (ex, ey) = (25.0 - 30.0, 10.5 - 20.0);
    let expected = [
        30.0 / 25.0 - 1.0,
        20.0 / 25.0 - 1.0,
        3.0 / 15.0,
        -1.5 / 15.0,
        0.5 / std::f64::consts::PI,
        2.0 / 10.0,
        1.0,
        ex / 25.0,
        ey / 25.0,
        (f64::atan2(ey, ex) - 0.5) / std::f64::consts::PI,
        f64::hypot(ex, ey) / 50.0,
    ];
    for (i, (&got, want)) in o.iter().zip(expected).enumerate() {
        assert!(
            (f64::from(got) - want).abs() < 1e-6,
            "obs[{i}] = {got}, expected {want}"
        );
    }
}

#[test]
fn spawn_is_seeded_and_inside_the_zone() {
    let mut t = task(Lander2dParams::default());
    let mut xs = Vec::new();
    for seed in 0..200 {
        t.reset(seed);
        let d = t.lander().drone();
        assert!(
            (20.0..=30.0).contains(&d.x) && (35.0..=45.0).contains(&d.y),
            "{d:?}"
        );
        assert!(d.angle.abs() <= 0.1 && d.vx == 0.0 && d.vy == 0.0, "{d:?}");
        xs.push(d.x);
    }
    t.reset(3);
    let again = t.lander().drone();
    t.reset(3);
    assert_eq!(t.lander().drone(), again);
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    assert_eq!(xs.len(), 200);
}

#[test]
fn spawn_is_clipped_to_the_world() {
    let params = LandingParams {
        spawn_x: 2.0,
        spawn_y: 48.0,
        initial_pos_random_range_m: 10.0,
        ..Default::default()
    };
    let mut t = Landing::new(Lander2dParams::default(), params).unwrap();
    for seed in 0..100 {
        t.reset(seed);
        let d = t.lander().drone();
        assert!(
            (1.0..=49.0).contains(&d.x) && (11.5..=49.0).contains(&d.y),
            "{d:?}"
        );
    }
}

#[test]
fn truncation_fires_at_exactly_max_steps() {
    let params = LandingParams {
        max_steps: 10,
        ..Default::default()
    };
    let mut t = Landing::new(quiet(), params).unwrap();
    let p = quiet();
    let hover = p.command_for_thrust(p.hover_thrust()).unwrap();
    for step in 1..=10 {
        let out = t.step(&[hover, hover]).unwrap();
        assert!(!out.terminated, "step {step}");
        assert_eq!(out.truncated, step == 10, "step {step}");
        let extra = terminal_part(&t, out.reward);
        let want = if step == 10 { -10.0 } else { 0.0 };
        assert!((extra - want).abs() < 1e-12, "step {step}: {extra}");
    }
    assert!(flag(&t, "time_limit"));
}

#[test]
fn landing_on_the_pad_pays_the_landing_reward_and_does_not_also_crash() {
    let mut t = task(quiet());
    t.reset_to(0, at(25.0, 13.0)).unwrap();
    let mut last = None;
    for _ in 0..500 {
        let out = t.step(&descent_action(&t, 0.5)).unwrap();
        if out.terminated || out.truncated {
            last = Some(out);
            break;
        }
    }
    let out = last.unwrap();
    assert!(out.terminated && !out.truncated);
    assert!(flag(&t, "landed") && !flag(&t, "crashed"));
    assert!(t.lander().contact().touched_platform);
    // Calm on the pad (normalised |v| < 0.1 and |ω| < 0.1) pays +100, otherwise +20.
    let (n, _) = t.normalised_observation();
    let calm = n[2].hypot(n[3]) < 0.1 && n[5].abs() < 0.1;
    let extra = terminal_part(&t, out.reward);
    assert_eq!(extra, if calm { 100.0 } else { 20.0 });
    assert!(calm, "a 0.5 m/s touch-down is calm: {n:?}");
    // The +5 for platform contact is in the shaping part.
    assert!(shaping_reward(&n, true) - shaping_reward(&n, false) == 5.0);
}

#[test]
fn touching_bare_ground_terminates_as_a_crash() {
    let mut t = task(quiet());
    t.reset_to(0, at(8.0, 12.0)).unwrap();
    for _ in 0..500 {
        let out = t.step(&descent_action(&t, 0.3)).unwrap();
        if out.terminated {
            assert!(flag(&t, "crashed") && !flag(&t, "landed"));
            assert_eq!(terminal_part(&t, out.reward), -50.0);
            return;
        }
    }
    panic!("never touched the ground");
}

#[test]
fn a_fall_onto_the_pad_terminates_as_a_crash() {
    let mut t = task(quiet());
    t.reset_to(0, at(25.0, 20.0)).unwrap();
    for _ in 0..200 {
        let out = t.step(&[-1.0, -1.0]).unwrap();
        if out.terminated {
            assert!(flag(&t, "crashed") && !flag(&t, "landed"));
            assert_eq!(terminal_part(&t, out.reward), -50.0);
            return;
        }
    }
    panic!("never reached the pad");
}

#[test]
fn lost_control_beyond_the_tilt_limit_terminates() {
    let mut t = task(quiet());
    t.reset_to(
        0,
        DroneState {
            x: 25.0,
            y: 30.0,
            angle: 1.6,
            ..Default::default()
        },
    )
    .unwrap();
    let out = t.step(&[0.0, 0.0]).unwrap();
    assert!(out.terminated);
    assert!(flag(&t, "lost_control"));
    assert_eq!(terminal_part(&t, out.reward), -50.0);
}

#[test]
fn simultaneous_failures_pay_one_penalty() {
    let model = Lander2dParams {
        battery_consumption_rate: 1e9,
        ..quiet()
    };
    let mut t = task(model);
    t.reset_to(
        0,
        DroneState {
            x: 25.0,
            y: 30.0,
            angle: -2.0,
            ..Default::default()
        },
    )
    .unwrap();
    let out = t.step(&[0.0, 0.0]).unwrap();
    assert!(flag(&t, "lost_control") && flag(&t, "battery_empty"));
    assert!(out.terminated && !out.truncated);
    assert_eq!(terminal_part(&t, out.reward), -50.0);
}

#[test]
fn empty_battery_terminates() {
    let mut t = task(Lander2dParams {
        battery_consumption_rate: 1e9,
        ..quiet()
    });
    let out = t.step(&[0.0, 0.0]).unwrap();
    assert!(out.terminated && flag(&t, "battery_empty"));
    assert_eq!(t.observation()[6], 0.0);
    assert_eq!(terminal_part(&t, out.reward), -50.0);
}

#[test]
fn leaving_the_world_terminates() {
    let mut t = task(quiet());
    t.reset_to(
        0,
        DroneState {
            x: 1.0,
            y: 30.0,
            vx: -60.0,
            ..Default::default()
        },
    )
    .unwrap();
    let out = t.step(&[0.0, 0.0]).unwrap();
    assert!(out.terminated && flag(&t, "out_of_bounds"));
    assert_eq!(terminal_part(&t, out.reward), -50.0);
    assert_eq!(t.observation()[0], -1.0, "clipped");
}

#[test]
fn wind_off_does_not_crash() {
    // The reference raised with wind switched off; here a whole episode runs.
    let model = Lander2dParams {
        wind_enabled: false,
        ..Default::default()
    };
    let mut t = task(model);
    t.reset(4);
    let mut steps = 0;
    loop {
        let out = t.step(&[0.0, 0.0]).unwrap();
        steps += 1;
        if out.terminated || out.truncated {
            break;
        }
    }
    assert!(steps > 1);
    match t.info().into_iter().find(|(n, _)| *n == "wind_force") {
        Some((_, InfoValue::Vector(v))) => assert_eq!(v, vec![0.0, 0.0]),
        other => panic!("{other:?}"),
    }
}

#[test]
fn bad_actions_are_errors_and_out_of_range_actions_are_clipped() {
    let mut t = task(quiet());
    assert_eq!(
        t.step(&[0.0]),
        Err(ActionError::WrongLength {
            expected: 2,
            got: 1
        })
    );
    assert!(matches!(
        t.step(&[0.0, f64::NAN]),
        Err(ActionError::NotFinite { index: 1, .. })
    ));
    assert!(matches!(
        t.step(&[f64::INFINITY, 0.0]),
        Err(ActionError::NotFinite { index: 0, .. })
    ));
    assert_eq!(t.status().step, 0, "a refused action takes no step");
    t.step(&[-3.0, 7.0]).unwrap();
    assert_eq!(t.lander().thrust(), [0.0, 15.0]);
}

#[test]
fn observations_stay_inside_declared_bounds_over_random_rollouts() {
    for moving in [false, true] {
        let model = Lander2dParams {
            moving_platform: moving,
            ..Default::default()
        };
        let mut t = task(model);
        let (low, high) = t.observation_bounds();
        let mut rng = SimRng::new(99);
        let mut obs = vec![0.0f32; t.observation_size()];
        let mut total = 0;
        for episode in 0..30 {
            t.reset(episode);
            loop {
                let action = [rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5)];
                let out = t.step(&action).unwrap();
                total += 1;
                t.write_observation(&mut obs);
                for (i, v) in obs.iter().enumerate() {
                    assert!(
                        v.is_finite() && *v >= low[i] && *v <= high[i],
                        "obs[{i}] = {v}"
                    );
                }
                assert!(out.reward.is_finite());
                if out.terminated || out.truncated {
                    break;
                }
            }
        }
        assert!(total > 1000, "{total} steps");
    }
}

#[test]
fn same_seed_replays_bit_identically() {
    let run = |seed| {
        let mut t = task(Lander2dParams {
            moving_platform: true,
            ..Default::default()
        });
        t.reset(seed);
        let mut rng = SimRng::new(1234);
        let mut trace = Vec::new();
        for _ in 0..300 {
            let out = t
                .step(&[rng.uniform(-0.2, 0.6), rng.uniform(-0.2, 0.6)])
                .unwrap();
            trace.push(out.reward.to_bits());
            trace.extend(t.observation().iter().map(|v| u64::from(v.to_bits())));
            if out.terminated || out.truncated {
                break;
            }
        }
        trace
    };
    assert_eq!(run(8), run(8));
    assert_ne!(run(8), run(9));
}

#[test]
fn task_save_restore_continues_bit_identically() {
    let mut a = task(Lander2dParams::default());
    a.reset(21);
    for _ in 0..50 {
        a.step(&[0.1, 0.05]).unwrap();
    }
    let bytes = a.save().unwrap();
    let mut b = Landing::restore(&bytes).unwrap();
    for _ in 0..100 {
        let (x, y) = (a.step(&[0.1, 0.0]).unwrap(), b.step(&[0.1, 0.0]).unwrap());
        assert_eq!(x.reward.to_bits(), y.reward.to_bits());
        assert_eq!(a.observation(), b.observation());
    }
    assert_eq!(a.info(), b.info());
    assert!(Landing::restore(&bytes[1..]).is_err());
    assert!(
        Landing::restore(&a.lander().save().unwrap()).is_err(),
        "a model snapshot is not a task"
    );
}

#[test]
fn info_names_every_outcome() {
    let t = task(Lander2dParams::default());
    let names: Vec<&str> = t.info().into_iter().map(|(n, _)| n).collect();
    for name in [
        "position",
        "velocity",
        "angle",
        "angular_velocity",
        "battery",
        "landed",
        "crashed",
        "lost_control",
        "out_of_bounds",
        "battery_empty",
        "time_limit",
        "distance",
        "step",
    ] {
        assert!(names.contains(&name), "{name} missing from {names:?}");
    }
}

#[test]
fn a_spawn_zone_that_cannot_fit_is_refused() {
    let model = Lander2dParams {
        world_height: 12.0,
        ..Default::default()
    };
    let err = Landing::new(model, LandingParams::default()).unwrap_err();
    assert!(err.to_string().contains("no room to spawn"), "{err}");
    let err = Landing::new(
        Lander2dParams::default(),
        LandingParams {
            max_steps: 0,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(err.to_string().contains("`max_steps` = 0"), "{err}");
}
