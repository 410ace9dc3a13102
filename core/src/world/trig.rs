//! sin and cos together, from a fixed sequence of IEEE operations (fdlibm's kernels after a
//! Cody–Waite reduction): the wind field evaluates one pair per mode per vehicle per sample,
//! where the platform's libm costs about four times as much — and varies between libm
//! versions, which this does not. The constants are fdlibm's, digit for digit.
#![allow(clippy::excessive_precision)]

use std::f64::consts::FRAC_2_PI;

/// The first 33 bits of π/2, and the rest: n·PIO2_HI is exact for |n| < 2²⁰.
const PIO2_HI: f64 = 1.570_796_326_734_125_6;
const PIO2_LO: f64 = 6.077_100_506_506_192_2e-11;
/// 1.5·2⁵²: adding and subtracting it rounds to the nearest integer (|x| < 2⁵¹).
const ROUNDER: f64 = 6_755_399_441_055_744.0;

const S: [f64; 6] = [
    -1.666_666_666_666_663_2e-1,
    8.333_333_333_322_49e-3,
    -1.984_126_982_985_795e-4,
    2.755_731_370_707_006_8e-6,
    -2.505_076_025_340_686_3e-8,
    1.589_690_995_211_55e-10,
];
const C: [f64; 6] = [
    4.166_666_666_666_660_2e-2,
    -1.388_888_888_887_411e-3,
    2.480_158_728_947_673e-5,
    -2.755_731_435_139_066_3e-7,
    2.087_572_321_298_175e-9,
    -1.135_964_755_778_819_5e-11,
];

/// (sin x, cos x) within 2e-16 of the exact values for |x| ≤ 2²⁰ (the wind field's phases stay
/// far below: |k|·|x| is about |x|/ℓ); beyond that, the platform's.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.is_nan() || x.abs() > 1_048_576.0 {
        return x.sin_cos();
    }
    let n = (x * FRAC_2_PI + ROUNDER) - ROUNDER;
    let r = (x - n * PIO2_HI) - n * PIO2_LO;
    let z = r * r;
    let s = r + r * z * (S[0] + z * (S[1] + z * (S[2] + z * (S[3] + z * (S[4] + z * S[5])))));
    let c = 1.0 - 0.5 * z
        + z * z * (C[0] + z * (C[1] + z * (C[2] + z * (C[3] + z * (C[4] + z * C[5])))));
    match (n as i64) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::SimRng;

    #[test]
    fn agrees_with_the_platform_within_two_ulps_of_one() {
        let mut rng = SimRng::new(4);
        let mut worst: f64 = 0.0;
        for k in 0..200_000 {
            let scale = [1.0, 10.0, 1e3, 1e5][k % 4];
            let x = rng.uniform(-scale, scale);
            let (s, c) = sin_cos(x);
            worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
        }
        assert!(worst < 2.5e-16, "worst error {worst:e}");
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(std::f64::consts::FRAC_PI_2);
        assert!((s - 1.0).abs() < 1e-16 && c.abs() < 1e-16);
        let (s, c) = sin_cos(1e300);
        assert!(s.is_finite() && c.is_finite());
    }
}
