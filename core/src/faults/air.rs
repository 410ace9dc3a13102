//! Air faults: a discrete gust and a wind shear, added to the wind the vehicle flies in.
//!
//! Discrete gust (MIL-F-8785C, 3.7.4; MIL-HDBK-1797): v(x) = V_m/2·(1 − cos(π x / d_m)) for
//! 0 ≤ x ≤ d_m, V_m beyond. A hovering vehicle covers no distance, so the rise is given in
//! time (`rise_time` = d_m / airspeed); after `hold` seconds at V_m the gust falls along the
//! mirrored curve, so `hold = 0` is the classic single 1−cos pulse of length 2·rise_time.
//!
//! Wind shear (MIL-F-8785C, 3.7.3.2): W(h) = W₂₀·ln(h / z₀) / ln(20 ft / z₀), z₀ = 0.15 ft
//! (category C flight): the mean wind's logarithmic profile, zero at and below z₀.

use nalgebra::Vector3;
use std::f64::consts::PI;

/// The gust's velocity `t` seconds after it fired, world ENU, m/s.
pub fn gust(amplitude: &Vector3<f64>, rise_time: f64, hold: f64, t: f64) -> Vector3<f64> {
    let shape = if t <= 0.0 {
        0.0
    } else if t < rise_time {
        0.5 * (1.0 - (PI * t / rise_time).cos())
    } else if t <= rise_time + hold {
        1.0
    } else if t < 2.0 * rise_time + hold {
        0.5 * (1.0 - (PI * (2.0 * rise_time + hold - t) / rise_time).cos())
    } else {
        0.0
    };
    amplitude * shape
}

/// The sheared wind at `height` m, blowing toward `direction` (rad from +x toward +y), world
/// ENU, m/s: zero at and below `roughness`.
pub fn shear(
    speed: f64,
    direction: f64,
    reference_height: f64,
    roughness: f64,
    height: f64,
) -> Vector3<f64> {
    if height <= roughness {
        return Vector3::zeros();
    }
    let w = speed * (height / roughness).ln() / (reference_height / roughness).ln();
    let (s, c) = direction.sin_cos();
    Vector3::new(w * c, w * s, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gust_rises_as_one_minus_cosine_holds_and_falls_back() {
        let a = Vector3::new(0.0, 6.0, 0.0);
        assert_eq!(gust(&a, 1.0, 0.5, 0.0), Vector3::zeros());
        assert!((gust(&a, 1.0, 0.5, 0.5).y - 3.0).abs() < 1e-12);
        assert_eq!(gust(&a, 1.0, 0.5, 1.2).y, 6.0);
        assert!((gust(&a, 1.0, 0.5, 2.0).y - 3.0).abs() < 1e-12);
        assert_eq!(gust(&a, 1.0, 0.5, 2.5), Vector3::zeros());
        // Symmetric about the middle of the hold.
        for t in [0.1, 0.3, 0.77] {
            assert!((gust(&a, 1.0, 0.5, t).y - gust(&a, 1.0, 0.5, 2.5 - t).y).abs() < 1e-12);
        }
    }

    #[test]
    fn the_shear_is_the_reference_speed_at_the_reference_height_and_logarithmic() {
        let (h20, z0) = (6.096, 0.0457);
        let w = |h| shear(5.0, 0.0, h20, z0, h).x;
        assert!((w(h20) - 5.0).abs() < 1e-12);
        assert_eq!(w(z0), 0.0);
        // Equal height ratios, equal speed steps.
        assert!(((w(2.0) - w(1.0)) - (w(4.0) - w(2.0))).abs() < 1e-12);
        let v = shear(5.0, std::f64::consts::FRAC_PI_2, h20, z0, h20);
        assert!(v.x.abs() < 1e-12 && (v.y - 5.0).abs() < 1e-12);
    }
}
