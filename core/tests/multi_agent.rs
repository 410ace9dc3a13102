//! The multi-agent flight tasks on one world: seeds, neighbours, collisions, ends, bounds and
//! bad input.

use flyloop_core::rng::SimRng;
use flyloop_core::tasks::InfoRef;
use flyloop_core::tasks::multi::{MultiConfig, MultiError, MultiFlight, Scenario};
use flyloop_core::tasks::randomization::ParamRange;
use nalgebra::Vector3;

fn task(scenario: Scenario, pairs: &[(&str, f64)]) -> MultiFlight {
    let config = MultiConfig::from_values(pairs.iter().copied(), Vec::new()).unwrap();
    MultiFlight::new(scenario, config).unwrap()
}

fn info(t: &MultiFlight, i: usize, name: &str) -> String {
    let mut found = String::new();
    t.visit_info(i, &mut |n, v| {
        if n == name {
            found = match v {
                InfoRef::Real(x) => format!("{x}"),
                InfoRef::Integer(x) => format!("{x}"),
                InfoRef::Flag(x) => format!("{x}"),
                InfoRef::Vector(x) => format!("{x:?}"),
            }
        }
    });
    found
}

/// Observations, rewards and flags of `steps` steps of random actions, as bits.
fn trace(t: &mut MultiFlight, seed: u64, steps: usize) -> Vec<u64> {
    t.reset(seed).unwrap();
    let n = t.num_agents();
    let (lo, hi) = t.action_bounds();
    let mut rng = SimRng::new(99);
    let mut obs = vec![0.0f32; n * t.observation_size()];
    let mut out = Vec::new();
    for _ in 0..steps {
        let actions: Vec<f64> = (0..n * 4)
            .map(|k| rng.uniform(lo[k % 4], hi[k % 4]))
            .collect();
        t.step(&actions).unwrap();
        t.write_observations(&mut obs);
        out.extend(obs.iter().map(|v| u64::from(v.to_bits())));
        for i in 0..n {
            let o = t.outcome(i);
            out.extend([
                o.reward.to_bits(),
                u64::from(o.terminated),
                u64::from(o.truncated),
            ]);
        }
    }
    out
}

#[test]
fn same_seed_same_bits_on_both_interfaces_and_a_different_seed_differs() {
    for scenario in [Scenario::MultiHover, Scenario::Swap] {
        for rates in [0.0, 1.0] {
            let pairs = [
                ("num_agents", 5.0),
                ("rates_action", rates),
                ("wind_enabled", 1.0),
            ];
            let (mut a, mut b) = (task(scenario, &pairs), task(scenario, &pairs));
            let ta = trace(&mut a, 7, 60);
            assert_eq!(ta, trace(&mut b, 7, 60), "{scenario:?} rates {rates}");
            assert_ne!(ta, trace(&mut b, 8, 60));
            // A reset in the middle of an episode starts the same episode again.
            assert_eq!(ta, trace(&mut a, 7, 60));
        }
    }
}

#[test]
fn swap_starts_on_a_circle_with_the_opposite_point_as_target() {
    let t = task(Scenario::Swap, &[("num_agents", 4.0), ("swap_radius", 2.5)]);
    for i in 0..4 {
        let p = t.world().vehicle(i).body().position;
        assert!((p.xy().norm() - 2.5).abs() < 1e-12);
        assert!((p.z - 1.5).abs() < 1e-12);
        let target = t.target(i);
        assert!((target.xy() + p.xy()).norm() < 1e-12, "{target} {p}");
        // Evenly spaced: the next agent a quarter turn on.
        let q = t.world().vehicle((i + 1) % 4).body().position;
        assert!(((p.xy() - q.xy()).norm() - 2.5 * 2f64.sqrt()).abs() < 1e-9);
    }
}

#[test]
fn swap_layers_put_each_agent_on_its_own_height_from_start_to_target() {
    // 4 agents 0.6 m apart around the 1.5 m start height: 0.6, 1.2, 1.8 and 2.4 m.
    let t = task(Scenario::Swap, &[("num_agents", 4.0), ("swap_layer", 0.6)]);
    for (i, height) in [0.6, 1.2, 1.8, 2.4].into_iter().enumerate() {
        let p = t.world().vehicle(i).body().position;
        assert!((p.z - height).abs() < 1e-12, "agent {i}: {p}");
        assert!(
            (t.target(i).z - height).abs() < 1e-12,
            "agent {i}: {}",
            t.target(i)
        );
        assert!((t.target(i).xy() + p.xy()).norm() < 1e-12);
    }
}

