//! Golden values of the Lander2D at its default parameters (control period and physics step
//! both 0.02 s): the trajectories the shipped policies were trained on and the gym numbers
//! come from these bits, so a change to how the model steps must leave them alone. The fixed
//! physics grid (issue 26) left the hashes recorded before it unchanged; they were recorded
//! anew once, when free flight left the rapier world (snapshot FLYL2D04: the drone is
//! integrated alone far from the ground and the pad, as rapier integrates it to 1e-9 over
//! 4 s, see `lander2d::scene`), and the shipped policies were checked to land as before.

// Test code: a failed unwrap is a failed test.

use crate::trace_hash::Hash;
use flyloop_core::lander2d::{DroneState, Lander2d, Lander2dParams};
use flyloop_core::rng::SimRng;
use flyloop_core::tasks::Task;
use flyloop_core::tasks::landing::{Landing, LandingParams};

impl Hash {
    fn add_state(&mut self, l: &Lander2d) {
        let d = l.drone();
        let c = l.contact();
        let reals = [
            d.x,
            d.y,
            d.angle,
            d.vx,
            d.vy,
            d.angular_velocity,
            l.battery(),
            l.platform_x(),
            l.platform_vx(),
            c.touchdown_speed,
            c.touchdown_angle,
        ];
        for v in reals.into_iter().chain(l.thrust()).chain(l.acceleration()) {
            self.add(v.to_bits());
        }
        for flag in [
            l.landed(),
            l.crashed(),
            c.on_platform,
            c.on_ground,
            c.touched_platform,
        ] {
            self.add(u64::from(flag));
        }
        self.add(l.steps());
    }
}

/// Motor commands of control period `k`: a weave around hover for 4 s, then a descent with
/// the motors low, onto the pad or the ground.
fn command(k: usize) -> [f64; 2] {
    if k < 200 {
        let a = 0.3 * (k as f64 * 0.05).sin();
        [-0.02 + a, -0.02 - a]
    } else {
        [-0.3, -0.25]
    }
}

fn start() -> DroneState {
    DroneState {
        x: 25.0,
        y: 30.0,
        ..Default::default()
    }
}

/// `periods` control periods through `step()`, every one in the hash.
fn stepped(params: Lander2dParams, seed: u64, periods: usize) -> (u64, Lander2d) {
    let mut l = Lander2d::new(params, start(), SimRng::new(seed)).unwrap();
    let mut hash = Hash::new();
    for k in 0..periods {
        l.set_command(command(k)).unwrap();
        l.step();
        hash.add_state(&l);
    }
    (hash.0, l)
}

#[test]
fn default_flight_with_noise_and_wind_keeps_its_bits() {
    let (hash, l) = stepped(Lander2dParams::default(), 11, 600);
    // A real flight: it came down and the touch-down was judged.
    assert!(l.landed() || l.crashed(), "{l:?}");
    assert!(l.battery() < 90.0, "{}", l.battery());
    assert_eq!(hash, 0xde15_09ce_91f5_3f2c, "{hash:#018x}");
}

#[test]
fn default_flight_over_a_moving_platform_keeps_its_bits() {
    let params = Lander2dParams {
        moving_platform: true,
        ..Default::default()
    };
    let (hash, l) = stepped(params, 4, 600);
    assert!(l.landed() || l.crashed(), "{l:?}");
    assert_eq!(hash, 0x4322_bd88_b012_de42, "{hash:#018x}");
}

/// The FMU's way: `advance_to(n·h)` at communication points that are not the control
/// period, the command changed only on period boundaries.
fn advanced(h: f64, seconds: f64) -> (u64, Lander2d) {
    let mut l = Lander2d::new(Lander2dParams::default(), start(), SimRng::new(11)).unwrap();
    let mut hash = Hash::new();
    let per_period = (0.02 / h).round() as usize;
    let on_period = (0.02 / h - per_period as f64).abs() < 1e-9;
    let points = (seconds / h).round() as usize;
    for n in 0..points {
        if on_period && n % per_period == 0 {
            l.set_command(command(n / per_period)).unwrap();
        } else if n == 0 {
            l.set_command([-0.02, -0.05]).unwrap();
        }
        l.advance_to((n + 1) as f64 * h);
        hash.add_state(&l);
    }
    (hash.0, l)
}

#[test]
fn default_flight_at_communication_points_inside_the_period_keeps_its_bits() {
    let (hash, l) = advanced(0.005, 10.0);
    assert!(l.landed() || l.crashed(), "{l:?}");
    assert_eq!(l.steps(), 500);
    assert_eq!(hash, 0x97e9_5db6_5f09_7341, "{hash:#018x}");
    // Off the period grid: shortened physics steps.
    let (hash, l) = advanced(0.007, 3.0);
    assert_eq!(l.steps(), 150);
    assert_eq!(hash, 0x3bcd_c9ba_35ed_4f95, "{hash:#018x}");
}

#[test]
fn default_landing_task_keeps_its_bits() {
    for (reward_version, golden) in [(0, 0xfac5_078c_1962_7985), (1, 0x4922_dad5_8dac_62a8)] {
        let params = LandingParams {
            reward_version,
            ..Default::default()
        };
        let mut task = Landing::new(Lander2dParams::default(), params).unwrap();
        let mut hash = Hash::new();
        let mut episodes = 0;
        task.reset(5);
        for k in 0..1500 {
            let outcome = task.step(&command(k % 400)).unwrap();
            for v in task.observation() {
                hash.add(u64::from(v.to_bits()));
            }
            hash.add(outcome.reward.to_bits());
            hash.add(u64::from(outcome.terminated) << 1 | u64::from(outcome.truncated));
            if outcome.terminated || outcome.truncated {
                episodes += 1;
                task.reset(5 + episodes);
            }
        }
        assert!(episodes >= 2, "{episodes}");
        assert_eq!(hash.0, golden, "version {reward_version}: {:#018x}", hash.0);
    }
}
