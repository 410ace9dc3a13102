//! Wind: per-episode mean wind and Ornstein–Uhlenbeck turbulence.

use super::params::QuadrotorParams;
use super::state::WindState;
use crate::rng::SimRng;
use nalgebra::Vector3;

/// A fresh episode's wind: mean speed uniform in [wind_speed_min, wind_speed_max], horizontal
/// direction uniform in [0, 2π), turbulence at zero. No wind (and no draws) when disabled.
pub fn reset_wind(params: &QuadrotorParams, rng: &mut SimRng) -> WindState {
    if !params.wind_enabled {
        return WindState::default();
    }
    let speed = rng.uniform(params.wind_speed_min, params.wind_speed_max);
    let direction = rng.uniform(0.0, std::f64::consts::TAU);
    WindState {
        mean: Vector3::new(speed * direction.cos(), speed * direction.sin(), 0.0),
        turbulence: Vector3::zeros(),
        since_sample: 0.0,
    }
}

/// How far a step end may miss a turbulence sample time and still count as on it, as a
/// fraction of `turbulence_dt`: steps of h = 0.005 s add up to 0.01 s only up to rounding.
pub(super) const GRID_SLACK: f64 = 1e-9;

/// The next piece of a step of `remaining` seconds on the turbulence grid: how long to
/// integrate under the current wind, and whether the turbulence is sampled at its end.
/// A step that ends on a sample time (within [`GRID_SLACK`]) is integrated whole, so a caller
/// stepping at exactly `turbulence_dt` integrates the same intervals it asked for.
pub fn next_segment(params: &QuadrotorParams, wind: &WindState, remaining: f64) -> (f64, bool) {
    let grid = params.turbulence_dt;
    let slack = GRID_SLACK * grid;
    let to_sample = grid - wind.since_sample;
    if remaining < to_sample - slack {
        (remaining, false)
    } else if remaining <= to_sample + slack {
        (remaining, true)
    } else {
        (to_sample, true)
    }
}

/// Whether the turbulence is due for its next sample (on its grid within [`GRID_SLACK`]).
pub fn sample_due(params: &QuadrotorParams, wind: &WindState) -> bool {
    params.turbulence_dt - wind.since_sample <= GRID_SLACK * params.turbulence_dt
}

/// How many wind segments a step of `dt` seconds takes at most (one more than the samples in
/// it), for callers that bound the work a step may cost.
pub fn segment_count(params: &QuadrotorParams, dt: f64) -> f64 {
    if params.wind_enabled {
        (dt / params.turbulence_dt).ceil() + 1.0
    } else {
        1.0
    }
}

/// One OU transition of length `dt`: x ← x·decay + sigma·ξ (sigma_z on z).
#[derive(Debug, Clone, Copy)]
pub struct OuTransition {
    /// Bits of (dt, θ, σ, vertical ratio) the coefficients were computed for.
    key: [u64; 4],
    decay: f64,
    sigma: f64,
    sigma_z: f64,
}

impl OuTransition {
    /// The exact transition x ← x e^(−θ dt) + σ √((1 − e^(−2θ dt)) / 2θ) ξ (for θ → 0,
    /// Brownian motion σ √dt ξ), σ on x and y, σ · turbulence_vertical_ratio on z.
    pub fn new(params: &QuadrotorParams, dt: f64) -> Self {
        let (decay, spread) = ou_decay_and_spread(params.turbulence_theta, dt);
        let sigma = params.turbulence_sigma * spread;
        OuTransition {
            key: Self::key(params, dt),
            decay,
            sigma,
            sigma_z: sigma * params.turbulence_vertical_ratio,
        }
    }

    fn key(params: &QuadrotorParams, dt: f64) -> [u64; 4] {
        [
            dt.to_bits(),
            params.turbulence_theta.to_bits(),
            params.turbulence_sigma.to_bits(),
            params.turbulence_vertical_ratio.to_bits(),
        ]
    }

    /// Whether these coefficients are the ones [`OuTransition::new`] gives for `params`, `dt`.
    pub fn is_for(&self, params: &QuadrotorParams, dt: f64) -> bool {
        self.key == Self::key(params, dt)
    }
}

/// The exact OU transition over `dt` at rate `theta` for unit diffusion: (e^(−θ dt),
/// √((1 − e^(−2θ dt)) / 2θ)), the spread √dt as θ → 0. Shared by a vehicle's turbulence and
/// the world's wind field.
pub fn ou_decay_and_spread(theta: f64, dt: f64) -> (f64, f64) {
    let decay = (-theta * dt).exp();
    let spread = if theta * dt > 1e-12 {
        ((1.0 - decay * decay) / (2.0 * theta)).sqrt()
    } else {
        dt.sqrt()
    };
    (decay, spread)
}