#[test]
fn neighbours_are_nearest_first_and_absent_slots_are_zero() {
    let t = task(
        Scenario::MultiHover,
        &[("num_agents", 2.0), ("neighbours", 3.0)],
    );
    let size = t.observation_size();
    assert_eq!(size, 33 + 3 * 7);
    let layout = t.observation_layout();
    assert_eq!(layout.last(), Some(&("neighbours", 21)));
    let mut obs = vec![0.0f32; size];
    t.write_observation(0, &mut obs);
    let (p0, p1) = (
        t.world().vehicle(0).body().position,
        t.world().vehicle(1).body().position,
    );
    let rel = p1 - p0;
    for k in 0..3 {
        assert_eq!(obs[33 + k], rel[k] as f32);
        assert_eq!(obs[36 + k], 0.0, "both at rest");
    }
    assert_eq!(obs[39], 1.0, "present");
    assert!(
        obs[40..].iter().all(|&v| v == 0.0),
        "absent slots: {:?}",
        &obs[40..]
    );
}

#[test]
fn observations_stay_inside_their_bounds() {
    for rates in [0.0, 1.0] {
        let mut t = task(
            Scenario::Swap,
            &[
                ("num_agents", 6.0),
                ("rates_action", rates),
                ("wind_enabled", 1.0),
            ],
        );
        let (lo, hi) = t.observation_bounds();
        let n = t.observation_size();
        let mut rng = SimRng::new(1);
        let mut obs = vec![0.0f32; 6 * n];
        let (alo, ahi) = t.action_bounds();
        for _ in 0..300 {
            let a: Vec<f64> = (0..24)
                .map(|k| rng.uniform(alo[k % 4], ahi[k % 4]))
                .collect();
            t.step(&a).unwrap();
            t.write_observations(&mut obs);
            for (k, v) in obs.iter().enumerate() {
                assert!(lo[k % n] <= *v && *v <= hi[k % n], "value {k}: {v}");
            }
            if t.all_done() {
                t.reset(rng.next_u64()).unwrap();
            }
        }
    }
}

/// Sends agent 1 into agent 0 at 3 m/s; returns the task after the collision step.
fn collide(scenario: Scenario, agents: f64) -> MultiFlight {
    let mut t = task(
        scenario,
        &[("num_agents", agents), ("collision_penalty", 10.0)],
    );
    let (p0, p1) = (
        t.world().vehicle(0).body().position,
        t.world().vehicle(1).body().position,
    );
    let towards = (p0 - p1).normalize();
    // Close to touching, closing at 3 m/s.
    let v1 = t.world_mut().vehicle_mut(1);
    v1.body_mut().position = p0 - towards * 0.35;
    v1.body_mut().velocity = towards * 3.0;
    let hover = vec![0.2; 4 * agents as usize];
    for _ in 0..20 {
        t.step(&hover).unwrap();
        if t.is_done(0) {
            break;
        }
    }
    t
}

#[test]
fn a_collision_ends_it_for_both_in_multi_hover_and_for_all_in_swap() {
    let t = collide(Scenario::MultiHover, 3.0);
    for i in [0, 1] {
        assert!(t.is_done(i) && t.outcome(i).terminated, "agent {i}");
        assert_eq!(info(&t, i, "collided"), "true");
        assert_eq!(info(&t, i, "collisions"), "1");
        assert!(info(&t, i, "collision_speed").parse::<f64>().unwrap() > 2.0);
        assert!(
            t.outcome(i).reward < -8.0,
            "penalty: {}",
            t.outcome(i).reward
        );
    }
    assert!(!t.is_done(2) && !t.outcome(2).terminated);
    assert_eq!(info(&t, 2, "collided"), "false");
    // The front ends' report of the step: which pair, how fast.
    let c = t.last_collisions();
    assert_eq!(c.len(), 1);
    assert_eq!((c[0].a, c[0].b), (0, 1));
    let speed = info(&t, 0, "collision_speed").parse::<f64>().unwrap();
    assert!((c[0].speed - speed).abs() < 1e-9, "{} {speed}", c[0].speed);

    let mut t = collide(Scenario::Swap, 4.0);
    assert!((0..4).all(|i| t.is_done(i) && t.outcome(i).terminated));
    assert_eq!(info(&t, 2, "collided"), "false");
    assert_eq!(info(&t, 2, "success"), "false");
    // The done agents are out: the next step has them inactive, zero reward.
    t.step(&[0.5; 16]).unwrap();
    assert!((0..4).all(|i| !t.is_active(i) && t.outcome(i).reward == 0.0));
    assert!(
        t.last_collisions().is_empty(),
        "only the step a contact starts in"
    );
}

