//! Forces between two vehicles: hull contact and downwash. Pure functions of the two states.
//!
//! **Contact.** Each vehicle is a sphere around its centre of mass, of radius = the farthest
//! rotor's distance plus a propeller radius ([`Shape`]). Two spheres that overlap by δ push
//! apart along the line between the centres with N = max(0, k·δ − c·vₙ) (vₙ the separating
//! speed): a spring-damper that never pulls, equal and opposite on both.
//!
//! **Downwash** (the model gym-pybullet-drones applies, fitted at the Dynamic Systems Lab,
//! University of Toronto, to Crazyflie measurements; J. Panerati et al., "Learning to Fly — a
//! Gym Environment with PyBullet Physics for Reinforcement Learning of Multi-agent Quadcopter
//! Control", IROS 2021): a vehicle Δz below another and Δxy off its axis is pushed down by
//! F = α·exp(−½(Δxy/β)²), α = c₁·(r/4Δz)², β = c₂·Δz + c₃, r the upper vehicle's propeller
//! radius. Three deviations, each documented in docs/core.md: the fitted β goes to zero and
//! negative above Δz = −c₃/c₂ (0.69 m), where the reference's wake becomes an infinitely thin
//! spike (0/0 = NaN directly below at β = 0), so β is floored at r; the force scales with the
//! upper vehicle's thrust over its weight (the reference assumes a hovering upper vehicle:
//! a vehicle with its motors off blows no wake); and it is cut off beyond 3β horizontally and
//! below `downwash_range`, so that the broad phase finds every pair that feels it.

use super::params::WorldParams;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// A vehicle's size as the world sees it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Shape {
    /// Radius of the sphere hull, m.
    pub hull_radius: f64,
    /// Propeller radius, m (the wake's scale).
    pub propeller_radius: f64,
}

/// The contact force on vehicle a from vehicle b (equal and opposite on b), world ENU, N, or
/// `None` when the hulls do not touch.
pub fn contact_force(
    params: &WorldParams,
    (pa, va, sa): (&Vector3<f64>, &Vector3<f64>, &Shape),
    (pb, vb, sb): (&Vector3<f64>, &Vector3<f64>, &Shape),
) -> Option<Vector3<f64>> {
    let offset = pa - pb;
    let distance = offset.norm();
    let overlap = sa.hull_radius + sb.hull_radius - distance;
    if overlap.is_nan() || overlap <= 0.0 {
        return None;
    }
    // Centres on top of each other: push along world up, a fixed choice.
    let normal = if distance > 1e-9 {
        offset / distance
    } else {
        Vector3::z()
    };
    let separating = (va - vb).dot(&normal);
    let push = (params.contact_stiffness * overlap - params.contact_damping * separating).max(0.0);
    Some(normal * push)
}

/// The downwash force on a vehicle `below` the rotors of a vehicle of propeller radius
/// `radius` whose thrust is `thrust_ratio` times its weight: (downward magnitude, N). Zero
/// outside the wake (not below, deeper than the range, or beyond 3β off its axis). The
/// fitted (r / 4Δz)² grows without bound as Δz → 0, where the fit has no data and two
/// vehicles side by side would be thrown apart: the depth is floored at the propeller radius.
pub fn downwash_force(
    params: &WorldParams,
    below: f64,
    off_axis: f64,
    radius: f64,
    thrust_ratio: f64,
) -> f64 {
    let in_wake = below > 0.0 && below <= params.downwash_range && thrust_ratio > 0.0;
    if !in_wake {
        return 0.0;
    }
    let width = wake_width(params, below, radius);
    if off_axis > 3.0 * width {
        return 0.0;
    }
    let strength = params.downwash_strength * (radius / (4.0 * below.max(radius))).powi(2);
    strength * (-0.5 * (off_axis / width).powi(2)).exp() * thrust_ratio
}

/// β at `below` metres under rotors of `radius`, floored at the radius.
fn wake_width(params: &WorldParams, below: f64, radius: f64) -> f64 {
    (params.downwash_spread * below + params.downwash_offset).max(radius)
}

