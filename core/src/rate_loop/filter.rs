//! PX4's second-order low-pass filter (`mathlib` `LowPassFilter2p`): a Butterworth biquad
//! from the bilinear transform, as PX4 filters the gyro and its derivative.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// A two-pole Butterworth low-pass filter in direct form II, PX4's coefficients and reset.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LowPass2p {
    b0: f64,
    b1: f64,
    b2: f64,
    a1: f64,
    a2: f64,
    delay1: f64,
    delay2: f64,
    /// Pass-through: a cutoff of 0 or at/above Nyquist switches the filter off, as in PX4.
    bypass: bool,
}

impl LowPass2p {
    /// A filter for samples at `sample_hz` with its −3 dB point at `cutoff_hz`.
    pub fn new(sample_hz: f64, cutoff_hz: f64) -> Self {
        if !(cutoff_hz > 0.0 && cutoff_hz < sample_hz / 2.0) {
            return LowPass2p {
                b0: 1.0,
                b1: 0.0,
                b2: 0.0,
                a1: 0.0,
                a2: 0.0,
                delay1: 0.0,
                delay2: 0.0,
                bypass: true,
            };
        }
        let ohm = (PI * cutoff_hz / sample_hz).tan();
        let cos45 = (PI / 4.0).cos();
        let c = 1.0 + 2.0 * cos45 * ohm + ohm * ohm;
        let b0 = ohm * ohm / c;
        LowPass2p {
            b0,
            b1: 2.0 * b0,
            b2: b0,
            a1: 2.0 * (ohm * ohm - 1.0) / c,
            a2: (1.0 - 2.0 * cos45 * ohm + ohm * ohm) / c,
            delay1: 0.0,
            delay2: 0.0,
            bypass: false,
        }
    }

    /// Filters one sample.
    pub fn apply(&mut self, sample: f64) -> f64 {
        if self.bypass {
            return sample;
        }
        let delay0 = sample - self.delay1 * self.a1 - self.delay2 * self.a2;
        let out = delay0 * self.b0 + self.delay1 * self.b1 + self.delay2 * self.b2;
        self.delay2 = self.delay1;
        self.delay1 = delay0;
        out
    }

    /// Settles the filter on a constant `sample` (its output is then `sample`) and returns it.
    pub fn reset(&mut self, sample: f64) -> f64 {
        if self.bypass {
            return sample;
        }
        let value = sample / (self.b0 + self.b1 + self.b2);
        self.delay1 = value;
        self.delay2 = value;
        self.apply(sample)
    }
}

/// PX4's first-order low-pass (`AlphaFilter`): y += α (x − y).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LowPass1p {
    alpha: f64,
    state: f64,
}

impl LowPass1p {
    /// For samples every `dt` seconds with cutoff `cutoff_hz` (α = dt / (τ + dt),
    /// τ = 1 / 2π·cutoff); a cutoff of 0 or at/above Nyquist passes samples through.
    pub fn new(dt: f64, cutoff_hz: f64) -> Self {
        let alpha = if cutoff_hz > 0.0 && cutoff_hz < 0.5 / dt {
            let tau = 1.0 / (2.0 * PI * cutoff_hz);
            dt / (tau + dt)
        } else {
            1.0
        };
        LowPass1p { alpha, state: 0.0 }
    }

    pub fn apply(&mut self, sample: f64) -> f64 {
        self.state += self.alpha * (sample - self.state);
        self.state
    }

    pub fn reset(&mut self, value: f64) {
        self.state = value;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_dc_and_damps_above_the_cutoff() {
        let mut f = LowPass2p::new(250.0, 30.0);
        assert!((f.reset(2.0) - 2.0).abs() < 1e-12);
        for _ in 0..200 {
            f.apply(2.0);
        }
        assert!((f.apply(2.0) - 2.0).abs() < 1e-12);
        // A 100 Hz sine: the analog Butterworth at 30 Hz passes 1/√(1 + (100/30)^4) ≈ 0.09;
        // the bilinear transform's warping damps it further.
        let mut f = LowPass2p::new(250.0, 30.0);
        let mut peak: f64 = 0.0;
        for k in 0..2000 {
            let y = f.apply((2.0 * PI * 100.0 * k as f64 / 250.0).sin());
            if k > 1000 {
                peak = peak.max(y.abs());
            }
        }
        assert!(peak < 0.09, "{peak}");
    }

    #[test]
    fn the_cutoff_point_is_minus_3_db() {
        let mut f = LowPass2p::new(1000.0, 50.0);
        let mut peak: f64 = 0.0;
        for k in 0..20_000 {
            let y = f.apply((2.0 * PI * 50.0 * k as f64 / 1000.0).sin());
            if k > 10_000 {
                peak = peak.max(y.abs());
            }
        }
        assert!((peak - 0.5f64.sqrt()).abs() < 0.01, "{peak}");
    }

    #[test]
    fn first_order_alpha_is_px4s() {
        // PX4: fs = 250 Hz, fc = 30 Hz → α = 0.4298688 (its spec's value).
        let mut f = LowPass1p::new(0.004, 30.0);
        assert!((f.apply(1.0) - 0.4298688).abs() < 1e-7);
        let mut yaw = LowPass1p::new(0.004, 2.0);
        assert!((yaw.apply(1.0) - 0.0478598).abs() < 1e-7);
        let mut off = LowPass1p::new(0.004, 0.0);
        assert_eq!(off.apply(2.5), 2.5);
    }

    #[test]
    fn butterworth_coefficients_are_px4s() {
        // PX4 at fs = 250 Hz, fc = 40 Hz: b0 = 0.1453239, a1 = −0.6710291, a2 = 0.2523246.
        let f = LowPass2p::new(250.0, 40.0);
        assert!((f.b0 - 0.1453239).abs() < 1e-7 && (f.b1 - 0.2906478).abs() < 1e-7);
        assert!((f.a1 + 0.6710291).abs() < 1e-7 && (f.a2 - 0.2523246).abs() < 1e-7);
    }

    #[test]
    fn zero_or_nyquist_cutoff_is_a_pass_through() {
        for cutoff in [0.0, 125.0, 400.0] {
            let mut f = LowPass2p::new(250.0, cutoff);
            assert_eq!(f.apply(3.5), 3.5);
            assert_eq!(f.reset(-1.0), -1.0);
        }
    }
}