#[test]
fn hovering_in_place_truncates_every_agent_at_max_steps() {
    let mut t = task(
        Scenario::MultiHover,
        &[("num_agents", 4.0), ("max_steps", 5.0)],
    );
    let hover = t.world().vehicle(0).params().hover_motor_state().unwrap();
    for step in 1..=5 {
        t.step(&[hover; 16]).unwrap();
        assert_eq!((0..4).all(|i| t.outcome(i).truncated), step == 5);
    }
    assert!(t.all_done());
}

#[test]
fn each_agent_draws_its_own_vehicle_and_the_seed_repeats_it() {
    let range = ParamRange {
        name: "mass".into(),
        low: 0.6,
        high: 1.4,
    };
    let config =
        MultiConfig::from_values([("num_agents", 3.0), ("rates_action", 1.0)], vec![range])
            .unwrap();
    let mut t = MultiFlight::new(Scenario::Swap, config).unwrap();
    t.reset(4).unwrap();
    let masses: Vec<f64> = (0..3).map(|i| t.world().vehicle(i).params().mass).collect();
    assert!(
        masses[0] != masses[1] && masses[1] != masses[2],
        "{masses:?}"
    );
    assert_eq!(info(&t, 1, "randomized"), format!("{:?}", [masses[1]]));
    t.reset(5).unwrap();
    t.reset(4).unwrap();
    let again: Vec<f64> = (0..3).map(|i| t.world().vehicle(i).params().mass).collect();
    assert_eq!(masses, again);
}

#[test]
fn bad_input_names_the_item() {
    let err = |pairs: &[(&str, f64)], scenario| {
        let config = MultiConfig::from_values(pairs.iter().copied(), Vec::new());
        match config {
            Err(e) => e.to_string(),
            Ok(c) => MultiFlight::new(scenario, c).unwrap_err().to_string(),
        }
    };
    let e = err(&[("num_agents", 70_000.0)], Scenario::Swap);
    assert!(e.contains("num_agents") && e.contains("65536"), "{e}");
    let e = err(&[("num_agents", 0.0)], Scenario::Swap);
    assert!(e.contains("num_agents"), "{e}");
    let e = err(
        &[("num_agents", 64.0), ("swap_radius", 1.0)],
        Scenario::Swap,
    );
    assert!(e.contains("swap_radius") && e.contains("hulls"), "{e}");
    // 4 layers of 1.2 m around 1.5 m: the lowest at -0.3 m.
    let e = err(&[("swap_layer", 1.2)], Scenario::Swap);
    assert!(e.contains("swap_layer") && e.contains("-0.300"), "{e}");
    let e = err(&[("swap_layer", 11.0)], Scenario::Swap);
    assert!(e.contains("swap_layer") && e.contains("10"), "{e}");
    let e = err(&[("hover_spacing", 0.2)], Scenario::MultiHover);
    assert!(e.contains("hover_spacing"), "{e}");
    let e = err(&[("neighbours", 65.0)], Scenario::Swap);
    assert!(e.contains("neighbours") && e.contains("64"), "{e}");
    let e = err(&[("massss", 1.0)], Scenario::Swap);
    assert!(e.contains("massss"), "{e}");

    let mut t = task(Scenario::Swap, &[("num_agents", 2.0)]);
    let e = t.step(&[0.5; 7]).unwrap_err();
    assert!(
        matches!(
            e,
            MultiError::ActionsLength {
                expected: 8,
                got: 7,
                ..
            }
        ),
        "{e}"
    );
    let mut a = [0.5; 8];
    a[6] = f64::NAN;
    let e = t.step(&a).unwrap_err().to_string();
    assert!(e.starts_with("agent 1:") && e.contains("value 2"), "{e}");
    assert_eq!(t.outcome(0).reward, 0.0, "nothing stepped");
    let _ = Vector3::<f64>::zeros();
}
