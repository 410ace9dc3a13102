//! The world's wind: a mean wind and a turbulence *field*, so that neighbours feel
//! correlated gusts and vehicles far apart independent ones.
//!
//! The turbulence is a sum of M random Fourier modes,
//! u(x, t) = Σⱼ aⱼ(t) cos(kⱼ·x) + bⱼ(t) sin(kⱼ·x),
//! with wave vectors kⱼ drawn once per world from N(0, I/ℓ²) and amplitudes aⱼ, bⱼ each an
//! Ornstein–Uhlenbeck process of rate θ and diffusion σ/√M (σ·ratio vertically). At any one
//! point the sum is again an OU process of rate θ and diffusion σ — the statistics of a lone
//! vehicle's turbulence ([`crate::quadrotor::wind`]) — and two points d apart are correlated
//! by (1/M) Σⱼ cos(kⱼ·d), whose expectation over the draws is exp(−|d|²/2ℓ²). This is the
//! random-Fourier-feature form of a Gaussian-covariance field (Rahimi & Recht 2007).

use super::params::WorldParams;
use super::trig::sin_cos;
use crate::quadrotor::wind::ou_decay_and_spread;
use crate::rng::SimRng;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// One Fourier mode: wave vector (rad/m) and its cosine and sine amplitudes (m/s).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Mode {
    wave: Vector3<f64>,
    cos: Vector3<f64>,
    sin: Vector3<f64>,
}

/// The mean wind and the turbulence modes of a world.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WindField {
    /// Mean wind, world ENU, m/s (horizontal).
    pub mean: Vector3<f64>,
    modes: Vec<Mode>,
}

impl WindField {
    /// The world's wind as it starts: mean speed uniform in [wind_speed_min, wind_speed_max],
    /// direction uniform in [0, 2π), wave vectors drawn, every amplitude zero. No draws and
    /// still air when the wind is off.
    pub fn new(params: &WorldParams, rng: &mut SimRng) -> Self {
        if !params.wind_enabled {
            return WindField {
                mean: Vector3::zeros(),
                modes: Vec::new(),
            };
        }
        let speed = rng.uniform(params.wind_speed_min, params.wind_speed_max);
        let direction = rng.uniform(0.0, std::f64::consts::TAU);
        let scale = 1.0 / params.turbulence_correlation_length;
        let modes = (0..params.turbulence_modes)
            .map(|_| Mode {
                wave: Vector3::new(rng.normal(), rng.normal(), rng.normal()) * scale,
                cos: Vector3::zeros(),
                sin: Vector3::zeros(),
            })
            .collect();
        WindField {
            mean: Vector3::new(speed * direction.cos(), speed * direction.sin(), 0.0),
            modes,
        }
    }

    /// The wind at `position` (world ENU, m), m/s.
    pub fn at(&self, position: &Vector3<f64>) -> Vector3<f64> {
        let mut u = self.mean;
        for m in &self.modes {
            let (s, c) = sin_cos(m.wave.dot(position));
            u += m.cos * c + m.sin * s;
        }
        u
    }

    /// Advances every amplitude by one exact OU transition of `turbulence_dt`.
    pub fn sample(&mut self, params: &WorldParams, rng: &mut SimRng) {
        if self.modes.is_empty() {
            return;
        }
        let dt = params.turbulence_dt;
        let theta = params.turbulence_theta;
        let (decay, spread) = ou_decay_and_spread(theta, dt);
        let sigma = params.turbulence_sigma * spread / (self.modes.len() as f64).sqrt();
        let sigma_z = sigma * params.turbulence_vertical_ratio;
        for m in &mut self.modes {
            for amplitude in [&mut m.cos, &mut m.sin] {
                amplitude.x = amplitude.x * decay + sigma * rng.normal();
                amplitude.y = amplitude.y * decay + sigma * rng.normal();
                amplitude.z = amplitude.z * decay + sigma_z * rng.normal();
            }
        }
    }

    /// Whether every value is finite.
    pub fn is_finite(&self) -> bool {
        self.mean.iter().all(|v| v.is_finite())
            && (self.modes.iter()).all(|m| {
                m.wave
                    .iter()
                    .chain(&m.cos)
                    .chain(&m.sin)
                    .all(|v| v.is_finite())
            })
    }

    /// The correlation of the field's x component between two points `d` apart that these
    /// modes give: (1/M) Σⱼ cos(kⱼ·d).
    pub fn correlation(&self, d: &Vector3<f64>) -> f64 {
        let n = self.modes.len().max(1) as f64;
        self.modes.iter().map(|m| m.wave.dot(d).cos()).sum::<f64>() / n
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn field_params() -> WorldParams {
        WorldParams {
            wind_speed_max: 0.0,
            ..Default::default()
        }
    }

    /// At one point the field is an OU process with the lone vehicle's variance σ²/2θ, and
    /// two points 10 m apart (ℓ = 10 m) share the gusts as the modes' correlation says.
    #[test]
    fn one_point_sees_the_lone_vehicle_statistics_and_neighbours_are_correlated() {
        let p = field_params();
        let mut rng = SimRng::new(7);
        let mut field = WindField::new(&p, &mut rng);
        let (a, b) = (Vector3::new(0.0, 0.0, 5.0), Vector3::new(10.0, 0.0, 5.0));
        for _ in 0..2_000 {
            field.sample(&p, &mut rng);
        }
        let n = 400_000;
        let (mut aa, mut bb, mut ab) = (0.0, 0.0, 0.0);
        for _ in 0..n {
            field.sample(&p, &mut rng);
            let (ua, ub) = (field.at(&a).x, field.at(&b).x);
            aa += ua * ua;
            bb += ub * ub;
            ab += ua * ub;
        }
        let nf = n as f64;
        // σ²/2θ = 1 m²/s² at both points (4,000 s = 2,000 time constants: ±5 %).
        assert!((aa / nf - 1.0).abs() < 0.08, "variance at a {}", aa / nf);
        assert!((bb / nf - 1.0).abs() < 0.08, "variance at b {}", bb / nf);
        let measured = ab / (aa * bb).sqrt();
        let expected = field.correlation(&(b - a));
        assert!(
            (measured - expected).abs() < 0.06,
            "{measured} vs {expected}"
        );
        assert!(expected > 0.2 && expected < 0.95, "{expected}");
    }

    /// Over many worlds the modes' correlation at distance d averages exp(−d²/2ℓ²).
    #[test]
    fn the_correlation_over_draws_is_gaussian_in_distance() {
        let p = field_params();
        for d in [0.0, 5.0, 10.0, 20.0] {
            let draws = 2_000;
            let mean: f64 = (0..draws)
                .map(|s| {
                    let f = WindField::new(&p, &mut SimRng::new(s));
                    f.correlation(&Vector3::new(0.0, d, 0.0))
                })
                .sum::<f64>()
                / draws as f64;
            let expected = (-d * d / 200.0_f64).exp();
            assert!(
                (mean - expected).abs() < 0.01,
                "d {d}: {mean} vs {expected}"
            );
        }
    }

    #[test]
    fn no_wind_is_still_air_and_draws_nothing() {
        let p = WorldParams {
            wind_enabled: false,
            ..Default::default()
        };
        let mut rng = SimRng::new(3);
        let before = rng.clone();
        let mut f = WindField::new(&p, &mut rng);
        f.sample(&p, &mut rng);
        assert_eq!(f.at(&Vector3::new(1.0, 2.0, 3.0)), Vector3::zeros());
        assert_eq!(rng, before);
    }
}