/// How far apart horizontally two vehicles can interact: touching hulls or the widest wake.
pub fn reach(params: &WorldParams, largest: &Shape) -> f64 {
    let contact = 2.0 * largest.hull_radius;
    let wake = if params.downwash_enabled {
        3.0 * wake_width(params, params.downwash_range, largest.propeller_radius)
    } else {
        0.0
    };
    contact.max(wake).max(1e-3)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Crazyflie 2.x of gym-pybullet-drones (cf2x.urdf: prop radius 2.31348e-2 m,
    /// DW_COEFF 2267.18, 0.16, −0.11) at hover: the reference's numbers, computed with its
    /// formula in double precision.
    #[test]
    fn downwash_matches_the_reference_where_its_wake_is_wider_than_a_propeller() {
        let p = WorldParams::default();
        let r = 2.31348e-2;
        let reference = [
            (1.0, 0.0, 0.07583985917265419),
            (1.0, 0.05, 0.04599919981650316),
            (2.0, 0.1, 0.016927693596516215),
            (0.8, 0.0, 0.11849977995727218),
            (3.0, 0.3, 0.006065957107331799),
        ];
        for (dz, dxy, force) in reference {
            let f = downwash_force(&p, dz, dxy, r, 1.0);
            assert!(
                (f - force).abs() <= 1e-15 * force,
                "Δz {dz} Δxy {dxy}: {f} vs {force}"
            );
        }
        // Twice the thrust, twice the wake; none above, beyond range, or with motors off.
        assert_eq!(
            downwash_force(&p, 1.0, 0.0, r, 2.0),
            2.0 * 0.07583985917265419
        );
        assert_eq!(downwash_force(&p, -1.0, 0.0, r, 1.0), 0.0);
        assert_eq!(downwash_force(&p, 6.0, 0.0, r, 1.0), 0.0);
        assert_eq!(downwash_force(&p, 1.0, 0.0, r, 0.0), 0.0);
        // Where the fitted β crosses zero (Δz = 0.6875 m) the reference gives NaN on the axis.
        let f = downwash_force(&p, 0.6875, 0.0, r, 1.0);
        assert!(f.is_finite() && f > 0.0, "{f}");
    }

    /// Regression: a vehicle passing level under another (collisions off) got a force of
    /// c₁(r/4Δz)² with Δz → 0 and its state went NaN. Within one propeller radius of the
    /// rotor plane the depth is the radius.
    #[test]
    fn downwash_just_below_the_rotors_is_bounded() {
        let p = WorldParams::default();
        let r = 0.0231;
        let at_radius = downwash_force(&p, r, 0.0, r, 1.0);
        assert_eq!(at_radius, p.downwash_strength / 16.0);
        for below in [1e-300, 1e-9, 1e-4, 0.5 * r] {
            assert_eq!(downwash_force(&p, below, 0.0, r, 1.0), at_radius, "{below}");
        }
        assert!(downwash_force(&p, 2.0 * r, 0.0, r, 1.0) < at_radius);
    }

    #[test]
    fn contact_pushes_apart_equally_and_never_pulls() {
        let p = WorldParams::default();
        let s = Shape {
            hull_radius: 0.15,
            propeller_radius: 0.05,
        };
        let (a, b) = (Vector3::new(0.0, 0.0, 1.0), Vector3::new(0.25, 0.0, 1.0));
        let still = Vector3::zeros();
        let f = contact_force(&p, (&a, &still, &s), (&b, &still, &s)).unwrap();
        // δ = 0.05 m → 2000 · 0.05 = 100 N along −x on a.
        assert!((f - Vector3::new(-100.0, 0.0, 0.0)).norm() < 1e-9, "{f}");
        let g = contact_force(&p, (&b, &still, &s), (&a, &still, &s)).unwrap();
        assert_eq!(f, -g);
        // Separating fast: the damper would pull, so no force.
        let away = Vector3::new(-10.0, 0.0, 0.0);
        let f = contact_force(&p, (&a, &away, &s), (&b, &still, &s)).unwrap();
        assert_eq!(f, Vector3::zeros());
        let far = Vector3::new(1.0, 0.0, 1.0);
        assert!(contact_force(&p, (&a, &still, &s), (&far, &still, &s)).is_none());
    }
}
