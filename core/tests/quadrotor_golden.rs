//! Golden values of the quad X at its default parameters: the trajectories the shipped hover
//! policies and the PX4-validated rates interface come from these bits, so the vehicle seam
//! and the rotor table (issue 33) must leave them alone. Recorded on main before the rotor
//! table (acce413); a change that moves them must say why in its commit.

// Test code: a failed unwrap is a failed test.

use crate::trace_hash::Hash;
use flyloop_core::quadrotor::{BodyState, Quadrotor, QuadrotorParams};
use flyloop_core::rng::SimRng;
use flyloop_core::tasks::InfoRef;
use flyloop_core::tasks::randomization::{ParamRange, Randomization};
use flyloop_core::tasks::registry::{TaskConfig, TaskInstance, TaskKind};
use nalgebra::Vector3;

impl Hash {
    fn add_body(&mut self, b: &BodyState) {
        let reals = b
            .position
            .iter()
            .chain(b.velocity.iter())
            .chain(b.attitude.coords.iter())
            .chain(b.body_rates.iter())
            .chain(b.motors.iter())
            .chain(b.gear_stretch.iter().flatten());
        for v in reals {
            self.add(v.to_bits());
        }
    }

    fn add_task(&mut self, task: &TaskInstance) {
        for v in task.observation() {
            self.add(u64::from(v.to_bits()));
        }
        task.visit_info(&mut |_, value| match value {
            InfoRef::Real(x) => self.add(x.to_bits()),
            InfoRef::Integer(i) => self.add(i as u64),
            InfoRef::Flag(b) => self.add(u64::from(b)),
            InfoRef::Vector(v) => v.iter().for_each(|x| self.add(x.to_bits())),
        });
    }
}

/// A deterministic, varied action of step `k` inside [lo, hi].
fn action(k: usize, lo: &[f64], hi: &[f64]) -> Vec<f64> {
    (0..lo.len())
        .map(|i| {
            let phase = (k as f64 * 0.037 + i as f64 * 1.3).sin();
            let mid = 0.5 * (lo[i] + hi[i]);
            mid + 0.45 * (hi[i] - mid) * phase
        })
        .collect()
}

/// Three episodes of `kind` (seeds 1, 2, 3), 400 steps or to their end, hashed.
fn episode_hash(kind: TaskKind, config: &TaskConfig) -> u64 {
    let mut task = TaskInstance::build(kind, config).unwrap();
    let (lo, hi) = task.action_bounds();
    let mut h = Hash::new();
    for seed in 1..=3 {
        task.reset(seed);
        h.add_task(&task);
        for k in 0..400 {
            let out = task.step(&action(k, &lo, &hi)).unwrap();
            h.add(out.reward.to_bits());
            h.add_task(&task);
            if out.terminated || out.truncated {
                break;
            }
        }
    }
    h.0
}

fn rates_config() -> TaskConfig {
    let mut config = TaskConfig::default();
    config.flight.rates_action = true;
    config
}

fn randomized_config() -> TaskConfig {
    let mut config = rates_config();
    let range = |name: &str, low, high| ParamRange {
        name: name.into(),
        low,
        high,
    };
    config.randomize = Randomization::new(vec![
        range("mass", 0.8, 1.3),
        range("thrust_coefficient", 9.0, 11.0),
        range("motor_time_constant", 0.05, 0.1),
        range("roll_rate_p", 0.1, 0.2),
    ])
    .unwrap();
    config
}

#[test]
fn hover_with_motor_actions_keeps_its_bits() {
    let h = episode_hash(TaskKind::Hover, &TaskConfig::default());
    assert_eq!(h, 0x1d4b_6fd4_4221_ac36, "{h:#018x}");
}

#[test]
fn waypoints_with_motor_actions_keep_their_bits() {
    let h = episode_hash(TaskKind::Waypoints, &TaskConfig::default());
    assert_eq!(h, 0x7261_9d8e_8f3e_40d6, "{h:#018x}");
}

#[test]
fn hover_with_rates_actions_keeps_its_bits() {
    let h = episode_hash(TaskKind::Hover, &rates_config());
    assert_eq!(h, 0xa2c8_80d6_81e1_abdb, "{h:#018x}");
}

#[test]
fn randomized_waypoints_with_rates_actions_keep_their_bits() {
    let h = episode_hash(TaskKind::Waypoints, &randomized_config());
    assert_eq!(h, 0x9215_b9da_7bdf_5641, "{h:#018x}");
}

/// A windy, tilted drop onto the gear, a bounce and a slide, then a climb out: the contact
/// path and the airborne path, at the SITL's 10 ms and PX4's 4 ms steps.
#[test]
fn a_drop_and_climb_keeps_its_bits() {
    let mut h = Hash::new();
    for dt in [0.01, 0.004] {
        let start = BodyState {
            velocity: Vector3::new(1.0, -0.5, -1.0),
            body_rates: Vector3::new(0.5, -0.3, 1.0),
            ..BodyState::at_rest(Vector3::new(0.0, 0.0, 1.0), 0.2, -0.1, 0.4, 0.3)
        };
        let mut quad = Quadrotor::new(QuadrotorParams::default(), start, SimRng::new(9)).unwrap();
        for k in 0..1500 {
            let m = if k < 600 { 0.2 } else { 0.56 };
            let wobble = 0.02 * (k as f64 * 0.1).sin();
            quad.set_command([m + wobble, m - wobble, m, m + 0.5 * wobble])
                .unwrap();
            quad.step(dt);
            h.add_body(&quad.body);
            let (a, alpha) = quad.accelerations();
            a.iter()
                .chain(alpha.iter())
                .for_each(|v| h.add(v.to_bits()));
        }
    }
    assert_eq!(h.0, 0x9f79_fdd5_b321_f150, "{:#018x}", h.0);
}