/// The last [`OuTransition`] used, so a run at a fixed step pays for exp and sqrt once.
/// A cache, not state: not stored in snapshots and equal to every other cache.
#[derive(Debug, Clone, Copy, Default)]
pub struct OuCache(Option<OuTransition>);

impl PartialEq for OuCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl OuCache {
    /// The transition for `params` and `dt`, recomputed only when one of them changed.
    pub fn get(&mut self, params: &QuadrotorParams, dt: f64) -> OuTransition {
        match self.0 {
            Some(t) if t.is_for(params, dt) => t,
            _ => *self.0.insert(OuTransition::new(params, dt)),
        }
    }
}

/// Advances the turbulence by `dt` with the exact OU transition (see [`OuTransition::new`]).
pub fn advance_wind(params: &QuadrotorParams, wind: &mut WindState, dt: f64, rng: &mut SimRng) {
    if params.wind_enabled {
        apply_transition(&OuTransition::new(params, dt), wind, rng);
    }
}

/// Advances the turbulence by one precomputed transition.
pub fn apply_transition(t: &OuTransition, wind: &mut WindState, rng: &mut SimRng) {
    let w = &mut wind.turbulence;
    w.x = w.x * t.decay + t.sigma * rng.normal();
    w.y = w.y * t.decay + t.sigma * rng.normal();
    w.z = w.z * t.decay + t.sigma_z * rng.normal();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sample statistics of a long OU run against the process's θ and σ.
    #[test]
    fn ou_turbulence_matches_theta_and_sigma() {
        let params = QuadrotorParams {
            turbulence_theta: 0.5,
            turbulence_sigma: 1.0,
            ..Default::default()
        };
        let dt = 0.01;
        let mut rng = SimRng::new(42);
        let mut wind = WindState::default();
        // Burn in 10 time constants, then sample 40,000 s (20,000 time constants).
        for _ in 0..2_000 {
            advance_wind(&params, &mut wind, dt, &mut rng);
        }
        let n = 4_000_000;
        let lag = 100; // 1 s
        let mut history = vec![0.0; lag];
        let (mut sx, mut sxx, mut sxy, mut sz2) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..n {
            advance_wind(&params, &mut wind, dt, &mut rng);
            let x = wind.turbulence.x;
            let earlier = history[i % lag];
            if i >= lag {
                sxy += x * earlier;
            }
            history[i % lag] = x;
            sx += x;
            sxx += x * x;
            sz2 += wind.turbulence.z * wind.turbulence.z;
        }
        let nf = n as f64;
        let var = sxx / nf - (sx / nf).powi(2);
        // Stationary variance σ²/(2θ) = 1 m²/s²; autocorrelation at 1 s e^(−θ) = 0.6065.
        let expected_var = 1.0 / (2.0 * 0.5);
        assert!((var - expected_var).abs() < 0.05, "variance {var}");
        let autocorr = (sxy / (nf - lag as f64)) / var;
        assert!(
            (autocorr - (-0.5f64).exp()).abs() < 0.03,
            "autocorrelation {autocorr}"
        );
        let var_z = sz2 / nf;
        assert!(
            (var_z - 0.04 * expected_var).abs() < 0.004,
            "vertical variance {var_z}"
        );
    }

    #[test]
    fn mean_wind_speed_and_direction_are_drawn_in_range() {
        let params = QuadrotorParams {
            wind_speed_min: 2.0,
            wind_speed_max: 3.0,
            ..Default::default()
        };
        let mut rng = SimRng::new(5);
        let mut quadrant = [0usize; 4];
        for _ in 0..1000 {
            let w = reset_wind(&params, &mut rng);
            let speed = w.mean.norm();
            assert!((2.0..3.0 + 1e-12).contains(&speed), "{speed}");
            assert_eq!(w.mean.z, 0.0);
            assert_eq!(w.turbulence, Vector3::zeros());
            let q = usize::from(w.mean.x < 0.0) * 2 + usize::from(w.mean.y < 0.0);
            quadrant[q] += 1;
        }
        assert!(quadrant.iter().all(|&c| c > 200), "{quadrant:?}");
    }

    #[test]
    fn wind_off_is_still_air() {
        let params = QuadrotorParams {
            wind_enabled: false,
            ..Default::default()
        };
        let mut rng = SimRng::new(5);
        let before = rng.clone();
        let mut w = reset_wind(&params, &mut rng);
        advance_wind(&params, &mut w, 0.01, &mut rng);
        assert_eq!(w.velocity(), Vector3::zeros());
        assert_eq!(rng, before, "disabled wind must not consume random numbers");
    }
}
