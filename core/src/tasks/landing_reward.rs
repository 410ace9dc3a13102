//! The Landing task's two rewards, chosen by `LandingParams::reward_version`.
//!
//! - **0, `seed`**: the reference's reward (docs/reference/lander2d.md), bit for bit
//!   ([`seed_step_reward`], [`seed_terminal_reward`]). It pays ≈ 2 per step for being near the
//!   pad (≈ 2,000 over a 1,000-step episode) against +100 for landing, so hovering beside the pad
//!   until the time limit is what a learner finds optimal: it does not teach landing.
//! - **1, `landing`**: potential-based shaping r = Φ(s′) − Φ(s) (Ng et al. 1999, as gymnasium's
//!   LunarLander), a small control cost and terminal rewards where landing dominates:
//!   landed +100; crashed, lost control, battery empty, out of the world and the time limit
//!   −100 each. Shaping telescopes over an episode to Φ(end) − Φ(start), so it cannot pay for
//!   hovering: only the terminal reward separates outcomes, and landing is the only positive one.

use crate::lander2d::{Lander2d, wrap_angle};

/// Reward version 0: the seed's reward.
pub const REWARD_SEED: u32 = 0;
/// Reward version 1: potential-based shaping toward a safe landing.
pub const REWARD_LANDING: u32 = 1;

/// Potential per metre of distance between the drone's centre and the platform's top centre.
/// 4/m: from a spawn 30 m away, closing in is worth ≈ 120.
pub const DISTANCE_WEIGHT: f64 = 4.0;
/// Potential per m/s of the drone's speed relative to the platform (10: a touchdown at the
/// 1.5 m/s limit has given back 15 of it).
pub const SPEED_WEIGHT: f64 = 10.0;
/// Potential per radian of tilt (|wrapped angle|).
pub const TILT_WEIGHT: f64 = 50.0;
/// Potential per rad/s of angular rate.
pub const ANGULAR_RATE_WEIGHT: f64 = 10.0;
/// Cost per step of the mean motor level in [0, 1] (≈ 0.025 per hovering step, 25 over a full
/// episode: cheap next to the terminal rewards, it only prefers landing sooner).
pub const CONTROL_COST: f64 = 0.05;
/// Terminal reward of a safe landing.
pub const LANDED_REWARD: f64 = 100.0;
/// Terminal reward of every failure: crash, lost control, empty battery, out of the world,
/// and running out of time.
pub const FAILURE_REWARD: f64 = -100.0;

/// Φ(s) of reward version 1: minus the weighted distance to the pad, speed relative to the
/// pad, tilt and angular rate, in physical units (the observation's clipping would flatten it
/// far from the pad).
pub fn potential(lander: &Lander2d) -> f64 {
    let d = lander.drone();
    let (tx, ty) = lander.platform_target();
    let distance = (tx - d.x).hypot(ty - d.y);
    let relative_speed = (d.vx - lander.platform_vx()).hypot(d.vy);
    -(DISTANCE_WEIGHT * distance
        + SPEED_WEIGHT * relative_speed
        + TILT_WEIGHT * wrap_angle(d.angle).abs()
        + ANGULAR_RATE_WEIGHT * d.angular_velocity.abs())
}

/// The control cost of one step with motor commands in [-1, 1].
pub fn control_cost(command: [f64; 2]) -> f64 {
    CONTROL_COST * (command[0] + command[1] + 2.0) / 4.0
}

/// The seed's per-step reward on normalised observation values n:
/// 2·e^(−0.1·n10) − 0.1·(n2² + n3²) − 0.2·|n4| − 0.1·|n5|, +5 on a step with platform contact.
pub fn seed_step_reward(n: &[f64; 12], touched_platform: bool) -> f64 {
    let r = 2.0 * (-0.1 * n[10]).exp()
        - 0.1 * (n[2] * n[2] + n[3] * n[3])
        - 0.2 * n[4].abs()
        - 0.1 * n[5].abs();
    if touched_platform { r + 5.0 } else { r }
}

/// How an episode step ended, for the terminal rewards.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ending {
    /// Landed; `calm` is the seed's "‖(n2, n3)‖ < 0.1 and |n5| < 0.1".
    Landed {
        calm: bool,
    },
    /// Crashed, lost control, battery empty or out of bounds.
    Failed,
    TimeLimit,
}

/// The seed's terminal reward: landed +100 if calm else +20, failures −50, time limit −10.
pub fn seed_terminal_reward(ending: Ending) -> f64 {
    match ending {
        Ending::Landed { calm: true } => 100.0,
        Ending::Landed { calm: false } => 20.0,
        Ending::Failed => -50.0,
        Ending::TimeLimit => -10.0,
    }
}

/// Reward version 1's terminal reward: landed +100, every failure and the time limit −100.
pub fn landing_terminal_reward(ending: Ending) -> f64 {
    match ending {
        Ending::Landed { .. } => LANDED_REWARD,
        Ending::Failed | Ending::TimeLimit => FAILURE_REWARD,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_step_reward_is_the_reference_formula() {
        let mut n = [0.0; 12];
        assert_eq!(seed_step_reward(&n, false), 2.0);
        assert_eq!(seed_step_reward(&n, true), 7.0);
        n[10] = 0.5;
        n[2] = 0.3;
        n[3] = -0.4;
        n[4] = -0.25;
        n[5] = 0.5;
        let want = 2.0 * (-0.05f64).exp() - 0.1 * 0.25 - 0.2 * 0.25 - 0.1 * 0.5;
        assert!((seed_step_reward(&n, false) - want).abs() < 1e-15);
    }

    #[test]
    fn terminal_rewards_of_both_versions() {
        let cases = [
            (Ending::Landed { calm: true }, 100.0, 100.0),
            (Ending::Landed { calm: false }, 20.0, 100.0),
            (Ending::Failed, -50.0, -100.0),
            (Ending::TimeLimit, -10.0, -100.0),
        ];
        for (ending, seed, landing) in cases {
            assert_eq!(seed_terminal_reward(ending), seed, "{ending:?}");
            assert_eq!(landing_terminal_reward(ending), landing, "{ending:?}");
        }
    }

    #[test]
    fn control_cost_is_zero_with_motors_off_and_full_at_full_thrust() {
        assert_eq!(control_cost([-1.0, -1.0]), 0.0);
        assert_eq!(control_cost([1.0, 1.0]), CONTROL_COST);
        assert_eq!(control_cost([0.0, 0.0]), CONTROL_COST / 2.0);
    }
}
