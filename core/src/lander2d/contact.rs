//! Touch-down classification. The reference (docs/reference/lander2d.md) decided "landed" or
//! "crashed" in Chipmunk's collision-begin callback, before the solver acted; here the contact
//! appears in rapier's narrow phase at the start of a physics step and the solver acts on it in
//! that same step, so the impact is judged on the state the drone had when that step began.

use super::drone::DroneState;
use super::params::Lander2dParams;
use serde::{Deserialize, Serialize};

/// Contact flags of the drone and the latched touch-down outcome.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ContactState {
    /// In contact with the platform after the last physics step.
    pub on_platform: bool,
    /// In contact with the ground after the last physics step.
    pub on_ground: bool,
    /// Touched the platform during the last control period.
    pub touched_platform: bool,
    /// Touched the ground during the last control period.
    pub touched_ground: bool,
    /// Latched: a platform touch-down slower and more level than the safe limits.
    pub landed: bool,
    /// Latched: any ground contact, or a platform touch-down too fast or too tilted.
    pub crashed: bool,
    /// Speed relative to the platform at the last platform touch-down, m/s.
    pub touchdown_speed: f64,
    /// Wrapped angle at the last platform touch-down, rad.
    pub touchdown_angle: f64,
}

impl ContactState {
    /// Clears the per-period flags at the start of a control period.
    pub(crate) fn begin_period(&mut self) {
        self.touched_platform = false;
        self.touched_ground = false;
    }

    /// Takes in one physics step: `before` is the drone at the step's start and
    /// `platform_vx` the platform's velocity then.
    pub(crate) fn update(
        &mut self,
        p: &Lander2dParams,
        before: &DroneState,
        platform_vx: f64,
        on_platform: bool,
        on_ground: bool,
    ) {
        if on_platform && !self.on_platform {
            // Relative to the pad: matching a moving pad's speed is how one lands on it.
            let speed = (before.vx - platform_vx).hypot(before.vy);
            let angle = wrap_angle(before.angle);
            self.touchdown_speed = speed;
            self.touchdown_angle = angle;
            if speed < p.max_safe_landing_speed && angle.abs() < p.max_safe_landing_angle {
                self.landed = true;
            } else {
                self.crashed = true;
            }
        }
        // Ground and pad are separate colliders: resting on the pad never touches the ground
        // (the reference flagged a pad landing as a crash as well).
        if on_ground {
            self.crashed = true;
        }
        self.on_platform = on_platform;
        self.on_ground = on_ground;
        self.touched_platform |= on_platform;
        self.touched_ground |= on_ground;
    }
}

/// `angle` wrapped into [−π, π).
pub fn wrap_angle(angle: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    (angle + PI).rem_euclid(TAU) - PI
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn at(vx: f64, vy: f64, angle: f64) -> DroneState {
        DroneState {
            vx,
            vy,
            angle,
            ..Default::default()
        }
    }

    #[test]
    fn first_platform_contact_is_judged_on_speed_and_angle() {
        let p = Lander2dParams::default();
        let mut c = ContactState::default();
        c.update(&p, &at(0.3, -1.0, 0.05), 0.0, true, false);
        assert!(c.landed && !c.crashed);
        let mut c = ContactState::default();
        c.update(&p, &at(0.0, -1.6, 0.0), 0.0, true, false);
        assert!(!c.landed && c.crashed);
        let mut c = ContactState::default();
        c.update(&p, &at(0.0, -0.5, 0.25), 0.0, true, false);
        assert!(c.crashed, "too tilted");
    }

    #[test]
    fn landing_speed_is_relative_to_a_moving_pad() {
        let p = Lander2dParams::default();
        let mut c = ContactState::default();
        c.update(&p, &at(1.5, -0.5, 0.0), 1.5, true, false);
        assert!(c.landed, "{c:?}");
        assert_eq!(c.touchdown_speed, 0.5);
    }

    #[test]
    fn staying_on_the_pad_is_not_a_new_touchdown() {
        let p = Lander2dParams::default();
        let mut c = ContactState::default();
        c.update(&p, &at(0.0, -0.5, 0.0), 0.0, true, false);
        // Later steps in contact are not first contacts: a fast slide does not re-judge.
        c.update(&p, &at(3.0, 0.0, 0.0), 0.0, true, false);
        assert!(c.landed && !c.crashed);
    }

    #[test]
    fn ground_contact_crashes() {
        let p = Lander2dParams::default();
        let mut c = ContactState::default();
        c.update(&p, &at(0.0, -0.1, 0.0), 0.0, false, true);
        assert!(c.crashed && !c.landed && c.touched_ground);
    }

    #[test]
    fn wrap_angle_is_in_minus_pi_to_pi() {
        assert_eq!(wrap_angle(0.0), 0.0);
        assert!((wrap_angle(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-12);
        assert!((wrap_angle(-3.0 * PI / 2.0) - PI / 2.0).abs() < 1e-12);
        assert!((wrap_angle(7.0 * PI) + PI).abs() < 1e-12);
    }
}
