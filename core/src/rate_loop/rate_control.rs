//! PX4's body-rate PID (`src/lib/rate_control`): P and I on the rate error, D on the measured
//! angular acceleration, feed-forward on the setpoint, an integrator that shrinks its gain for
//! large errors, is clamped to its limit and stops growing in a direction the allocator
//! reports saturated.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Gains of the three axes (roll, pitch, yaw), body FRD; torques are normalised to [−1, 1].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RateGains {
    pub p: Vector3<f64>,
    pub i: Vector3<f64>,
    pub d: Vector3<f64>,
    pub ff: Vector3<f64>,
    /// Integrator limit per axis (normalised torque).
    pub integrator_limit: Vector3<f64>,
}

/// Which axes the allocator could not follow in the last step, and in which direction.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Saturation {
    pub positive: [bool; 3],
    pub negative: [bool; 3],
}

/// The rate controller's state: the integrator and the allocator's saturation flags.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RateControl {
    pub gains: RateGains,
    integrator: Vector3<f64>,
    saturation: Saturation,
}

/// Rate error at which the integrator's gain falls to 0 (PX4: 400 deg/s).
const I_FACTOR_RATE: f64 = 400.0 * std::f64::consts::PI / 180.0;

impl RateControl {
    pub fn new(gains: RateGains) -> Self {
        RateControl {
            gains,
            integrator: Vector3::zeros(),
            saturation: Saturation::default(),
        }
    }

    /// Zeroes the integrator and forgets the saturation.
    pub fn reset(&mut self) {
        self.integrator = Vector3::zeros();
        self.saturation = Saturation::default();
    }

    /// The integrator's value (normalised torque).
    pub fn integrator(&self) -> Vector3<f64> {
        self.integrator
    }

    /// Records the allocator's saturation for the next integration.
    pub fn set_saturation(&mut self, saturation: Saturation) {
        self.saturation = saturation;
    }

    /// Normalised torque for `rate` (measured, filtered) toward `setpoint` with the measured
    /// angular acceleration `accel`; integrates over `dt` unless `landed`. PX4 computes the
    /// output before it integrates, so this step's integration shows in the next output.
    pub fn update(
        &mut self,
        rate: &Vector3<f64>,
        setpoint: &Vector3<f64>,
        accel: &Vector3<f64>,
        dt: f64,
        landed: bool,
    ) -> Vector3<f64> {
        let g = &self.gains;
        let error = setpoint - rate;
        let torque = g.p.component_mul(&error) + self.integrator - g.d.component_mul(accel)
            + g.ff.component_mul(setpoint);
        if !landed {
            self.integrate(error, dt);
        }
        torque
    }

    fn integrate(&mut self, mut error: Vector3<f64>, dt: f64) {
        for i in 0..3 {
            if self.saturation.positive[i] {
                error[i] = error[i].min(0.0);
            }
            if self.saturation.negative[i] {
                error[i] = error[i].max(0.0);
            }
            // Less integral gain for a large error: no bounce-back after a flip.
            let f = error[i] / I_FACTOR_RATE;
            let factor = (1.0 - f * f).max(0.0);
            let value = self.integrator[i] + factor * self.gains.i[i] * error[i] * dt;
            if value.is_finite() {
                let limit = self.gains.integrator_limit[i];
                self.integrator[i] = value.clamp(-limit, limit);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gains() -> RateGains {
        RateGains {
            p: Vector3::new(0.15, 0.15, 0.2),
            i: Vector3::new(0.2, 0.2, 0.1),
            d: Vector3::new(0.003, 0.003, 0.0),
            ff: Vector3::new(0.0, 0.0, 0.0),
            integrator_limit: Vector3::new(0.3, 0.3, 0.3),
        }
    }

    #[test]
    fn p_d_and_ff_terms_by_hand() {
        let mut g = gains();
        g.ff = Vector3::new(0.1, 0.0, 0.0);
        let mut rc = RateControl::new(g);
        let out = rc.update(
            &Vector3::new(0.5, -0.2, 0.1),
            &Vector3::new(1.0, 0.0, 0.0),
            &Vector3::new(10.0, 0.0, -4.0),
            0.004,
            false,
        );
        // roll: 0.15·0.5 − 0.003·10 + 0.1·1 = 0.145; pitch: 0.15·0.2 = 0.03; yaw: 0.2·(−0.1).
        assert!((out.x - 0.145).abs() < 1e-15, "{out}");
        assert!((out.y - 0.03).abs() < 1e-15, "{out}");
        assert!((out.z + 0.02).abs() < 1e-15, "{out}");
        // The integral of this step appears in the next output: 0.2 · 0.5 · 0.004 · factor.
        let f = 1.0 - (0.5 / I_FACTOR_RATE).powi(2);
        assert!((rc.integrator().x - 0.2 * 0.5 * 0.004 * f).abs() < 1e-15);
    }

    #[test]
    fn integrator_is_clamped_and_frozen_when_landed() {
        let mut rc = RateControl::new(gains());
        let zero = Vector3::zeros();
        for _ in 0..10_000 {
            rc.update(&zero, &Vector3::new(1.0, -1.0, 1.0), &zero, 0.004, false);
        }
        assert_eq!(rc.integrator(), Vector3::new(0.3, -0.3, 0.3));
        rc.reset();
        rc.update(&zero, &Vector3::new(1.0, 1.0, 1.0), &zero, 0.004, true);
        assert_eq!(rc.integrator(), Vector3::zeros());
    }

    #[test]
    fn large_errors_integrate_slower_and_400_deg_s_not_at_all() {
        let mut rc = RateControl::new(gains());
        let zero = Vector3::zeros();
        rc.update(
            &zero,
            &Vector3::new(I_FACTOR_RATE, 0.0, 0.0),
            &zero,
            0.004,
            false,
        );
        assert_eq!(rc.integrator().x, 0.0);
    }

    #[test]
    fn saturation_stops_windup_in_its_direction_only() {
        let mut rc = RateControl::new(gains());
        let zero = Vector3::zeros();
        rc.set_saturation(Saturation {
            positive: [true, false, false],
            negative: [false, true, false],
        });
        rc.update(&zero, &Vector3::new(1.0, -1.0, 1.0), &zero, 0.004, false);
        let i = rc.integrator();
        assert_eq!((i.x, i.y), (0.0, 0.0));
        assert!(i.z > 0.0);
        // The way back out of saturation still integrates.
        rc.update(&zero, &Vector3::new(-1.0, 1.0, 0.0), &zero, 0.004, false);
        assert!(rc.integrator().x < 0.0 && rc.integrator().y > 0.0);
    }
}
